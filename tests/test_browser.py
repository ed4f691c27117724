"""What a browser shows: the study report opened from the file system (every figure drawn,
one table row per run, sorting by a click, no network asked for) and `trackbench view
--web` (the viewer's canvas draws the vehicle in its colours; Ctrl-C ends it with exit 0 and
no process left), in headless Chromium driven by Playwright. The browser tests skip when
Chromium or Playwright is missing; the command line's own errors are checked without one."""

import io
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import trackbench as tb
from trackbench.cli import view as V
from trackbench.figures.report import write_report
from trackbench.outputs.recording.entities import WHEEL_RGB
from trackbench.outputs.recording.record import write_recording
from trackbench.study import run_study

CLI = [sys.executable, "-m", "trackbench.cli"]
CHROMIUM = next((p for p in (os.environ.get("CHROMIUM"), shutil.which("chromium"),
                             shutil.which("chromium-browser")) if p), None)
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
         "--enable-unsafe-swiftshader", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]

SWEEP = """[study]
name = "sweep_tiny"
description = "Peak road-wheel forces against speed over a 0.1 m step, shortened"
[scenario]
duration = 0.01
output_interval = 1e-3
record = { enabled = false }
terrain = { kind = "step", height = 0.1, first_contact_time = 0.002 }
[grid]
speed = [5.0, 10.0]
[[runs]]
speed = 15.0
max_steps = 20
"""

LIMIT = """[study]
name = "obstacle_limit_tiny"
description = "The obstacle-limited speed, shortened: the seat's peak over a step"
[scenario]
preset = "damped"
"track.layout" = "closed"
"drive.kind" = "speed"
"contact.friction" = 0.6
duration = 0.02
output_interval = 1e-3
terrain = { kind = "step", height = 0.2, first_contact_time = 0.005 }
record = { enabled = false }
[grid]
"terrain.height" = [0.2]
[search]
parameter = "speed"
low = 2.0
high = 13.0
tolerance = 5.0
quantity = "peak_seat_acceleration_g"
limit = 0.15
"""


def _study(tmp_path_factory, name, text):
    d = tmp_path_factory.mktemp(name)
    (d / f"{name}.toml").write_text(text.replace("[study]\n", f'[study]\noutput = "{d / "results"}"\n', 1))
    run_study(d / f"{name}.toml", workers=2, quiet=True)
    return d / "results"


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    """Three runs of 0.01 s, the third failing (too few steps allowed)."""
    return _study(tmp_path_factory, "sweep", SWEEP)


@pytest.fixture(scope="module")
def limit_study(tmp_path_factory):
    """The obstacle-limit study on one grid point, shortened to five runs of 0.02 s."""
    return _study(tmp_path_factory, "limit", LIMIT)


@pytest.fixture(scope="module")
def browser():
    if CHROMIUM is None:
        pytest.skip("no Chromium installed (apt-get install chromium)")
    sync_api = pytest.importorskip("playwright.sync_api",
                                   reason="Playwright is not installed (pip install playwright)")
    with sync_api.sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        yield b
        b.close()


def _page(browser, block_network=True):
    """A page that records (and refuses) every request that would leave this machine."""
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    page.asked = []

    def route(r):
        url = r.request.url
        if url.startswith(("file:", "data:")) or (not block_network and "localhost" in url):
            return r.continue_()
        page.asked.append(url)
        return r.abort()

    page.route("**/*", route)
    return page


# --- the report -----------------------------------------------------------------------


def _open_report(browser, path):
    page = _page(browser)
    page.goto(Path(path).resolve().as_uri())
    page.wait_for_load_state("load")
    widths = page.eval_on_selector_all("figure img", "imgs => imgs.map(i => i.complete ? i.naturalWidth : 0)")
    rows = page.locator("#runs tbody tr").count()
    return page, widths, rows


def _column(page, k):
    return page.eval_on_selector_all(f"#runs tbody tr td:nth-child({k})", "cs => cs.map(c => c.textContent)")


