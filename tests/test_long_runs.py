"""Steps chosen by the error control alone, samples from the dense output, and the output
rates of ride runs (docs/usage.md, "Output rates")."""

import numpy as np
import pytest

import trackbench as tb
from trackbench.outputs.files.storage import frame_step
from trackbench.run.simulate import controls

FLAT = {"terrain": {"kind": "flat"}, "duration": 0.2}


@pytest.fixture(scope="module")
def flat_runs():
    """The flat run sampled at 1e-4 s and at 1e-3 s, and capped at 1e-4 s as before."""
    return {
        "fine": tb.simulate(tb.Scenario.from_dict({**FLAT, "output_interval": 1e-4})),
        "coarse": tb.simulate(tb.Scenario.from_dict({**FLAT, "output_interval": 1e-3})),
        "capped": tb.simulate(tb.Scenario.from_dict({**FLAT, "output_interval": 1e-4, "max_step": 1e-4})),
    }


def test_steps_do_not_depend_on_the_output_interval(flat_runs):
    fine, coarse = flat_runs["fine"], flat_runs["coarse"]
    assert fine.attrs["steps"] == coarse.attrs["steps"]
    assert fine.attrs["rejected_steps"] == coarse.attrs["rejected_steps"]
    assert fine.attrs["max_step"] > 1e-3   # no longer held to either output interval
    assert fine.sizes["time"] == 2001 and coarse.sizes["time"] == 201
    # the same dense output read at the same times (the times differ in their last bits)
    for name in ("chassis_y", "pin_y", "wheel_force_y"):
        a, b = fine[name].values[::10], coarse[name].values
        assert np.allclose(a, b, rtol=1e-12, atol=1e-9), name
    # peaks are found along the steps, not read from the samples: the same whatever the sampling
    for name in ("peak_wheel_force_y", "peak_link_tension", "min_chassis_vx", "max_energy_residual"):
        assert np.array_equal(fine[name].values, coarse[name].values), name


def test_free_samples_agree_with_the_capped_run_to_the_tolerance(flat_runs):
    free, capped = flat_runs["fine"], flat_runs["capped"]
    assert free.attrs["steps"] < capped.attrs["steps"] / 3
    tol = free.attrs["tolerance"]
    for name in ("chassis_y", "chassis_pitch", "pin_x", "pin_y", "chassis_vy", "wheel_y"):
        diff = float(np.nanmax(np.abs(free[name].values - capped[name].values)))
        assert diff < 2 * tol, (name, diff)   # absolute tolerance 1e-9 (m, rad, m/s)


def test_the_paper_preset_keeps_its_cap_on_obstacles_only():
    paper = tb.Scenario.paper()
    assert controls(paper).h_max == paper["output_interval"] == 1e-4
    coarse = tb.Scenario.paper(output_interval=1e-3)
    assert controls(coarse).h_max == 1e-3   # as before: the paper's runs keep their bits
    flat = tb.Scenario.from_dict({"terrain": {"kind": "flat"}})
    assert flat["max_step"] == 0.0 and controls(flat).h_max == flat["duration"]
    damped = tb.Scenario.paper(preset="damped")
    assert damped["max_step"] == 0.0
    given = tb.Scenario.paper(preset="damped", max_step=2e-4)
    assert controls(given).h_max == 2e-4
    # a scenario moved from flat ground onto a step takes the paper's sampling and cap again
    moved = flat.with_overrides({"terrain": {"kind": "step", "height": 0.1}})
    assert moved["output_interval"] == 1e-4 and moved["max_step"] == 1e-4


def test_ride_ground_samples_and_records_at_the_ride_rates():
    flat = tb.Scenario.from_dict({"terrain": {"kind": "flat"}})
    assert flat["output_interval"] == 1e-3 and flat["record"]["every"] == 0
    assert frame_step(flat["record"], flat["output_interval"]) == 20    # 50 frames a second
    step = tb.Scenario.paper()
    assert frame_step(step["record"], step["output_interval"]) == 5     # impacts in slow motion
    given = tb.Scenario.from_dict({"terrain": {"kind": "flat"}, "record.fps": 30.0})
    assert frame_step(given["record"], given["output_interval"]) == 33
    every = tb.Scenario.from_dict({"terrain": {"kind": "flat"}, "record.every": 7, "output_interval": 1e-4})
    assert every["output_interval"] == 1e-4 and frame_step(every["record"], 1e-4) == 7
    assert frame_step({"every": 0, "fps": 1e4}, 1e-3) == 1   # never less than a sample a frame


@pytest.mark.parametrize("bad", [{"max_step": -1e-3}, {"record.fps": 0.0}, {"record.every": -1}])
def test_bad_rates_are_one_line_errors(bad):
    with pytest.raises(tb.ScenarioError) as e:
        tb.Scenario.from_dict(bad)
    assert "\n" not in str(e.value) and next(iter(bad)) in str(e.value)


def _prepared(scenario):
    from trackbench.run.simulate import prepare
    return prepare(scenario)


