"""Where numba keeps the compiled kernels.

numba's own cache checks only the source file of each compiled function, not the files
of the functions it calls and inlines: after an upgrade (or a `git pull` on an editable
install) that changed only `model/contact/track_contacts.py`, the cached time loop would
still hold the old contact kernels. So the cache lives in a folder named by a hash of the source of the
compiled code (model/, solvers/, status.py): ~/.cache/trackbench/numba/<hash>; the last
few folders are kept, and any folder used within a day (another install may be running
from it). Setting NUMBA_CACHE_DIR yourself overrides this.
"""

import hashlib
import os
import shutil
import sys
import time
from pathlib import Path

KEEP = 3
IDLE = 24 * 3600     # s: a folder another install (another venv, a work tree) used lately is kept
COMPILED = ("model", "solvers")     # every @njit function lives here
CONSTANTS = ("status.py",)          # module constants the kernels compile in


def configure():
    if "NUMBA_CACHE_DIR" in os.environ:
        return
    root = Path(__file__).parent
    digest = hashlib.sha1()
    compiled = [p for sub in COMPILED for p in (root / sub).rglob("*.py")] + [root / f for f in CONSTANTS]
    for path in sorted(compiled):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "trackbench" / "numba"
    target = base / digest.hexdigest()[:16]
    try:
        target.mkdir(parents=True, exist_ok=True)
        os.utime(target)
    except OSError:
        return  # not writable: numba falls back to __pycache__ / its own rules
    try:
        _prune(base, target)
    except OSError:
        pass    # pruning is housekeeping: never a reason to run without the cache
    os.environ["NUMBA_CACHE_DIR"] = str(target)
    if "numba" in sys.modules:  # already imported (by the user): set its live config too
        sys.modules["numba"].config.CACHE_DIR = str(target)


def _prune(base, target):
    """Remove the folders of older sources: beyond the KEEP most recent, and only once
    unused for IDLE seconds, since another process (another install of another version)
    may be loading from one of them right now."""
    def age(p):
        try:
            return p.stat().st_mtime
        except OSError:     # removed meanwhile by another process
            return None
    now = time.time()
    folders = [
        (t, p) for p in base.iterdir() if p.is_dir() and p != target for t in [age(p)] if t is not None
    ]
    for t, p in sorted(folders, reverse=True)[KEEP - 1:]:
        if now - t > IDLE:
            shutil.rmtree(p, ignore_errors=True)


class CompileNotice:
    """While active, says once (on ``stream``) when numba starts compiling a kernel instead of
    loading it from the cache: the first run of a kind (paper, closed track, soil, lee) on a
    machine, or after an upgrade, compiles for about a minute with nothing else to show.
    ``seconds`` is the time spent compiling (nested compilations counted once)."""

    def __init__(self, stream, flag=None):
        self.stream, self.flag, self.seconds, self._depth, self._t0 = stream, flag, 0.0, 0, 0.0

    def _tell(self, compiling):
        """The flag file (a study's fork server compiles for its workers: the command shows it)."""
        if self.flag:
            import json
            try:
                Path(self.flag).write_text(json.dumps({"compiling": compiling, "seconds": self.seconds}))
            except OSError:
                pass

    def __enter__(self):
        from numba.core import event

        notice = self

        class _Listener(event.Listener):
            def on_start(self, ev):
                if notice._depth == 0:
                    if notice.seconds == 0.0 and notice.stream is not None:
                        print(
                            "compiling the model for this kind of run (first use on this machine or after an "
                            "upgrade: about a minute; later runs load it from the cache) ...",
                            file=notice.stream,
                            flush=True,
                        )
                    notice._t0 = time.perf_counter()
                    notice._tell(True)
                notice._depth += 1

            def on_end(self, ev):
                notice._depth -= 1
                if notice._depth == 0:
                    notice.seconds += max(time.perf_counter() - notice._t0, 1e-9)
                    notice._tell(False)

        self._listener = _Listener()
        event.register("numba:compile", self._listener)
        return self

    def __exit__(self, *exc):
        from numba.core import event
        event.unregister("numba:compile", self._listener)
        return False
