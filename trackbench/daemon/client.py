"""The command's side of the daemon: hand a command to the daemon for its key, or run it here
and leave a daemon behind for the next one. Standard library only.

The conversation over the daemon's socket: the command sends its arguments, its current
folder, its environment and its process attributes (JSON, length first); the daemon says
"ready"; the command sends its standard input, output and error (the descriptors
themselves: the command's copy in the daemon writes to this terminal); the daemon answers
"pid N" once its copy runs (or "refused: why": the command then runs in its own process)
and "exit N" when it ends. A Ctrl-C (or a
SIGTERM, SIGHUP) here is passed on as one byte; the copy treats it as the Ctrl-C it would
have had, and so does every process it started. Should this process die, its copy hears
the socket close and stops the same way."""

import json
import os
import signal
import socket
import struct
import subprocess
import sys
import time

from . import address

START_LOCK_AGE = 60.0   # s: a "starting" mark older than this is a daemon that never came up


CODE = []   # the stamp of the sources and libraries this command started with
PATHS = "TRACKBENCH_DAEMON_PATHS"


def daemon_path(argv):
    """The socket of the daemon that would serve the command ``argv`` (None: no daemon serves
    it), by the code and settings it starts with (a command may change its own environment)."""
    if not (address.enabled() and address.eligible(argv)):
        return None
    CODE[:] = [address.stamp()]
    return address.socket_path(code=CODE[0])


def run(argv, path):
    """The command's exit status when the daemon at ``path`` ran it, None when none could (run
    it here)."""
    sock = _connect(path) if path is not None else None
    if sock is None:
        return None
    with sock:
        return _converse(sock, argv)


def _connect(path):
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        sock.connect(os.fspath(path))
        return sock
    except ConnectionRefusedError:   # a daemon that died without removing its socket
        _unlink(path)
    except OSError:
        pass
    sock.close()
    return None


def _streams():
    """This process's standard input, output and error; /dev/null in place of a closed one."""
    fds = []
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
            fds.append(fd)
        except OSError:
            fds.append(os.open(os.devnull, os.O_RDWR))
    return fds


FIRST_REPLY = 5.0   # s: a daemon that does not answer within this (stopped, swamped) is passed by
PASSED_ON = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def _attributes():
    """What a process inherits besides its environment, which the copy takes on: the umask,
    the nice level, the processors, the resource limits, the cgroup, the signals ignored."""
    import resource
    mask = os.umask(0)
    os.umask(mask)
    limits = {name: resource.getrlimit(getattr(resource, name))
              for name in dir(resource) if name.startswith("RLIMIT_")}
    try:
        with open("/proc/self/cgroup") as f:
            cgroup = f.read()
    except OSError:
        cgroup = ""
    ignored = [int(s) for s in PASSED_ON if signal.getsignal(s) == signal.SIG_IGN]
    return {"umask": mask, "nice": os.getpriority(os.PRIO_PROCESS, 0), "limits": limits,
            "cpus": sorted(os.sched_getaffinity(0)), "cgroup": cgroup, "ignored": ignored}


def _converse(sock, argv):
    try:
        request = {"argv": list(argv), "cwd": os.getcwd(), "env": dict(os.environ), **_attributes()}
        _check_peer(sock)
        body = json.dumps(request).encode()
        sock.settimeout(FIRST_REPLY)
        sock.sendall(struct.pack("!I", len(body)) + body)
        replies = sock.makefile("rb")
        if replies.readline() != b"ready\n":
            return None
        socket.send_fds(sock, [b"f"], _streams())   # the terminal, once the daemon is there to take it
        first = replies.readline()
        sock.settimeout(None)
    except (OSError, ValueError):
        return None   # no daemon to speak of (gone, stopped, another user's): run here
    except KeyboardInterrupt:
        sys.stderr.write("error: interrupted\n")
        return 130
    if not first.startswith(b"pid "):
        return None   # the daemon is leaving (idle) or cannot take on this command: run here
    for sig in PASSED_ON:
        if signal.getsignal(sig) != signal.SIG_IGN:   # nohup, a background job: left as they are
            signal.signal(sig, lambda *_: _pass_on(sock, b"i"))
    group = int(first.split()[1])   # the copy leads a process group of its own
    signal.signal(signal.SIGTSTP, lambda *_: _suspend(group))
    line = replies.readline()
    if line.startswith(b"exit "):
        return int(line.split()[1])
    sys.stderr.write("error: the daemon's process of this command ended without an exit status "
                     "(killed?); TRACKBENCH_DAEMON=off runs commands in their own process\n")
    return 1


def _check_peer(sock):
    """The daemon must be this user's (its folder is; this holds should the folder be swapped)."""
    uid = struct.unpack("3i", sock.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, 12))[1]
    if uid != os.getuid():
        raise ValueError(f"the daemon's socket belongs to uid {uid}")


