"""The command line starts fast: help, the parameter list and the errors of bad input
need none of the heavy libraries (numba, xarray, pandas, rerun, matplotlib, dask)."""

import subprocess
import sys

HEAVY = ("numba", "xarray", "pandas", "rerun", "matplotlib", "dask")

CODE = """
import sys
from typer.testing import CliRunner
from trackbench.cli import app
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
