"""The command line starts fast: help, the parameter list and the errors of bad input
need none of the heavy libraries (numba, xarray, pandas, rerun, matplotlib, dask)."""

import subprocess
import sys

HEAVY = ("numba", "xarray", "pandas", "rerun", "matplotlib", "dask")

CODE = """
import sys
from typer.testing import CliRunner
from trackbench.cli.app import app
runner = CliRunner()
outs = [runner.invoke(app, args) for args in (["--help"], ["params"], ["study", "run", sys.argv[1]],
                                                ["run", "--set", "speeed=3"])]
print([r.exit_code for r in outs])
print(outs[2].output.strip().splitlines()[-1] if outs[2].output.strip() else "")
print(outs[3].output.strip().splitlines()[-1] if outs[3].output.strip() else "")
print(sorted(m for m in %r if m in sys.modules))
""" % (HEAVY,)


def test_help_params_and_bad_input_load_no_heavy_library(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[study]\nname = "bad"\n[scenario]\nsped = 10\n')
    out = subprocess.run([sys.executable, "-c", CODE, str(bad)], capture_output=True, text=True, check=True)
    codes, study_err, run_err, loaded = out.stdout.strip().splitlines()
    assert codes == "[0, 0, 2, 2]"
    assert "unknown parameter 'sped'" in study_err and "speed" in study_err
    assert "unknown parameter 'speeed'" in run_err
    assert loaded == "[]", f"heavy libraries imported: {loaded}"


def test_run_that_cannot_start_says_why_in_one_line(tmp_path):
    """A soil too soft for the vehicle: no equilibrium, a one-line error that says how deep
    it would sink, exit code 1, nothing written."""
    from typer.testing import CliRunner

    from trackbench.cli.app import app

    out = tmp_path / "out"
    r = CliRunner().invoke(
        app,
        [
            "run",
            "--set",
            "terrain.kind=flat",
            "--set",
            "terrain.soil=heavy_clay",
            "--set",
            "speed=0",
            "--duration",
            "0.01",
            "--out",
            str(out),
        ],
    )
    assert r.exit_code == 1
    # on a cold numba cache (a fresh clone) the compile notice comes first: it is not the error
    lines = [x for x in r.output.strip().splitlines() if not x.startswith("compiling the model")]
    assert (
        len(lines) == 1
        and lines[0].startswith("error: static equilibrium not found")
        and "track.width" in lines[0]
    )
    assert not out.exists() or not any(out.iterdir())


def test_validating_a_study_of_the_paper_layout_loads_no_compiler():
    """The coordinator of `study run` and `study status` validate every run: with the paper's
    layout that needs no numba (the workers' server loads it meanwhile)."""
    code = (
        "import sys; from trackbench.study.spec.study_file import load_study; s = load_study(sys.argv[1]); "
        "print(len(s.runs), sorted(m for m in %r if m in sys.modules))" % (HEAVY,)
    )
    out = subprocess.run([sys.executable, "-c", code, "studies/speed_sweep.toml"], capture_output=True,
                         text=True, check=True)
    assert out.stdout.split() == ["15", "[]"]


def test_the_checks_track_path_is_the_models():
    """The geometry checks measure the taut path with numpy's cos and sin; the model lays its
    pins along the same path with the compiled ones: the same wheels, the same length."""
    import numpy as np

    import trackbench as tb
    from trackbench.model.vehicle.parameters import wheel_centres_body
    from trackbench.model.vehicle.track_path import initial_track
    from trackbench.scenario.check_vehicle import _taut_length, wheel_centres_for_checks

    sc = tb.Scenario.paper()
    v, tr = sc["vehicle"], sc["track"]
    wc = wheel_centres_body(v)
    assert np.allclose(wheel_centres_for_checks(v), wc, rtol=0, atol=1e-15)
    ends = np.array([v["front_track_end"], v["rear_track_end"]], float)
    rho = v["wheel_radius"] + tr["pad_wheel"]
    assert abs(_taut_length(ends, wc, rho) - initial_track(ends, wc, rho, tr["n_links"])[1]) < 1e-12
