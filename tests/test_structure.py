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
    "trackbench.vehicles",
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
        ("ride", "ride_jit"),
    ],
)
def test_plain_and_compiled_twins_are_named_alike(plain, compiled):
    names = {p.stem for p in _modules()}
    assert plain in names and compiled in names


# --- the rooms and their arrows ------------------------------------------------------

# each room's floor: a module imports from its own floor or below, never above (the package's
# __init__ is the API, above all). scenario/ is data every room reads; warm/ only cli/ reads.
FLOORS = {"_jitcache": 0, "status": 0, "version": 0, "vehicles": 0, "model": 1, "scenario": 2, "solvers": 2,
          "run": 3, "outputs": 3, "study": 4, "figures": 4, "cli": 5, "warm": 5}


def _module_name(path):
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts), parts[-1] == "__init__"


def _imports():
    """{module: {modules it imports, at its top or inside a function}} within trackbench."""
    names = {_module_name(p)[0] for p in _modules()}
    graph = {}
    for path in _modules():
        here, is_pkg = _module_name(path)
        base = here.split(".") if is_pkg else here.split(".")[:-1]
        out = graph.setdefault(here, set())
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                out.update(a.name for a in node.names if a.name in names)
            elif isinstance(node, ast.ImportFrom):
                mod = node.module or ""
                if node.level:
                    mod = ".".join(base[: len(base) - node.level + 1] + ([mod] if mod else []))
                if not mod.startswith("trackbench"):
                    continue
                subs = [f"{mod}.{a.name}" for a in node.names if f"{mod}.{a.name}" in names]
                out.update(subs or [mod])
    return graph


def _cycles(graph):
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_import_cycle():
    graph = {m: {w for w in ws if not m.startswith(w + ".")} for m, ws in _imports().items()}
    assert not _cycles(graph), f"modules that import each other: {_cycles(graph)}"


def _room(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def test_rooms_import_downwards():
    up = sorted(
        f"{m} -> {w}"
        for m, ws in _imports().items() if _room(m) is not None
        for w in ws if _room(w) is not None and FLOORS[_room(w)] > FLOORS[_room(m)]
    )
    assert not up, "imports that run back up: " + "; ".join(up)


def test_only_the_command_line_reaches_the_start_up_corner():
    reach = sorted(f"{m} -> {w}" for m, ws in _imports().items() if _room(m) not in ("cli", "warm")
                   for w in ws if _room(w) == "warm")
    assert not reach, "modules below the command line that import trackbench.warm: " + "; ".join(reach)


def test_the_package_works_without_its_start_up_corner(tmp_path):
    """A copy of the package without warm/ imports every module outside cli/, and its command
    line starts: the corner can go by touching the command line only."""
    import shutil
    copy = tmp_path / "trackbench"
    shutil.copytree(ROOT, copy, ignore=shutil.ignore_patterns("__pycache__", "warm"))
    code = (
        "import importlib, pkgutil, trackbench\n"
        "for m in pkgutil.walk_packages(trackbench.__path__, 'trackbench.'):\n"
        "    if not m.name.startswith(('trackbench.cli', 'trackbench.warm')):\n"
        "        importlib.import_module(m.name)\n"
        "assert 'trackbench.warm' not in __import__('sys').modules\n"
        "from trackbench.cli import app\n"
        "print(trackbench.__file__)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path,
                         env={**__import__("os").environ, "PYTHONPATH": str(tmp_path)})
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == str(copy / "__init__.py")
