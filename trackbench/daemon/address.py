"""Which daemon serves which command, and where it listens. Standard library only.

A daemon holds the code it imported and the settings it started with, so a command is
served only by a daemon started from the same interpreter, the same trackbench sources
(their sizes and modification times), the same libraries (the import path's folders, as
installed) and the same settings that decide a run's numbers
or the libraries' set-up (numba's and the BLAS' variables, the Python path, ...): they make
its key, which names its socket. Another key gets another daemon; an old one leaves when
idle."""

import hashlib
import os
import sys
import tempfile
from pathlib import Path

SWITCH = "TRACKBENCH_DAEMON"     # "off" (or 0, no, false): every command runs in its own process
OFF = {"0", "off", "no", "false"}
# the environment variables a daemon's imports read (they are part of its key)
KEYED = ("NUMBA_", "OPENBLAS_", "OMP_", "MKL_", "NPY_", "PYTHON", "LD_", "GLIBC_", "JE_", "HDF5_",
         "TRACKBENCH_", "XDG_CACHE_HOME", "HOME", "TMPDIR", "LANG", "LC_")
NUMBA_CONFIG = ".numba_config.yaml"   # numba reads it from the folder it is imported in
MAX_PATH = 94    # bytes: an AF_UNIX address holds at most 107, and the socket is built as PATH.PID.tmp
PACKAGE = Path(__file__).resolve().parents[1]


def enabled(env=None):
    env = os.environ if env is None else env
    return env.get(SWITCH, "").strip().lower() not in OFF


def eligible(argv):
    """The commands a daemon serves: `run` and `study run` (they load the model), not a dask
    study (its workers are dask's), not a request for help, and not in a folder with a numba
    configuration file (the daemon's numba was set up without it)."""
    if not argv or any(a in ("--help", "-h") for a in argv) or os.path.exists(NUMBA_CONFIG):
        return False
    if argv[0] == "run":
        return True
    return argv[:2] == ["study", "run"] and not any(
        a.split("=")[0] in ("--executor", "--scheduler") for a in argv
    )


def _sources():
    """(path, size, mtime) of every Python file of the package: a change of code is a new key."""
    found = []
    for root, dirs, files in os.walk(PACKAGE):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for f in sorted(files):
            if f.endswith(".py"):
                st = os.stat(os.path.join(root, f))
                found.append(f"{os.path.join(root, f)}:{st.st_size}:{st.st_mtime_ns}")
    return found


def _libraries(paths=None):
    """The modification time of every folder on the import path: installing, upgrading or
    removing a library changes its folder's (pip renames its files there)."""
    try:
        here = os.getcwd()
    except OSError:
        here = ""
    found, skip = [], ("", ".", here, str(PACKAGE.parent))
    for entry in sys.path if paths is None else paths:
        if entry in skip:   # the current folder and this package's: not a library's, and they change
            continue
        try:
            found.append(f"{entry}:{os.stat(entry).st_mtime_ns}")
        except OSError:
            pass
    return found


def stamp(paths=None):
    """The package's sources and the installed libraries (on the import path ``paths``, default
    this process's) as they are now: part of the key; a daemon leaves once they change (no
    command would be handed to it again)."""
    parts = _sources() + _libraries(paths)
    return hashlib.sha1("\0".join(parts).encode("utf-8", "surrogateescape")).hexdigest()


def key(env=None, code=None):
    """The key of a daemon for this interpreter, environment and ``code`` (stamp())."""
    env = os.environ if env is None else env
    digest = hashlib.sha1()
    settings = sorted(
        f"{k}={v}" for k, v in env.items() if k.startswith(KEYED) and not k.startswith(SWITCH)
    )
    # the interpreter itself, its flags and its environment (a venv's python and python3 are one)
    interpreter = [os.path.realpath(sys.executable), sys.prefix, sys.version, repr(sys.flags)]
    for part in [*interpreter, str(PACKAGE), code or stamp(), *settings]:
        digest.update(part.encode("utf-8", "surrogateescape") + b"\0")
    return digest.hexdigest()[:16]


def folder():
    """This user's folder of daemon sockets (mode 0700), or None where it is not safe to use
    (another owner, open to others) or cannot be made."""
    import stat
    base = os.environ.get("XDG_RUNTIME_DIR") or tempfile.gettempdir()
    path = Path(base) / f"trackbench-{os.getuid()}"
    try:
        path.mkdir(mode=0o700, exist_ok=True)
        st = path.lstat()   # not a link to somewhere else
    except OSError:
        return None
    if not stat.S_ISDIR(st.st_mode) or st.st_uid != os.getuid() or st.st_mode & 0o077:
        return None
    return path


def socket_path(env=None, code=None):
    """Where the daemon for this command's key listens, or None (no safe folder)."""
    where = folder()
    if where is None:
        return None
    path = where / f"{key(env, code)}.sock"
    return path if len(os.fsencode(path)) <= MAX_PATH else None