def _pass_on(sock, what):
    try:
        sock.send(what)
    except OSError:
        pass


def _suspend(group):
    """Ctrl-Z: the copy and its workers stop with this process, and go on with it (`fg`)."""
    def go_on(*_):
        try:
            os.killpg(group, signal.SIGCONT)
        except OSError:
            pass
    signal.signal(signal.SIGCONT, go_on)
    try:
        os.killpg(group, signal.SIGSTOP)
    except OSError:
        pass
    os.kill(os.getpid(), signal.SIGSTOP)


def _unlink(path):
    try:
        os.unlink(path)
    except OSError:
        pass


def leave_daemon(path):
    """After a command this process ran itself: start the daemon at ``path`` (daemon_path) for
    the next one, in its own session, unless one is starting already."""
    if path is None or path.exists() or unusable(path).exists() or not _mark_starting(path):
        return
    from ..startup import single_threaded_libraries
    env = dict(os.environ)
    single_threaded_libraries(env)   # read as the daemon's libraries load
    paths = [str(address.PACKAGE.parent)] + [p for p in [env.get("PYTHONPATH")] if p]
    env["PYTHONPATH"] = os.pathsep.join(paths)   # the daemon starts in / and imports this package
    env[PATHS] = json.dumps(sys.path)   # the import path this command's stamp was taken on
    try:
        code = CODE[0] if CODE else address.stamp()
        flags = subprocess._args_from_interpreter_flags()   # -O, -X ...: part of its key (as multiprocessing)
        command = [sys.executable, *flags, "-m", "trackbench.daemon", os.fspath(path), code]
        subprocess.Popen(command, env=env, cwd="/", stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, start_new_session=True, close_fds=True)
    except OSError:
        _unlink(starting(path))


def starting(path):
    return path.with_suffix(".starting")


def unusable(path):
    """Where a daemon that could not serve says why (then none is started for its key again)."""
    return path.with_suffix(".unusable")


def _mark_starting(path):
    """Claim the start of the daemon at ``path`` (one command starts it, not every command that
    runs while it loads)."""
    mark = starting(path)
    try:
        if time.time() - mark.stat().st_mtime > START_LOCK_AGE:
            _unlink(mark)
    except OSError:
        pass
    try:
        os.close(os.open(mark, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600))
        return True
    except OSError:
        return False


def _daemons():
    """(socket, its description or {}) of this user's daemons."""
    where = address.folder()
    if where is None:
        return []
    found = []
    for sock in sorted(where.glob("*.sock")):
        try:
            info = json.loads(sock.with_suffix(".json").read_text())
        except (OSError, ValueError):
            info = {}
        found.append((sock, info))
    return found


def _alive(pid):
    try:
        os.kill(int(pid), 0)
        return True
    except (OSError, TypeError, ValueError):
        return False


def status():
    """A line about each of this user's daemons (`trackbench daemon status`)."""
    mine = address.socket_path() if address.enabled() else None
    lines = []
    for sock, info in _daemons():
        try:
            served = sock.with_suffix(".log").read_text().splitlines()
        except OSError:
            served = []
        up = f"{(time.time() - info['started']) / 60:.0f} min" if "started" in info else "?"
        state = "running" if _alive(info.get("pid")) else "not answering"
        lines.append(
            f"daemon {sock.stem}: {state}, pid {info.get('pid', '?')}, up {up}, "
            f"{len(served)} command{'s' if len(served) != 1 else ''} served; "
            f"{'serves this environment' if sock == mine else 'started with other code or settings'}"
            f" ({info.get('package', '?')})"
        )
    where = address.folder()
    for bad in sorted(where.glob("*.unusable")) if where is not None else []:
        lines.append(f"daemon {bad.stem}: could not serve ({bad.read_text().strip()}); commands with "
                     "its code and settings run in their own process")
    if not lines:
        off = "" if address.enabled() else f" ({address.SWITCH} is off: commands run in their own process)"
        lines.append(f"no daemon is running{off}")
    return "\n".join(lines)


def stop(wait=5.0):
    """Stop this user's daemons: each leaves when its socket is gone (within a second, once the
    commands it runs have ended); the number stopped."""
    pids, stopped = [], 0
    where = address.folder()
    for bad in where.glob("*.unusable") if where is not None else []:
        _unlink(bad)   # stop forgets them too: the next command tries again
    for sock, info in _daemons():
        _unlink(sock)
        pids.append(info.get("pid"))
        stopped += _alive(info.get("pid"))
        if not _alive(info.get("pid")):   # gone without its files: they go now
            for suffix in (".json", ".log"):
                _unlink(sock.with_suffix(suffix))
    t0 = time.monotonic()
    while any(_alive(p) for p in pids) and time.monotonic() - t0 < wait:
        time.sleep(0.05)
    return stopped
