"""Studies with [search]: the algorithm on synthetic quantities (evaluations counted), the
[search] table's errors, and one small real search (run ids, waves, resume, limits.csv,
open_limits, status, dask)."""

import json
import math
import random
import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

import trackbench as tb
from trackbench.study import run_study
from trackbench.study.execute import executors
from trackbench.study.spec import search as S
from trackbench.study.spec.study_file import StudyError, expand_range, load_study, resolved_toml

CLI = [sys.executable, "-c", "from trackbench.cli import main; main()"]


def spec(**kw):
    d = dict(parameter="speed", low=2.0, high=20.0, tolerance=0.25, quantity="q", limit=1.0)
    d.update(kw)
    return S.SearchSpec(**d)


class Counted:
    """evaluate() of a synthetic quantity q(point, x), counting calls and evaluations."""

    def __init__(self, q):
        self.q, self.calls, self.asked = q, [], []

    def __call__(self, asks):
        self.calls.append(len(asks))
        self.asked += asks
        return [self.q(p, x) for p, x in asks]


# --- the algorithm --------------------------------------------------------------------


def test_monotone_quantity_limit_within_tolerance_with_the_fewest_evaluations():
    sp = spec()
    crossings = [3.1, 7.77, 12.0, 19.9, 6.5]   # q = x / c: within the limit up to x = c
    ev = Counted(lambda c, x: x / c)
    found = S.search_limits(sp, crossings, ev)
    rounds = S.bisection_rounds(sp)
    assert rounds == 5 and S.max_evaluations(sp) == S.SCAN_POINTS + 5 == 10   # 4.5 -> 0.140625
    for ps, c in zip(found, crossings):
        assert ps.status == "found"
        assert c - sp.tolerance <= ps.search_value <= c < ps.hi
        assert ps.hi - ps.lo <= sp.tolerance
        assert ps.runs == S.SCAN_POINTS + rounds
    # one wave of every point's scan, then one wave a round with every point still bisecting
    assert ev.calls == [S.SCAN_POINTS * len(crossings)] + [len(crossings)] * rounds
    assert len(ev.asked) == len(set(map(tuple, ev.asked))) == len(crossings) * S.max_evaluations(sp)


def test_random_monotone_quantities_stay_within_tolerance():
    rng = random.Random(7)
    for _ in range(200):
        low = rng.uniform(-50.0, 50.0)
        high = low + rng.uniform(0.1, 100.0)
        sp = spec(low=low, high=high, tolerance=(high - low) * rng.uniform(1e-4, 0.99), limit=0.0)
        c = rng.uniform(low, high)
        ev = Counted(lambda p, x: math.tanh(x - c) * 3.0)   # increasing, crosses 0 at c
        (ps,) = S.search_limits(sp, [None], ev)
        if ps.status == "limit_exceeded_at_low":   # c fell within rounding of low
            assert c - low < 1e-9
            continue
        assert ps.status == "found", (low, high, c)
        assert c - sp.tolerance * (1 + 1e-9) <= ps.search_value <= c
        assert ps.runs <= S.max_evaluations(sp) and len(ev.calls) <= 1 + S.bisection_rounds(sp)


def test_edge_statuses():
    sp = spec()
    ev = Counted(lambda p, x: p * x)
    low_ok, high_over, never, at_limit = S.search_limits(sp, [0.01, 1.0, 0.0, 1 / 20.0], ev)
    assert (low_ok.status, low_ok.search_value, low_ok.runs) == ("limit_not_reached", 20.0, 5)
    assert (high_over.status, high_over.search_value, high_over.runs) == ("limit_exceeded_at_low", None, 5)
    assert never.status == "limit_not_reached"
    assert at_limit.status == "limit_not_reached"   # q = limit at high: within (<=)
    assert ev.calls == [20]   # decided by the scan alone: no bisection


