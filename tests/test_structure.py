"""The code stays readable: no function in trackbench/ longer than one screen or with a
parameter list nobody can follow (bundle the arrays instead: model/bundles.py), and no
compiled function without the shared compile options (model/jit.py)."""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "trackbench"
MAX_LINES = 80
MAX_PARAMS = 12


def _functions():
    for path in sorted(ROOT.rglob("*.py")):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                yield path.relative_to(ROOT.parent), node


def test_functions_fit_on_a_screen():
    long = [f"{p}:{f.lineno} {f.name} ({f.end_lineno - f.lineno + 1} lines)"
            for p, f in _functions() if f.end_lineno - f.lineno + 1 > MAX_LINES]
    assert not long, "functions over 80 lines: " + "; ".join(long)


def test_short_parameter_lists():
    def count(a):
        return len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs)
    many = [f"{p}:{f.lineno} {f.name} ({count(f.args)})" for p, f in _functions() if count(f.args) > MAX_PARAMS]
    assert not many, "functions over 12 parameters: " + "; ".join(many)


def test_every_njit_uses_the_shared_options():
    loose = []
    for p, f in _functions():
        for d in f.decorator_list:
            if isinstance(d, ast.Call) and getattr(d.func, "id", None) == "njit":
                if not any(k.arg is None for k in d.keywords):   # njit(**KERNEL) / njit(**INLINE)
                    loose.append(f"{p}:{f.lineno} {f.name}")
            elif isinstance(d, ast.Name) and d.id == "njit":
                loose.append(f"{p}:{f.lineno} {f.name}")
    assert not loose, "@njit without model/jit.py's options: " + "; ".join(loose)