def test_report_of_a_sweep_opens_offline_with_every_figure_and_run(browser, sweep):
    path, facts = write_report(sweep)
    assert path == sweep / "report.html" and facts["runs"] == 3 and facts["failed"] == 1
    page, widths, rows = _open_report(browser, path)
    assert rows == facts["runs"] == 3
    assert len(widths) == facts["figures"] >= 1 and all(w > 0 for w in widths), widths
    assert page.asked == []                     # nothing from the network: fonts, scripts, images
    assert page.inner_text("h1") == "sweep_tiny"
    failures = page.inner_text("h2:has-text('Failures') + table")
    failed = [line for line in failures.splitlines() if "15" in line]
    assert failed and re.search(r"step", failed[0]), failures   # the reason, from status_message
    text = page.inner_text("#runs")
    folder = os.path.relpath(sweep) if not os.path.relpath(sweep).startswith("..") else str(sweep)
    for run_id in _column(page, 1):
        assert f"trackbench view {folder} {run_id}" in text and f"{run_id} --web" in text
    page.close()


def test_report_table_sorts_by_a_click(browser, sweep):
    path, _ = write_report(sweep)
    page, _, _ = _open_report(browser, path)
    speed = page.eval_on_selector_all("#runs thead th", "hs => hs.map(h => h.textContent)").index("speed") + 1
    wall = page.eval_on_selector_all("#runs thead th", "hs => hs.map(h => h.textContent)").index("wall s") + 1
    page.click(f"#runs thead th:nth-child({speed})")
    assert [float(x) for x in _column(page, speed)] == [5.0, 10.0, 15.0]
    page.click(f"#runs thead th:nth-child({speed})")
    assert [float(x) for x in _column(page, speed)] == [15.0, 10.0, 5.0]
    page.click(f"#runs thead th:nth-child({wall})")
    walls = [float(x) for x in _column(page, wall) if x != "-"]
    assert walls == sorted(walls)
    page.close()


def test_report_of_a_search_has_its_limits_and_their_figures(browser, limit_study, tmp_path):
    out = tmp_path / "elsewhere" / "limit.html"
    code = subprocess.run(CLI + ["report", str(limit_study), "--out", str(out)], capture_output=True,
                          text=True)
    assert code.returncode == 0, code.stderr
    assert f"written: {out}" in code.stdout and "5 runs" in code.stdout
    page, widths, rows = _open_report(browser, out)
    names = page.eval_on_selector_all("figure img", "imgs => imgs.map(i => i.alt)")
    assert rows == 5 and len(widths) == len(names) and all(w > 0 for w in widths)
    assert any(n.startswith("limit_") for n in names) and any(n.startswith("search_") for n in names)
    limits = page.inner_text("h2:has-text('Limits') + table")
    assert "--limit 1 --web" in limits and page.asked == []
    page.close()


def test_view_limit_picks_the_run_at_a_grid_points_limit(limit_study):
    import pandas as pd
    run = pd.read_csv(limit_study / "limits.csv")["limit_run"][0]
    assert V.limit_run_id(limit_study, "1") == run
    assert V.limit_run_id(limit_study, "terrain.height=0.2") == run
    with pytest.raises(V.ViewError, match="names no grid point; the grid points are 1: terrain.height=0.2"):
        V.limit_run_id(limit_study, "2")
    with pytest.raises(V.ViewError, match="NAME=VALUE with NAME one of terrain.height"):
        V.limit_run_id(limit_study, "height=0.2")
    with pytest.raises(V.ViewError, match="no limits.csv: --limit is for a study with"):
        V.limit_run_id(limit_study.parent, "1")