def test_non_monotone_is_said_and_its_first_crossing_bisected():
    sp = spec()   # scan 2, 6.5, 11, 15.5, 20: within, over (the bump), within, within, over
    bump = lambda p, x: 2.0 if 4.0 < x < 9.0 or x > 18.0 else 0.0  # noqa: E731
    (ps,) = S.search_limits(sp, ["p"], Counted(bump))
    assert ps.status == "non_monotone" and ps.non_monotone
    assert 4.0 - sp.tolerance <= ps.search_value <= 4.0   # the first (lowest) crossing
    assert ps.runs == S.max_evaluations(sp)
    over_low = lambda p, x: 0.0 if 5.0 < x < 12.0 else 2.0  # noqa: E731
    (ps,) = S.search_limits(sp, ["p"], Counted(over_low))
    assert ps.status == "limit_exceeded_at_low" and ps.search_value is None


def test_failed_and_pending_runs_end_a_point_and_the_waves_go_on_without_it():
    sp = spec()   # scan 2, 6.5, 11, 15.5, 20; q = x / 10 crosses the limit at 10
    q = {"ok": lambda x: x / 10.0, "fails": lambda x: None if 5.0 < x < 12.0 else x / 10.0,
         "nan": lambda x: math.nan, "pending": lambda x: S.PENDING if x == 2.0 else 0.0,
         "fails_beyond": lambda x: None if x > 12.0 else x / 10.0}
    ev = Counted(lambda p, x: q[p](x))
    ok, fails, nan, pending, beyond = S.search_limits(sp, list(q), ev)
    assert ok.status == "found" and fails.status == "failed" and nan.status == "failed"
    assert pending.status == "pending" and pending.runs == 4 and pending.search_value is None
    assert fails.search_value is None
    # failed above the crossing: the limit is found below it, as for ok
    assert beyond.status == "found" and beyond.search_value == ok.search_value
    assert ev.calls == [25] + [2] * S.bisection_rounds(sp)


def test_a_failed_run_with_a_maximum_already_over_the_limit_counts_as_over(monkeypatch):
    """A maximum can only grow: a run that failed after passing the limit is over it (the
    shipped obstacle study's 0.3 m step throws the idler off its guide at 1.15 s, after the
    seat's 2.8 g); under the limit, or a mean, a failed run stays unknown."""
    from types import SimpleNamespace

    from trackbench.study.read import limits
    recs = {"over": {"status": "failed", "results": {"peak_q": 3.0, "mean_q": 3.0}},
            "under": {"status": "failed", "results": {"peak_q": 1.0}}}
    monkeypatch.setattr(limits.store, "read_run", lambda output, run_id: recs[run_id])
    study = SimpleNamespace(output=None, search=spec(quantity="peak_q", limit=2.0))
    assert limits.quantity_of(study, SimpleNamespace(run_id="over")) == 3.0
    assert limits.quantity_of(study, SimpleNamespace(run_id="under")) is None
    study.search = spec(quantity="mean_q", limit=2.0)
    assert limits.quantity_of(study, SimpleNamespace(run_id="over")) is None


def test_a_failed_run_whose_ride_figure_is_already_over_the_limit_counts_as_over(monkeypatch):
    """A stopped run's ride figures are the least the whole run's could be (ride_figures): a
    track thrown on rough ground after the seat absorbed more than the limit over the half it
    was to average is over it, in the search, the study's exit and the search figure alike."""
    from types import SimpleNamespace

    from trackbench.study.execute.runner import Outcome
    from trackbench.study.read import limits
    recs = {"thrown": {"status": "failed", "results": {"absorbed_power": 380.0, "mean_drawbar_pull": 9.0}},
            "early": {"status": "failed", "results": {"absorbed_power": 0.0}}}
    monkeypatch.setattr(limits.store, "read_run", lambda output, run_id: recs[run_id])
    study = SimpleNamespace(output=None, search=spec(quantity="absorbed_power", limit=6.0), runs=[None] * 2)
    assert limits.quantity_of(study, SimpleNamespace(run_id="thrown")) == 380.0
    assert limits.quantity_of(study, SimpleNamespace(run_id="early")) is None
    frame = pd.DataFrame({"run_id": ["a", "b"], "status": ["completed", "failed"],
                          "absorbed_power": [4.0, 380.0]})
    assert Outcome(study, summary=frame).problem() is None
    # a mean of a signed quantity bounds nothing
    study.search = spec(quantity="mean_drawbar_pull", limit=2.0)
    assert limits.quantity_of(study, SimpleNamespace(run_id="thrown")) is None


