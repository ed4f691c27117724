"""Nothing outlives a command: after `trackbench run` and `trackbench study run` (the README's
main job, shortened) no process of theirs is left, whether they end normally, are started
in the background by a script and killed, or their output is a closed pipe."""

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TB = [sys.executable, "-m", "trackbench.cli"]


def _session(sid):
    """Processes of session ``sid`` (Linux: /proc/<pid>/stat field 6)."""
    found = []
    for p in Path("/proc").iterdir():
        if p.name.isdigit():
            try:
                fields = (p / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[3]) == sid and fields[0] != "Z":
                found.append(int(p.name))
    return found


def _left_after(proc, within=10.0):
    """The processes of ``proc``'s session still there ``within`` seconds after it ended."""
    deadline = time.monotonic() + within
    while True:
        left = _session(proc.pid)
        if not left or time.monotonic() > deadline:
            return left
        time.sleep(0.1)


def _study(tmp_path):
    text = (ROOT / "studies" / "speed_sweep.toml").read_text()
    text = text.replace("duration = 0.5", "duration = 0.01")
    lines = [ln for ln in text.splitlines() if not ln.startswith(("speed = [", '"terrain.height" = ['))]
    p = tmp_path / "sweep.toml"
    p.write_text("\n".join(lines) + '\nspeed = [5.0, 10.0]\n"terrain.height" = [0.1]\n')
    return p


pytestmark = pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux's /proc")


@pytest.mark.parametrize("command", ["run", "study"])
def test_a_command_leaves_no_process_behind(tmp_path, command):
    args = ["run", "--duration", "0.01", "--out", str(tmp_path / "out")] if command == "run" else [
        "study", "run", str(_study(tmp_path)), "-o", str(tmp_path / "res")]
    proc = subprocess.Popen(TB + args, cwd=tmp_path, start_new_session=True, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    out, _ = proc.communicate(timeout=600)
    assert proc.returncode == 0, out[-2000:]
    assert _session(proc.pid) == []   # at once: the command stops its fork server before it ends


def test_a_study_started_in_the_background_and_killed_leaves_nothing(tmp_path):
    """As a script does it: `cmd &`, then kill; the workers and the fork server go with it."""
    study = _study(tmp_path)
    text = study.read_text().replace("duration = 0.01", "duration = 5.0")
    study.write_text(text)
    proc = subprocess.Popen(TB + ["study", "run", str(study), "-o", str(tmp_path / "res")], cwd=tmp_path,
                            start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while len(_session(proc.pid)) < 4 and time.monotonic() < deadline:   # the command, its server, 2 workers
        time.sleep(0.2)
    assert len(_session(proc.pid)) >= 4, "the study's workers never started"
    time.sleep(2.0)   # the workers run
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=60)
    assert _left_after(proc, within=20.0) == []
    # a netCDF file under its own name is a whole run (renamed into place once written); a run
    # killed before its run.json counts as pending, and a rerun replaces its files
    import xarray as xr
    for nc in (tmp_path / "res" / "runs").glob("*/timeseries.nc"):
        with xr.open_dataset(nc) as ds:
            assert ds.attrs["status"] == "completed" and float(ds.time[-1]) == pytest.approx(5.0)


def test_a_closed_output_does_not_crash_the_command(tmp_path):
    """`trackbench run >&-`: the run is written and the command ends without a traceback."""
    if shutil.which("sh") is None:
        pytest.skip("needs a shell")
    cmd = " ".join(TB + ["run", "--duration", "0.01", "--out", str(tmp_path / "out")])
    proc = subprocess.run(["sh", "-c", f"{cmd} >&-"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=600, env={**os.environ})
    assert "Traceback" not in proc.stderr, proc.stderr[-2000:]
    assert (tmp_path / "out" / "paper_step.nc").is_file()