# --- view --web -----------------------------------------------------------------------


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """The paper's vehicle, 0.02 s over its step, recorded."""
    rrd = tmp_path_factory.mktemp("web") / "short.rrd"
    write_recording(tb.simulate(tb.Scenario.paper(duration=0.02)), rrd)
    return rrd


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _at_a_terminal():
    """In the child: Ctrl-C's default action, as a command typed at a terminal has it (the
    suite itself may run as a background job, whose children inherit SIGINT ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _serving(rrd, port):
    """`trackbench view RRD --web --port PORT` started as at a terminal; returns (process, lines
    printed) once it says where to look."""
    proc = subprocess.Popen(CLI + ["view", str(rrd), "--web", "--port", str(port)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=_at_a_terminal)
    lines, deadline = [], time.monotonic() + 90
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        lines.append(line)
        if "Ctrl-C" in line:
            return proc, lines
    proc.kill()
    pytest.fail(f"view --web did not start: {lines} {proc.stderr.read()}")


def _children(pid):
    kids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            kids.append(int(stat.parent.name))
    return kids


def _alive(pid):
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _stopped(proc, sig):
    """Send ``sig``; the exit code, what it printed after, and its processes still alive."""
    kids = _children(proc.pid)
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=20)
    return proc.returncode, out + err, kids, [k for k in kids if _alive(k)]


def _wheel_pixels(png):
    """Pixels of the side view (the viewer's upper left) in each road wheel's colour."""
    import matplotlib.pyplot as plt
    img = plt.imread(io.BytesIO(png))[..., :3]
    h, w = img.shape[:2]
    side = img[int(0.05 * h):int(0.6 * h), : int(0.58 * w)]
    near = [np.abs(side - np.array(rgb) / 255.0).max(axis=-1) < 0.1 for rgb in WHEEL_RGB[:5]]
    return [int(n.sum()) for n in near], side


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc for the processes left")
def test_view_web_draws_the_vehicle_and_stops_clean_on_ctrl_c(browser, recording, tmp_path):
    port = _free_port()
    proc, lines = _serving(recording, port)
    try:
        text = "".join(lines)
        assert f"http://localhost:{port}" in text and f"ssh -N -L {port}:localhost:{port} " in text
        assert len(_children(proc.pid)) == 1              # rerun's web viewer, in its own group
        page = _page(browser, block_network=False)
        page.goto(f"http://localhost:{port}/")
        deadline, counts = time.monotonic() + 120, None
        while time.monotonic() < deadline:
            time.sleep(2)
            png = page.screenshot()
            counts, side = _wheel_pixels(png)
            if min(counts) >= 20:
                break
        (tmp_path / "web_view.png").write_bytes(png)
        shot = tmp_path / "web_view.png"
        assert min(counts) >= 20, f"pixels of each wheel's colour in the side view: {counts} (see {shot})"
        assert side.std() > 0.05
        page.close()
    finally:
        code, said, kids, left = _stopped(proc, signal.SIGINT)
    assert code == 0 and "stopped" in said and "Traceback" not in said, said
    assert kids and not left, f"left behind: {left}"
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", port), timeout=1).close()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc for the processes left")
def test_view_web_stops_clean_on_sigterm_and_says_when_the_port_is_taken(recording):
    port = _free_port()
    proc, _ = _serving(recording, port)
    again = subprocess.run(CLI + ["view", str(recording), "--web", "--port", str(port)], capture_output=True,
                           text=True, timeout=60)
    assert again.returncode == 3 and again.stderr.count("\n") == 1
    assert f"port {port} is in use" in again.stderr and "--port" in again.stderr
    code, said, kids, left = _stopped(proc, signal.SIGTERM)
    assert code == 0 and kids and not left, said


def test_view_web_refuses_a_file_that_is_no_recording(tmp_path):
    bad = tmp_path / "notes.rrd"
    bad.write_text("not a recording\n")
    r = subprocess.run(CLI + ["view", str(bad), "--web", "--port", str(_free_port())], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 3 and r.stderr.count("\n") == 1 and "is not a rerun recording" in r.stderr


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the parent-death signal is Linux's")
def test_view_web_killed_outright_takes_its_viewer_with_it(recording):
    proc, _ = _serving(recording, _free_port())
    kids = _children(proc.pid)
    proc.kill()
    proc.communicate(timeout=20)
    deadline = time.monotonic() + 10
    while any(_alive(k) for k in kids) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert kids and not [k for k in kids if _alive(k)]
