"""The code stays readable: no function in trackbench/ longer than one screen or with a
parameter list nobody can follow (bundle the arrays instead: model/core/bundles.py), no
compiled function without the shared compile options (model/core/jit.py), no file over 450
lines, no two modules of one name, a code map (docs/development.md) that matches the tree,
and plain modules that never load the compiler."""

import ast
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "trackbench"
CODE_MAP = ROOT.parent / "docs" / "development.md"
MAX_FILE_LINES = 450
MAX_LINES = 80
MAX_PARAMS = 12


def _functions():
    for path in sorted(ROOT.rglob("*.py")):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                yield path.relative_to(ROOT.parent), node


def test_functions_fit_on_a_screen():
    long = [
        f"{p}:{f.lineno} {f.name} ({f.end_lineno - f.lineno + 1} lines)"
        for p, f in _functions()
        if f.end_lineno - f.lineno + 1 > MAX_LINES
    ]
    assert not long, "functions over 80 lines: " + "; ".join(long)


def test_short_parameter_lists():
    def count(a):
        return len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs)

    many = [
        f"{p}:{f.lineno} {f.name} ({count(f.args)})" for p, f in _functions() if count(f.args) > MAX_PARAMS
    ]
    assert not many, "functions over 12 parameters: " + "; ".join(many)


def test_every_njit_uses_the_shared_options():
    loose = []
    for p, f in _functions():
        for d in f.decorator_list:
            if isinstance(d, ast.Call) and getattr(d.func, "id", None) == "njit":
                if not any(k.arg is None for k in d.keywords):  # njit(**KERNEL) / njit(**INLINE)
                    loose.append(f"{p}:{f.lineno} {f.name}")
            elif isinstance(d, ast.Name) and d.id == "njit":
                loose.append(f"{p}:{f.lineno} {f.name}")
    assert not loose, "@njit without model/jit.py's options: " + "; ".join(loose)


def _modules():
    return sorted(p for p in ROOT.rglob("*.py") if "__pycache__" not in p.parts)


def test_files_fit_in_a_sitting():
    long = [
        f"{p.relative_to(ROOT.parent)} ({n})"
        for p in _modules()
        if (n := len(p.read_text().splitlines())) > MAX_FILE_LINES
    ]
    assert not long, f"files over {MAX_FILE_LINES} lines: " + "; ".join(long)


def test_one_module_per_name():
    names = Counter(p.name for p in _modules() if p.name != "__init__.py")
    assert not [n for n, k in names.items() if k > 1], f"module names used twice: {names.most_common(3)}"


def _code_map():
    """The code map's block: (folders named, file names named)."""
    text = CODE_MAP.read_text()
    block = text[text.index("## Code map") : text.index("## Conventions")]
    block = re.sub(r"tests/\w+\.py", "", block)  # the tests are not in the map
    return set(re.findall(r"\b([a-z0-9_]+)/", block)), set(re.findall(r"\b([a-z0-9_]+\.py)\b", block))


def test_code_map_matches_the_tree():
    folders, files = _code_map()
    packages = {p.parent.name for p in _modules() if p.name == "__init__.py"} - {"trackbench"}
    assert packages <= folders, f"packages the code map does not name: {sorted(packages - folders)}"
    present = {p.name for p in _modules()}
    assert files <= present, f"the code map names modules that do not exist: {sorted(files - present)}"
    unnamed = sorted(p.name for p in _modules() if p.name != "__init__.py" and p.name not in files)
    assert not unnamed, f"modules the code map does not name: {unnamed}"


# plain modules: numpy only (scenario validation, the command line and studies import them)
PLAIN = [
    "trackbench.model.contact.laws",
    "trackbench.model.ground.soil",
    "trackbench.model.ground.terrain",
    "trackbench.model.ground.rough",
    "trackbench.model.vehicle.teeth",
    "trackbench.model.vehicle.parameters",
    "trackbench.model.vehicle.closed_track",
    "trackbench.model.vehicle.track_path",
    "trackbench.model.core.indices",
    "trackbench.scenario",
    "trackbench.solvers.registry",
    "trackbench.outputs.metrics.ride",
]


def test_plain_modules_never_import_numba():
    """Each plain module on its own, in a fresh process: importing it loads no numba (what
    they compute with the compiled elementary functions imports them inside the function)."""
    code = (
        "import importlib, sys\n"
        "bad = []\n"
        "for m in sys.argv[1:]:\n"
        "    importlib.import_module(m)\n"
        "    if 'numba' in sys.modules: bad.append(m); break\n"
        "print(bad)"
    )
    for module in PLAIN:
        out = subprocess.run([sys.executable, "-c", code, module], capture_output=True, text=True, check=True)
        assert out.stdout.strip() == "[]", f"importing {module} loads numba"


@pytest.mark.parametrize(
    "plain, compiled",
    [
        ("laws", "laws_jit"),
        ("soil", "soil_jit"),
        ("teeth", "teeth_jit"),
        ("indices", "indices_jit"),
        ("closed_track", "closed_track_jit"),
        ("ride_metrics", "ride_metrics_jit"),
    ],
)
def test_plain_and_compiled_twins_are_named_alike(plain, compiled):
    names = {p.stem for p in _modules()}
    assert plain in names and compiled in names
