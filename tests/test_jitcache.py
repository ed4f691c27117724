"""The compiled-kernel cache folders: old ones pruned, recent or current ones never."""

import os
import time

from trackbench import _jitcache


def _folder(base, name, age_s):
    p = base / name
    p.mkdir()
    t = time.time() - age_s
    os.utime(p, (t, t))
    return p


def test_prune_keeps_current_recent_and_newest(tmp_path):
    day = _jitcache.IDLE
    current = _folder(tmp_path, "current", 10 * day)
    newest_old = _folder(tmp_path, "a", 3 * day)
    recent = [_folder(tmp_path, f"r{i}", 60.0 * (i + 1)) for i in range(4)]
    stale = [_folder(tmp_path, f"s{i}", (5 + i) * day) for i in range(3)]
    _jitcache._prune(tmp_path, current)
    left = {p.name for p in tmp_path.iterdir()}
    # the current folder and every folder used within IDLE stay, whatever their number
    assert {"current", *(p.name for p in recent)} <= left
    # older ones go once there are KEEP - 1 newer others
    assert not any(p.exists() for p in stale) and not newest_old.exists()


def test_prune_keeps_old_folders_within_keep(tmp_path):
    current = _folder(tmp_path, "current", 0.0)
    old = [_folder(tmp_path, f"o{i}", (2 + i) * _jitcache.IDLE) for i in range(_jitcache.KEEP - 1)]
    _jitcache._prune(tmp_path, current)
    assert all(p.exists() for p in old)


def test_compile_notice_says_once_when_numba_compiles(capsys):
    """`trackbench run` says when it compiles (a first run of a kind takes about a minute with
    nothing else on screen) and how long; loading from the cache says nothing."""
    import io

    from numba import njit

    from trackbench._jitcache import CompileNotice

    @njit
    def inner(x):
        return x + 1.0

    @njit
    def outer(x):
        return inner(x) * 2.0

    out = io.StringIO()
    with CompileNotice(out) as notice:
        assert outer(1.0) == 4.0  # compiles outer, and inner inside it
        assert outer(2.0) == 6.0  # compiled: no event
    assert out.getvalue().count("compiling the model") == 1
    assert notice.seconds > 0.0
    quiet = io.StringIO()
    with CompileNotice(quiet) as again:
        outer(3.0)
    assert quiet.getvalue() == "" and again.seconds == 0.0
