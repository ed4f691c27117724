"""The daemon (trackbench/daemon/): a command it serves does what the command does in its own
process (same output, same files bit for bit, same exit status), only sooner; an interrupt
reaches the runs; a command with other code or settings is not served; it leaves when told
or idle. Each test's daemons live in a folder of their own (XDG_RUNTIME_DIR)."""

import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from trackbench.daemon import address, client

CLI = [sys.executable, "-c", "from trackbench.cli import main; main()"]


def environment(runtime, **extra):
    env = {**os.environ, "TRACKBENCH_DAEMON": "on", "XDG_RUNTIME_DIR": str(runtime),
           "TRACKBENCH_DAEMON_IDLE": "120", **extra}
    return env


def cli(args, env, cwd, **kw):
    return subprocess.run(CLI + args, env=env, cwd=cwd, capture_output=True, text=True, **kw)


def served(runtime):
    """The commands this folder's daemons served (their log lines)."""
    lines = []
    for log in Path(runtime, f"trackbench-{os.getuid()}").glob("*.log"):
        lines += [json.loads(x) for x in log.read_text().splitlines()]
    return lines


def sockets(runtime):
    return sorted(Path(runtime, f"trackbench-{os.getuid()}").glob("*.sock"))


@pytest.fixture
def runtime():
    """A short folder for daemons' sockets (a socket's path holds at most 107 bytes)."""
    path = Path(tempfile.mkdtemp(prefix="tb"))
    yield path
    shutil.rmtree(path, ignore_errors=True)