@pytest.mark.parametrize("overrides", [
    {"terrain": {"kind": "flat"}, "duration": 5.0},                                       # dopri5, 2 chunks
    {"preset": "damped", "duration": 0.3, "output_interval": 5e-5, "method": "ark436l2sa"},  # IMEX, 2 chunks
    # the closed track: dopri5's PI controller carries the last error over the pause
    {"preset": "damped", "track.layout": "closed", "drive.kind": "speed", "duration": 0.25,
     "output_interval": 5e-5, "terrain": {"kind": "flat"}},
])
def test_a_run_in_chunks_is_the_run_in_one_piece(overrides):
    """The loop pauses when its chunk is full and resumes with the same step: the samples,
    peaks, first contacts and statistics are those of the run in one piece, bit for bit."""
    sc = tb.Scenario.from_dict(overrides)
    whole = _prepared(sc)[-1]()
    run = _prepared(sc)[-1]
    bases, ys, ds = [], [], []

    def sink(base, y, diag, stats, peaks):
        bases.append(base)
        ys.append(y.copy())
        ds.append(diag.copy())

    part = run(sink=sink)
    assert len(bases) == 2 and bases[0] == 0 and bases[1] == ys[0].shape[0]
    assert np.array_equal(whole.y, np.concatenate(ys), equal_nan=True)
    assert np.array_equal(whole.diag, np.concatenate(ds), equal_nan=True)
    assert np.array_equal(whole.peaks, part.peaks, equal_nan=True)
    assert np.array_equal(whole.stats, part.stats)


@pytest.fixture(scope="module")
def long_flat():
    return tb.Scenario.from_dict({"terrain": {"kind": "flat"}, "duration": 5.0})


def test_a_streamed_file_reads_back_as_the_run(long_flat, tmp_path):
    import xarray as xr

    from trackbench.run.stream import stream_run, streamable
    assert streamable(long_flat) and not streamable(long_flat, "compact")
    assert not streamable(tb.Scenario.paper(duration=0.2))   # one chunk: built in memory
    path, ok = stream_run(long_flat, tmp_path / "run.nc", tmp_path / "run.failed.nc")
    assert ok and path == tmp_path / "run.nc" and [p.name for p in tmp_path.iterdir()] == ["run.nc"]
    ds = tb.simulate(long_flat)
    with xr.open_dataset(path) as f:
        assert set(f.variables) == set(ds.variables)
        for name in ds.variables:
            assert np.array_equal(ds[name].values, f[name].values, equal_nan=True), name
        for k, v in ds.attrs.items():
            if k not in ("wall_time", "solve_time"):
                assert f.attrs[k] == v, k


def test_a_stream_that_stops_leaves_no_file(long_flat, tmp_path, monkeypatch):
    import trackbench.run.stream as S
    calls = []

    def broken(self, ds):   # the second chunk never arrives (as a run killed halfway)
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return original(self, ds)

    original = S.Appender.append
    monkeypatch.setattr(S.Appender, "append", broken)
    with pytest.raises(KeyboardInterrupt):
        S.stream_run(long_flat, tmp_path / "run.nc", tmp_path / "run.failed.nc")
    assert list(tmp_path.iterdir()) == []


def test_a_streamed_run_that_fails_is_kept_as_failed(tmp_path):
    from trackbench.run.stream import stream_run
    sc = tb.Scenario.from_dict({"terrain": {"kind": "flat"}, "duration": 5.0, "max_steps": 10_000})
    path, ok = stream_run(sc, tmp_path / "run.nc", tmp_path / "run.failed.nc")
    assert not ok and path.name == "run.failed.nc" and not (tmp_path / "run.nc").exists()


def test_a_long_recording_is_written_block_by_block(tmp_path):
    """More samples than a block: every sample's plot row and every 20th sample's frame (and
    the last), in time order."""
    from rerun.chunk import RrdReader

    from trackbench.outputs.recording import entities as E
    from trackbench.outputs.recording import record as R
    ds = tb.simulate(tb.Scenario.from_dict({"terrain": {"kind": "flat"}, "duration": 9.0}))
    n = ds.sizes["time"]
    assert n > R.RECORD_BLOCK
    path = R.maybe_write_recording(ds, tmp_path, name="run.rrd")
    times = {E.E_CHASSIS: [], E.E_WHEEL_FY: []}
    for c in RrdReader(path).stream().to_chunks():
        if c.entity_path in times and E.TIMELINE in c.timeline_names:
            col = c.to_record_batch().column(E.TIMELINE).to_pylist()
            times[c.entity_path] += [t.total_seconds() if hasattr(t, "total_seconds") else t for t in col]
    frames, rows = sorted(times[E.E_CHASSIS]), sorted(times[E.E_WHEEL_FY])
    assert len(rows) == n and len(frames) == len(range(0, n, 20)) + (0 if (n - 1) % 20 == 0 else 1)
    assert np.allclose(frames[:3], [0.0, 0.02, 0.04]) and frames[-1] == pytest.approx(float(ds.time[-1]))


def test_the_step_cap_grows_with_the_simulated_time():
    """max_steps = 0 (the default) caps a run at 400,000 steps a simulated second, at least
    2,000,000 (a 20 s closed-track run takes about 3.2 million); a number caps it at that."""
    cap = {d: controls(tb.Scenario.from_dict({"terrain": {"kind": "flat"}, "duration": d})).max_steps
           for d in (0.5, 5.0, 20.0, 60.0)}
    assert cap == {0.5: 2_000_000, 5.0: 2_000_000, 20.0: 8_000_000, 60.0: 24_000_000}
    sc = tb.Scenario.from_dict({"terrain": {"kind": "flat"}, "duration": 20.0, "max_steps": 10_000})
    assert controls(sc).max_steps == 10_000
    with pytest.raises(tb.ScenarioError, match="max_steps = -1 is not allowed"):
        tb.Scenario.from_dict({"max_steps": -1})