def test_a_search_study_with_only_decided_failures_exits_cleanly():
    """The run that failed over the limit is the search's answer: no problem line, no nonzero
    exit; a failure under the limit (unknown) still is one."""
    from types import SimpleNamespace

    from trackbench.study.execute.runner import Outcome
    study = SimpleNamespace(search=spec(quantity="peak_q", limit=2.0), runs=[None] * 3)
    frame = pd.DataFrame({"run_id": ["a", "b", "c"], "status": ["completed", "failed", "completed"],
                          "peak_q": [1.0, 3.0, 2.5]})
    assert Outcome(study, summary=frame).problem() is None
    frame.loc[1, "peak_q"] = 1.5
    assert Outcome(study, summary=frame).problem().startswith("1 of 3 runs failed")


def test_scan_values_are_a_grid_range_and_lines_say_how_far():
    sp = spec(low=0.05, high=0.25, tolerance=0.01)
    assert sp.scan_values() == expand_range("x", {"start": 0.05, "stop": 0.25, "num": S.SCAN_POINTS})
    assert S.midpoint(0.1, 0.2) == 0.15
    lines = []
    found = S.search_limits(sp, [1.0, 2.0], Counted(lambda p, x: p * x * 10),
                            on_round=lambda *a: lines.append(S.progress_line(*a)))
    assert lines[0] == "search: 0/2 points done, round 1 of at most 4, 10 runs"
    assert lines[1] == "search: 0/2 points done, round 2 of at most 4, 12 runs"
    assert S.state_line(sp, found).endswith("2/2 points done (2 found), 16 runs")


# --- the [search] table -----------------------------------------------------------------

BASE = """[study]
name = "lim"
[scenario]
duration = 0.02
output_interval = 0.001
record = { enabled = false }
terrain = { kind = "step", height = 0.1, first_contact_time = 0.005 }
"track.layout" = "closed"
"drive.kind" = "speed"
[grid]
"terrain.height" = [0.05, 0.1]
[search]
parameter = "speed"
low = 2.0
high = 20.0
tolerance = 1.0
quantity = "peak_wheel1_force_y"
limit = 7e5
"""


@pytest.mark.parametrize("old, new, message", [
    ('parameter = "speed"', 'parameter = "sped"', "[search]: unknown parameter 'sped'; did you mean speed"),
    ('parameter = "speed"', 'parameter = "solver"', "parameter = 'solver' is not allowed: expected a "
                                                    "parameter that takes any number in a range"),
    ('parameter = "speed"', 'parameter = "vehicle.n_wheels"', "('vehicle.n_wheels' takes an integer"),
    ('parameter = "speed"', 'parameter = "terrain.height"', "parameter 'terrain.height' is also varied"),
    ("low = 2.0", 'low = "2"', "[search] low = '2' is not allowed: expected a finite number"),
    ("limit = 7e5", "limit = nan", "[search] limit = nan is not allowed: expected a finite number"),
    ("low = 2.0", "low = 20.0", "low = 20.0 is not allowed: expected a number below high = 20.0"),
    ("high = 20.0", "high = 200.0", "high = 200.0 is not allowed: speed takes a number in [0, 100] m/s"),
    ("tolerance = 1.0", "tolerance = 0", "tolerance = 0.0 is not allowed: expected a number in (0, high"),
    ("tolerance = 1.0", "tolerance = 18.0", "tolerance = 18.0 is not allowed"),
    ('quantity = "peak_wheel1_force_y"', 'quantity = "peak_whel1_force_y"',
     "quantity = 'peak_whel1_force_y' is not a summary quantity of this study; did you mean peak_wheel1"),
    ('quantity = "peak_wheel1_force_y"', 'quantity = "seat_g"', "allowed: peak_wheel1_force_y, "),
    ('quantity = "peak_wheel1_force_y"', 'quantity = "peak_sinkage"', "of runs with soft soil only"),
    ("limit = 7e5", "limt = 7e5", "[search]: unknown key 'limt'; did you mean limit?"),
    ("low = 2.0\n", "", "[search] lacks low: it needs parameter, low, high, tolerance, quantity, limit"),
    ('"track.layout" = "closed"\n"drive.kind" = "speed"\n', "",
     "[search] parameter = speed needs the speed held, but the paper's bolted track coasts; allowed: "
     'track.layout = "closed" with drive.kind = "speed"'),
    ('"drive.kind" = "speed"', '"drive.kind" = "torque"\n"drive.torque" = 1000.0',
     "needs the speed held, but drive.kind = 'torque'"),
    ('name = "lim"', 'name = "lim"\nreplicates = 2', "replicates = 2 is not allowed with it"),
])
def test_bad_search_tables_fail_in_one_line(tmp_path, old, new, message):
    assert old in BASE
    p = tmp_path / "bad.toml"
    p.write_text(BASE.replace(old, new))
    with pytest.raises(StudyError) as e:
        load_study(p)
    assert message in str(e.value) and "\n" not in str(e.value) and str(p) in str(e.value)