def wait_for(predicate, seconds=90.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < seconds:
        if predicate():
            return True
        time.sleep(0.1)
    return False


@pytest.fixture(scope="module")
def daemon(tmp_path_factory):
    """A daemon left by a first command (run in its own process), and that command's folder."""
    base = tmp_path_factory.mktemp("daemon")
    runtime = base / "rt"
    runtime.mkdir(mode=0o700)
    env = environment(runtime)
    first = cli(["run", "--duration", "0.01", "--out", "local"], env, base)
    assert first.returncode == 0, first.stderr
    assert wait_for(lambda: sockets(runtime)), "no daemon came up"
    yield base, runtime, env, first
    cli(["daemon", "stop"], env, base)


def strip_times(text):
    return [line for line in text.splitlines() if "wall time" not in line and "written:" not in line]


def test_a_served_run_is_the_run_of_the_command(daemon):
    base, runtime, env, first = daemon
    before = len(served(runtime))
    out = cli(["run", "--duration", "0.01", "--out", "served"], env, base)
    assert out.returncode == 0, out.stderr
    assert len(served(runtime)) == before + 1          # the daemon ran it
    assert strip_times(out.stdout) == strip_times(first.stdout) and out.stderr == first.stderr
    a = xr.load_dataset(base / "local" / "paper_step.nc")
    b = xr.load_dataset(base / "served" / "paper_step.nc")
    for name in a.variables:
        assert np.array_equal(a[name].values, b[name].values, equal_nan=a[name].dtype.kind == "f"), name
    assert (base / "served" / "paper_step.rrd").stat().st_size > 0


def test_bad_input_gets_the_same_error_and_status(daemon):
    base, runtime, env, _ = daemon
    out = cli(["run", "--set", "speed=-3", "--out", "bad"], env, base)
    here = cli(["run", "--set", "speed=-3", "--out", "bad"], {**env, "TRACKBENCH_DAEMON": "off"}, base)
    assert served(runtime)[-1]["argv"][:3] == ["run", "--set", "speed=-3"]
    assert (out.returncode, out.stdout, out.stderr) == (here.returncode, here.stdout, here.stderr)
    assert out.returncode == 2 and "speed = -3" in out.stderr


def test_a_served_study_runs_on_forked_workers(daemon):
    base, runtime, env, _ = daemon
    (base / "two.toml").write_text('[study]\nname = "two"\n[scenario]\nduration = 0.02\n'
                                   '[grid]\nspeed = [8.0, 12.0]\n')
    out = cli(["study", "run", "two.toml"], env, base)
    assert out.returncode == 0, out.stderr
    assert served(runtime)[-1]["argv"] == ["study", "run", "two.toml"]
    here = cli(["study", "run", "two.toml", "--output", "results/here"], {**env, "TRACKBENCH_DAEMON": "off"},
               base)
    assert here.returncode == 0, here.stderr
    a = (base / "results" / "two" / "summary.csv").read_text().splitlines()
    b = (base / "results" / "here" / "summary.csv").read_text().splitlines()
    keep = [i for i, c in enumerate(a[0].split(",")) if "time" not in c or "peak" in c]
    assert [[r.split(",")[i] for i in keep] for r in a] == [[r.split(",")[i] for i in keep] for r in b]


def test_ctrl_c_reaches_the_runs_and_keeps_what_is_done(daemon):
    base, runtime, env, _ = daemon
    (base / "long.toml").write_text('[study]\nname = "long"\n[scenario]\nduration = 20.0\n'
                                    '[grid]\nspeed = [5.0, 6.0, 7.0, 8.0]\n')
    proc = subprocess.Popen(CLI + ["study", "run", "long.toml"], env=env, cwd=base, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    time.sleep(3.0)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr
    copy = served(runtime)[-1]
    assert copy["exit"] == 130
    assert wait_for(lambda: not _group_alive(copy["pid"]), 10), "a worker of the study outlived it"


def _group_alive(pgid):
    try:
        os.killpg(pgid, 0)
        return True
    except ProcessLookupError:
        return False


def test_a_killed_command_stops_its_copy(daemon):
    base, runtime, env, _ = daemon
    n = len(served(runtime))
    proc = subprocess.Popen(CLI + ["run", "--duration", "30", "--out", "killed"], env=env, cwd=base,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(2.0)
    proc.kill()
    proc.wait()
    assert wait_for(lambda: len(served(runtime)) > n, 30), "the copy ran on"
    assert served(runtime)[-1]["exit"] != 0
    assert not (base / "killed" / "paper_step.nc").exists()


def test_other_settings_are_not_served_by_it(daemon):
    base, runtime, env, _ = daemon
    n = len(served(runtime))
    other = {**env, "NUMBA_OPT": "3"}   # numba's default, said: another setting
    assert address.key(other) != address.key(env)
    out = cli(["run", "--duration", "0.01", "--out", "other"], other, base)
    assert out.returncode == 0
    assert len(served(runtime)) == n
    assert wait_for(lambda: len(sockets(runtime)) == 2)   # it left one of its own
    status = cli(["daemon", "status"], env, base).stdout
    assert "serves this environment" in status and "other code or settings" in status


def test_stop_and_idle_leave_no_daemon(tmp_path, runtime):
    env = environment(runtime, TRACKBENCH_DAEMON_IDLE="3")
    assert cli(["run", "--duration", "0.01", "--out", "a"], env, tmp_path).returncode == 0
    assert wait_for(lambda: sockets(runtime))
    assert wait_for(lambda: not sockets(runtime), 30), "the idle daemon stayed"
    assert not list(runtime.glob("*/*.json"))
    env["TRACKBENCH_DAEMON_IDLE"] = "120"
    assert cli(["run", "--duration", "0.01", "--out", "a", "--force"], env, tmp_path).returncode == 0
    assert wait_for(lambda: sockets(runtime))
    out = cli(["daemon", "stop"], env, tmp_path)
    assert out.stdout.strip() == "stopped 1 daemon"
    assert not sockets(runtime) and "no daemon is running" in cli(["daemon", "status"], env, tmp_path).stdout


def test_which_commands_a_daemon_serves(runtime, monkeypatch):
    assert address.eligible(["run", "--duration", "1"])
    assert address.eligible(["study", "run", "a.toml", "-w", "1"])
    for argv in (["study", "status", "a.toml"], ["run", "--help"], ["plot", "x"], [],
                 ["study", "run", "a.toml", "--executor", "dask"], ["study", "run", "a.toml", "--scheduler=tcp://h:1"]):
        assert not address.eligible(argv), argv
    monkeypatch.chdir(runtime)
    (runtime / ".numba_config.yaml").write_text("")   # numba's settings of this folder: not the daemon's
    assert not address.eligible(["run"])
    (runtime / ".numba_config.yaml").unlink()
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(runtime))
    path = address.socket_path()
    path.write_text("")    # a socket left by a daemon that died: the command runs here
    assert client.run(["run"], path) is None and not path.exists()
    monkeypatch.setenv("TRACKBENCH_DAEMON", "on")
    assert client.daemon_path(["run"]) == path
    monkeypatch.setenv("TRACKBENCH_DAEMON", "off")
    assert client.daemon_path(["run"]) is None


def test_an_edited_package_or_library_sends_its_daemon_away(monkeypatch):
    """A daemon looks at its sources and libraries every LOOK seconds and leaves once they are
    not what its key was made of (no command would be handed to it again)."""
    from trackbench.daemon import serving
    idle = serving._Idle("/nonexistent", 0, [], None, address.stamp())
    monkeypatch.setattr(serving, "_still_ours", lambda path, inode: True)
    idle.looked = -1e9
    assert not idle.leave()             # as it was
    idle.code, idle.looked = "another", -1e9
    assert idle.leave()                 # edited or upgraded


def test_a_daemon_loads_kernels_from_the_cache_and_never_compiles():
    """A kernel not in numba's cache would be compiled: the daemon refuses (it would take a core
    for a minute, unasked) and leaves that kind for after a command; a cached kind loads."""
    import numba

    from trackbench.daemon import serving

    @numba.njit
    def never_compiled(x):
        return x + 1

    with pytest.raises(serving._Uncached):
        with serving._cached_only():
            never_compiled(1)
    assert never_compiled(1) == 2   # outside, numba compiles as ever
    assert serving.warm_kinds([{}]) == []   # the paper's kernels: in the cache (the suite ran them)
    assert serving.warm_kinds([{"speed": -1.0}]) == [{"speed": -1.0}]   # not runnable: left


def test_the_copy_takes_on_the_commands_umask_and_ignored_signals(daemon):
    """A served command is the command's process: its umask (the files' modes) and the signals
    it was started with ignored (nohup: a hangup does not stop it)."""
    base, runtime, env, _ = daemon
    n = len(served(runtime))
    out = subprocess.run(["sh", "-c", "umask 077; exec \"$@\"", "sh", *CLI, "run", "--duration", "0.01",
                          "--out", "private"], env=env, cwd=base, capture_output=True, text=True)
    assert out.returncode == 0 and len(served(runtime)) == n + 1
    assert (base / "private" / "paper_step.nc").stat().st_mode & 0o777 == 0o600
    proc = subprocess.Popen(CLI + ["run", "--duration", "1.5", "--out", "nohup"], env=env, cwd=base,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN))
    time.sleep(1.0)
    proc.send_signal(signal.SIGHUP)
    assert proc.wait(60) == 0 and (base / "nohup" / "paper_step.nc").exists()
    assert served(runtime)[-1]["argv"][-1] == "nohup"


def test_a_stopped_daemon_is_passed_by(daemon):
    """A daemon that does not answer (stopped, swamped) costs the command FIRST_REPLY seconds:
    it then runs in its own process."""
    base, runtime, env, _ = daemon
    assert cli(["run", "--duration", "0.01", "--out", "probe"], env, base).returncode == 0
    logs = Path(runtime, f"trackbench-{os.getuid()}").glob("*.log")
    log = next(p for p in logs if "probe" in p.read_text())
    pid = json.loads(log.with_suffix(".json").read_text())["pid"]    # the daemon that serves env
    n = len(served(runtime))
    os.kill(pid, signal.SIGSTOP)
    try:
        t0 = time.monotonic()
        out = cli(["run", "--duration", "0.01", "--out", "passed_by"], env, base, timeout=120)
        assert out.returncode == 0 and time.monotonic() - t0 > client.FIRST_REPLY
    finally:
        os.kill(pid, signal.SIGCONT)
    assert wait_for(lambda: len(served(runtime)) >= n, 10)
    time.sleep(1.0)
    assert all(x["argv"][-1] != "passed_by" or x["exit"] != 0 for x in served(runtime)[n:])
