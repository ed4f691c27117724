"""The linter's verdict is part of the test suite: ruff, configured in pyproject.toml (line
length 110, pycodestyle errors, pyflakes, import order), finds nothing in the repository."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.skipif(
    shutil.which("ruff") is None and not Path(sys.executable).with_name("ruff").exists(),
    reason="ruff is not installed (pip install -e '.[test]')",
)
def test_ruff_finds_nothing():
    ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    run = subprocess.run([ruff, "check", "--no-cache", str(ROOT)], capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]


@pytest.mark.skipif(
    shutil.which("mypy") is None and not Path(sys.executable).with_name("mypy").exists(),
    reason="mypy is not installed (pip install -e '.[test]')",
)
def test_the_public_api_type_checks():
    """The API (Scenario, simulate, open_study, open_study_dataset, open_limits) and the command
    line's functions carry type hints, and mypy (configured in pyproject.toml) finds no error."""
    mypy = shutil.which("mypy") or str(Path(sys.executable).with_name("mypy"))
    run = subprocess.run([mypy, "--no-incremental"], capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]