def test_search_runs_have_the_run_ids_of_a_grid(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text(BASE)
    s = load_study(p)
    assert s.param_names == ["terrain.height", "speed"] and s.points == [{"terrain.height": 0.05},
                                                                        {"terrain.height": 0.1}]
    g = tmp_path / "g.toml"
    axis = "[grid]\nspeed = {start = 2.0, stop = 20.0, num = 5}"
    g.write_text(BASE.split("[search]")[0].replace("[grid]", axis))
    grid = {(r.params["terrain.height"], r.params["speed"]): r.run_id for r in load_study(g).runs}
    assert {(r.params["terrain.height"], r.params["speed"]): r.run_id for r in s.runs} == grid
    assert [r.variant for r in s.runs] == [0] * 5 + [1] * 5
    resolved = resolved_toml(s)
    assert "[search]" in resolved and 'quantity = "peak_wheel1_force_y"' in resolved


# --- a real search ------------------------------------------------------------------------


def files(folder):
    return {str(p.relative_to(folder)): (p.stat().st_ino, p.stat().st_mtime_ns)
            for p in Path(folder).rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def searched(tmp_path_factory):
    """The small search stopped (KeyboardInterrupt, as a kill) after 7 runs, its state read,
    then resumed through the command line; the waves of both counted."""
    d = tmp_path_factory.mktemp("search")
    out = d / "out"
    (d / "lim.toml").write_text(BASE.replace('name = "lim"', f'name = "lim"\noutput = "{out}"'))
    waves, real = [], executors.run_local

    def stopping(tasks, workers=2, notify=None, on_running=None, pools=None):
        waves.append(len(tasks))
        for n, item in enumerate(real(tasks, workers, notify=notify, on_running=on_running)):
            if sum(waves[:-1]) + n == 7:
                raise KeyboardInterrupt
            yield item

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(executors, "run_local", stopping)
        with pytest.raises(KeyboardInterrupt):
            run_study(d / "lim.toml", workers=2, quiet=True)
    stopped = {"limits": pd.read_csv(out / "limits.csv"), "files": files(out / "runs"),
               "done": [q.parent.name for q in out.glob("runs/*/run.json")],
               "status": subprocess.run(CLI + ["study", "status", "lim.toml"], cwd=d, capture_output=True,
                                        text=True, timeout=300)}
    resumed = subprocess.run(CLI + ["study", "run", "lim.toml"], cwd=d, capture_output=True, text=True,
                             timeout=600)
    return d, out, waves, stopped, resumed


def test_interrupted_search_keeps_its_runs_and_says_how_far_it_is(searched):
    _, out, waves, stopped, _ = searched
    n = len(stopped["done"])   # 7, and those in flight then (the pool finishes them)
    assert waves == [10] and 7 <= n < 10
    lim = stopped["limits"]
    assert list(lim.columns) == ["terrain.height", "search_value", "status", "runs", "limit_run"]
    assert set(lim.status) == {"pending"} and lim.search_value.isna().all()
    st = stopped["status"]
    assert st.returncode == 0, st.stderr
    # pending: the scan's runs left, and the first bisection run of each point whose scan is done
    # (how many scans were done when the pool stopped depends on which runs were in flight)
    m = re.search(rf"study lim: (\d+) runs: {n} done, 0 failed, (\d+) pending", st.stdout)
    assert m, st.stdout
    total, pending = int(m.group(1)), int(m.group(2))
    assert 10 <= total <= 12 and pending == total - n and pending >= 1, st.stdout
    assert f"0/2 points done (2 not finished), {n} runs" in st.stdout


def test_resumed_search_reuses_completed_runs_and_finds_the_limits(searched):
    d, out, _, stopped, resumed = searched
    assert resumed.returncode == 0, resumed.stderr
    n = len(stopped["done"])
    assert f"16 runs, {16 - n} run now, {n} already completed, 0 failed" in resumed.stdout
    after = files(out / "runs")
    kept = {k: v for k, v in stopped["files"].items() if k.split("/")[0] in stopped["done"]}
    assert {k: after[k] for k in kept} == kept   # completed runs never rerun
    log = resumed.stderr.splitlines()
    assert "search: 0/2 points done, round 1 of at most 4, 10 runs" in log
    assert "search: 0/2 points done, round 4 of at most 4, 16 runs" in log
    assert f"{10 - n} runs to do, {n} already completed" in log
    lim = tb.open_limits(out)
    assert lim.status.tolist() == ["found", "found"] and lim.runs.tolist() == [8, 8]
    assert lim["terrain.height"].tolist() == [0.05, 0.1]
    df = tb.open_study(out).set_index("run_id")
    assert len(df) == 16 and (df.status == "completed").all()
    for h, v in zip(lim["terrain.height"], lim.search_value):
        runs = df[df["terrain.height"] == h].sort_values("speed")
        within = runs[runs.peak_wheel1_force_y <= 7e5].speed
        over = runs[runs.peak_wheel1_force_y > 7e5].speed
        assert v == within.max() and over.min() - v <= 1.0 and within.max() < over.min()
    assert tb.open_limits(d / "lim.toml").equals(lim)   # the study file reads the same
    m = json.loads((out / "runs.json").read_text())
    assert len(m["runs"]) == 16 and m["search"]["parameter"] == "speed"
    assert not list(out.glob(".*.tmp*"))


def test_search_status_summary_and_a_second_resume(searched):
    d, out, _, _, _ = searched
    st = subprocess.run(CLI + ["study", "status", str(out)], cwd=d, capture_output=True, text=True,
                        timeout=300)
    assert "16 runs: 16 done, 0 failed, 0 pending" in st.stdout
    said = "search of speed in [2, 20] for peak_wheel1_force_y <= 700000: 2/2 points done (2 found)"
    assert said in st.stdout
    sm = subprocess.run(CLI + ["study", "summary", "lim.toml"], cwd=d, capture_output=True, text=True,
                        timeout=300)
    assert sm.stdout.count("completed") == 16 and len(pd.read_csv(out / "summary.csv")) == 16
    snap = files(out / "runs")
    o = run_study(d / "lim.toml", workers=2, quiet=True)
    assert (o.ran, o.skipped) == (0, 16) and files(out / "runs") == snap
    assert o.limits.status.tolist() == ["found", "found"]


def test_plot_draws_the_limit_curve_and_names_the_run_at_the_limit(searched, tmp_path):
    from trackbench.figures.plots import plot_study
    out = searched[1]
    lim = pd.read_csv(out / "limits.csv")
    summary = pd.read_csv(out / "summary.csv").set_index("run_id")
    for run, v in zip(lim.limit_run, lim.search_value):   # the run at the limit, to replay
        assert summary.loc[run, "speed"] == v and (out / "runs" / run / "timeseries.nc").exists()
    paths = [p.name for p in plot_study(out, tmp_path)]
    assert {"limit_speed.png", "search_peak_wheel1_force_y.png"} <= set(paths)
    assert all((tmp_path / p).stat().st_size > 10_000 for p in paths)


def test_search_on_dask_gives_the_same_limits(searched, tmp_path):
    pytest.importorskip("dask.distributed")
    d, out = searched[0], searched[1]
    o = run_study(d / "lim.toml", workers=2, executor="dask", output=tmp_path / "dk", quiet=True)
    assert o.ran == 16 and o.failed_total == 0
    assert tb.open_limits(tmp_path / "dk").equals(tb.open_limits(out))


def test_open_limits_needs_a_search_and_its_file(tmp_path):
    g = tmp_path / "g.toml"
    g.write_text(BASE.split("[search]")[0].replace('name = "lim"', f'name = "g"\noutput = "{tmp_path}/g"'))
    (tmp_path / "g").mkdir()
    with pytest.raises(StudyError, match="has no \\[search\\] table"):
        tb.open_limits(g)
    s = tmp_path / "s.toml"
    s.write_text(BASE.replace('name = "lim"', f'name = "s"\noutput = "{tmp_path / "s"}"'))
    (tmp_path / "s").mkdir()
    with pytest.raises(FileNotFoundError, match="limits.csv does not exist: run `trackbench study run`"):
        tb.open_limits(s)


def test_the_search_line_labels_the_bar_on_a_terminal_and_is_a_line_of_a_log():
    import io

    from trackbench.study.execute.progress import StudyProgress

    term = io.StringIO()
    p = StudyProgress(0, 10, stream=term, workers=2, terminal=True, line="search: round 1")
    assert p.bar is None   # nothing to run yet: no bar
    p.search("search: 0/2 points done, round 2 of at most 4, 12 runs")
    p.more(2, 0)           # the next wave: the bar starts, labelled by the search's line
    p.update({"run_id": "a1", "status": "completed"})
    p.bar.refresh()
    p.close()
    text = re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]", "", term.getvalue())
    assert "search: 0/2 points done, round 2 of at most 4, 12 runs" in text and "done 1" in text
    log = io.StringIO()
    p = StudyProgress(10, 0, stream=log, workers=2, line="search: round 1")
    p.search("search: round 2")
    p.more(2, 1)
    p.close()
    assert log.getvalue().splitlines() == ["search: round 1", "10 runs to do, 0 already completed",
                                           "search: round 2", "2 runs to do, 1 already completed"]


def test_a_search_over_seeds_reads_as_the_median_of_the_seeds_limits(tmp_path):
    """Each seed's limit is a row of limits.csv; over_seeds gives per roughness the median of
    those found, their range and how many of the seeds found one; the limit curve draws it."""
    import pandas as pd

    from trackbench.study.read.limits import over_seeds
    limits = pd.DataFrame({
        "terrain.rms_in": [0.5, 0.5, 0.5, 1.0, 1.0, 1.0], "terrain.seed": [1, 2, 3, 1, 2, 3],
        "search_value": [12.0, 14.0, 13.5, 8.0, float("nan"), 9.0],
        "status": ["found", "found", "found", "found", "limit_exceeded_at_low", "found"],
        "runs": [5] * 6, "limit_run": ["a"] * 6})
    m = over_seeds(limits)
    assert m["median"].tolist() == [13.5, 8.5] and m["min"].tolist() == [12.0, 8.0]
    assert m["max"].tolist() == [14.0, 9.0] and m["found"].tolist() == [3, 2]
    assert m["seeds"].tolist() == [3, 3]
    pytest.importorskip("matplotlib")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from trackbench.figures.limit_figures import _limit_curve
    search = {"parameter": "speed", "quantity": "absorbed_power", "limit": 6.0, "tolerance": 1.0,
              "low": 2.0, "high": 16.0}
    path = _limit_curve(limits, ["terrain.rms_in", "terrain.seed"], search, tmp_path, plt)
    assert path.is_file() and path.stat().st_size > 10_000
