"""Study files (TOML): parse, validate and expand into runs before anything starts.

    [study]     name, description, output, replicates, storage ("full" or "compact")
    [scenario]  the base scenario (anything left out takes the paper's value)
    [grid]      cartesian axes: name = [values] | {start, stop, step} | {start, stop, num}
    [[zip]]     axes varied together (equal lengths), crossed with [grid]
    [[runs]]    explicit runs: each a table of overrides on top of [scenario]
    [search]    one parameter searched for a limit at every point of the rest (search.py)

Every error is a ``StudyError`` with a one-line message naming the file and the culprit.
"""

import itertools
import json
import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from trackbench.scenario import Scenario, ScenarioError, parameter_names
from trackbench.solvers.registry import settings_tables
from trackbench.study.spec.rules import (
    MAX_RUNS,
    RANGE_KEYS,
    StudyError,
    check_name,
    expand_range,
    unknown,
)
from trackbench.study.spec.runid import run_id

TOP_KEYS = ("study", "scenario", "grid", "zip", "runs", "search")
STUDY_KEYS = ("name", "description", "output", "replicates", "storage")
REPLICATE_PERTURBATION = 1e-9  # m


@dataclass
class Run:
    """One run of a study: its id, where it sits in the grid and its resolved scenario."""
    run_id: str
    index: int
    variant: int
    replicate: int
    params: dict          # dotted name -> value varied by the study (grid, zip, runs)
    scenario: dict        # fully resolved scenario (Scenario.to_dict())


@dataclass
class Study:
    name: str
    description: str
    source: Path
    output: Path
    replicates: int
    base: dict            # resolved base scenario
    axes: dict = field(default_factory=dict)       # the expanded [grid]
    zips: list = field(default_factory=list)       # the expanded [[zip]] groups
    explicit: list = field(default_factory=list)   # the [[runs]] tables
    runs: list = field(default_factory=list)
    param_names: list = field(default_factory=list)
    storage: str = "full"  # how the runs' files are stored (trackbench/storage.py)
    search: object = None  # the [search] table (search.SearchSpec) or None
    points: list = field(default_factory=list)     # with [search]: the grid points searched, in order
    base_scenario: object = field(default=None, repr=False, compare=False)  # the Scenario runs start from

    @property
    def runs_dir(self):
        return self.output / "runs"


def _axis_values(where, value):
    if isinstance(value, dict):
        vals = expand_range(where, value)
    elif isinstance(value, list):
        vals = value
    else:
        raise StudyError(f"{where} = {value!r}: expected a list of values or a range table "
                         "{start, stop, step} / {start, stop, num}")
    if not vals:
        raise StudyError(f"{where} is empty: the study would have no runs; give at least one value")
    return vals


def _unquoted_dotted(where, name, value):
    """An unquoted dotted key of an axis (terrain.height = [...]) reaches here as a table
    {'height': [...]} under 'terrain': say to quote it instead of reading it as a range."""
    if not isinstance(value, dict) or all(k in RANGE_KEYS for k in value):
        return
    if name != "terrain" and not any(p.startswith(name + ".") for p in parameter_names()):
        return
    k, v = next((k, v) for k, v in value.items() if k not in RANGE_KEYS)
    dotted = f"{name}.{k}"
    raise StudyError(f"{where}: {dotted} = ... is read by TOML as a table '{name}'; quote dotted names: "
                     f'"{dotted}" = {_toml_value(v) if not isinstance(v, dict) else "[...]"}')


def _param_value(v):
    """A summary-friendly value: scalars as they are, tables and lists as JSON text."""
    if isinstance(v, (dict, list)):
        return json.dumps(v, sort_keys=True)
    return v


def _variants(doc, path):
    """The list of override dicts (dotted names) the study asks for, in order."""
    axes, zips, explicit = {}, [], []
    grid = doc.get("grid")
    if grid is not None:
        if not isinstance(grid, dict):
            raise StudyError(f"{path}: [grid] must be a table of axes, e.g. speed = [5.0, 10.0]")
        if not grid:
            raise StudyError(f"{path}: [grid] is empty: give at least one axis, e.g. speed = [5.0, 10.0]")
        for name, value in flatten_axes(grid).items():
            _unquoted_dotted(f"{path}: [grid]", name, value)
            check_name(f"{path}: [grid]", name)
            axes[name] = _axis_values(f"{path}: [grid] {name}", value)
    zdoc = doc.get("zip", [])
    zdoc = [zdoc] if isinstance(zdoc, dict) else zdoc
    if not isinstance(zdoc, list):
        raise StudyError(f"{path}: [[zip]] must be tables of equal-length lists")
    for i, group in enumerate(zdoc):
        where = f"{path}: [[zip]] #{i + 1}"
        if not isinstance(group, dict) or not group:
            raise StudyError(f"{where} is empty: give two or more axes of equal length")
        g = {}
        for name, value in flatten_axes(group).items():
            _unquoted_dotted(where, name, value)
            check_name(where, name)
            if name in axes or any(name in z for z in zips):
                raise StudyError(f"{where}: '{name}' is varied twice (in [grid] or another [[zip]])")
            g[name] = _axis_values(f"{where} {name}", value)
        lengths = {n: len(v) for n, v in g.items()}
        if len(set(lengths.values())) > 1:
            raise StudyError(f"{where}: zipped axes must have equal lengths, got "
                             + ", ".join(f"{n}: {k}" for n, k in lengths.items()))
        zips.append(g)
    rdoc = doc.get("runs", [])
    if not isinstance(rdoc, list) or not all(isinstance(r, dict) for r in rdoc):
        raise StudyError(f"{path}: [[runs]] must be an array of tables, each a run's overrides")
    for i, r in enumerate(rdoc):
        flat = flatten_axes(r)
        for name in flat:
            check_name(f"{path}: [[runs]] #{i + 1}", name)
        explicit.append(flat)
    variants = []
    if axes or zips:
        groups = [[{n: v} for v in vals] for n, vals in axes.items()]
        groups += [[dict(zip(g, combo)) for combo in zip(*g.values())] for g in zips]
        for combo in itertools.product(*groups):
            v = {}
            for part in combo:
                v.update(part)
            variants.append(v)
    variants += explicit
    if grid is None and not zdoc and "runs" not in doc:
        variants = [{}]  # no grid at all: the base scenario, once
    if not variants:
        raise StudyError(f"{path}: the study has no runs: [[runs]] is empty")
    return variants, axes, zips, explicit


def flatten_axes(table):
    """{'vehicle': {'chassis_mass': [..]}} -> {'vehicle.chassis_mass': [..]} (also a solver's
    own settings table: solvers/registry.py); terrain stays whole unless given by dotted name."""
    out = {}
    for k, v in table.items():
        if isinstance(v, dict) and (k in ("vehicle", "track", "record") or k in settings_tables()):
            for k2, v2 in v.items():
                out[f"{k}.{k2}"] = v2
        else:
            out[k] = v
    return out


def _read_toml(path):
    try:
        text = Path(path).read_text()
    except OSError as e:
        raise StudyError(f"{path}: cannot read the study file: {e.strerror}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        msg = str(e)
        m = re.search(r"\s*\(at line (\d+), column (\d+)\)", msg)
        if m:
            line, col = int(m.group(1)), int(m.group(2))
        else:  # "(at end of document)": point after the last character
            lines = text.split("\n")
            line, col = len(lines), len(lines[-1]) + 1
            if not lines[-1] and len(lines) > 1:
                line, col = len(lines) - 1, len(lines[-2]) + 1
        msg = re.sub(r"\s*\(at [^)]*\)", "", msg)
        raise StudyError(f"{path}: TOML syntax error at line {line}, column {col}: {msg}") from None


def load_study(path, output=None):
    """Read, validate and expand a study file. ``output`` overrides the results folder."""
    path = Path(path)
    doc = _read_toml(path)
    for k in doc:
        if k not in TOP_KEYS:
            raise unknown(str(path), k, list(TOP_KEYS))
    meta = doc.get("study", {})
    if not isinstance(meta, dict):
        raise StudyError(f"{path}: [study] must be a table")
    for k in meta:
        if k not in STUDY_KEYS:
            raise unknown(f"{path}: [study]", k, list(STUDY_KEYS))
    name = meta.get("name", path.stem)
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_.-]+", name) or name.startswith("."):
        raise StudyError(f"{path}: [study] name = {name!r} is not allowed: expected letters, digits, _ . - "
                         "(it names the results folder)")
    desc = meta.get("description", "")
    if not isinstance(desc, str):
        raise StudyError(f"{path}: [study] description must be a text")
    reps = meta.get("replicates", 1)
    if not isinstance(reps, int) or isinstance(reps, bool) or not 1 <= reps <= 1000:
        raise StudyError(
            f"{path}: [study] replicates = {reps!r} is not allowed: expected an integer in [1, 1000]"
        )
    out = meta.get("output", f"results/{name}")
    if not isinstance(out, str) or not out:
        raise StudyError(f"{path}: [study] output must be a folder path (text)")
    base_doc = doc.get("scenario", {})
    if not isinstance(base_doc, dict):
        raise StudyError(f"{path}: [scenario] must be a table")
    base_doc = _files_beside(base_doc, path)
    try:
        base = Scenario.from_dict(base_doc, folder=str(path.parent))   # vehicle files beside the study
    except ScenarioError as e:
        raise StudyError(f"{path}: [scenario]: {e}") from None
    variants, axes, zips, explicit = _variants(doc, path)
    if len(variants) * reps > MAX_RUNS:
        raise StudyError(f"{path}: the study has {len(variants) * reps} runs; at most {MAX_RUNS}")
    study = Study(name=name, description=desc, source=path, output=Path(output or out), replicates=reps,
                  base=base.to_dict(), axes=axes, zips=zips, explicit=explicit, storage=_storage(path, meta),
                  base_scenario=base)
    pairs = list(enumerate(variants))
    if "search" in doc:
        pairs = _search_pairs(study, doc["search"], variants, path)
    names = []
    for _, v in pairs:
        names += [n for n in v if n not in names]
    if reps > 1:
        names += [n for n in ("seed",) if n not in names]
    study.param_names = names
    seen = {}
    for vi, over in pairs:
        for r in range(reps):
            run = _make_run(study, vi, over, r, path)
            if run.run_id in seen:
                a = seen[run.run_id]
                raise StudyError(
                    f"{path}: duplicate runs: run {a.variant + 1} and run {vi + 1} resolve to the "
                    f"same scenario ({', '.join(f'{k} = {x}' for k, x in run.params.items()) or 'base'})"
                )
            seen[run.run_id] = run
            study.runs.append(run)
    if study.search is not None:
        from trackbench.outputs import quantities as Q
        from trackbench.study.spec.search import check_held_speed, check_quantity
        wheels, features = Q.shape_of(r.scenario for r in study.runs)
        check_quantity(str(path), study.search, Q.summary_columns(wheels, features=features))
        check_held_speed(str(path), study.search, [r.scenario for r in study.runs])
    return study


def _files_beside(base_doc, path):
    """The base scenario with a measured profile's file (terrain.file) taken against the study
    file's folder when it is relative, as a reader of the study file would take it."""
    def beside(file):
        return str(path.parent / file) if isinstance(file, str) and not Path(file).is_absolute() else file

    terrain = base_doc.get("terrain")
    if isinstance(terrain, dict) and "file" in terrain:
        base_doc = {**base_doc, "terrain": {**terrain, "file": beside(terrain["file"])}}
    if "terrain.file" in base_doc:   # the dotted form
        base_doc = {**base_doc, "terrain.file": beside(base_doc["terrain.file"])}
    return base_doc


def _make_run(study, vi, over, r, path):
    """Run ``r`` (replicate) of the grid point ``vi`` with the overrides ``over``."""
    try:
        sc = study.base_scenario.with_overrides({**over, "name": study.name})
    except ScenarioError as e:
        desc_v = ", ".join(f"{k} = {_param_value(x)}" for k, x in over.items()) or "the base scenario"
        raise StudyError(f"{path}: run {vi + 1} ({desc_v}): {e}") from None
    d = sc.to_dict()
    params = {k: _param_value(x) for k, x in over.items()}
    if study.replicates > 1:
        d["seed"] = r + 1
        if d["perturbation"] == 0.0:
            d["perturbation"] = REPLICATE_PERTURBATION
        params["seed"] = r + 1
    return Run(run_id=run_id(d), index=len(study.runs), variant=vi, replicate=r, params=params, scenario=d)


def _search_pairs(study, table, variants, path):
    """With [search]: the grid points (study.points) and the scan's (point, overrides) pairs."""
    from trackbench.study.spec.search import parse_search
    varied = {n for v in variants for n in v}
    study.search = parse_search(str(path), table, varied)
    if study.replicates > 1:
        raise StudyError(f"{path}: [search] takes one run per value: [study] replicates = "
                         f"{study.replicates} is not allowed with it (use 1)")
    study.points = variants
    xs = study.search.scan_values()
    return [(vi, {**v, study.search.parameter: x}) for vi, v in enumerate(variants) for x in xs]


def search_run(study, variant, value):
    """The run of grid point ``variant`` at ``value`` of the searched parameter: the study's run
    when it has it, else a new one (the run id a grid with that value gives) added to
    study.runs; None when the study cannot make runs (read from its results folder)."""
    name = study.search.parameter
    for run in study.runs:
        if run.variant == variant and run.params.get(name) == value:
            return run
    if study.base_scenario is None:
        return None
    run = _make_run(study, variant, {**study.points[variant], name: value}, 0, study.source)
    study.runs.append(run)
    return run


def _storage(path, meta):
    from trackbench.outputs.files.storage import check_storage
    try:
        return check_storage(meta.get("storage", "full"), f"{path}: [study] storage =")
    except ValueError as e:
        raise StudyError(str(e)) from None


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        if math.isnan(v):
            return "nan"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _toml_key(k):
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else json.dumps(k)


def resolved_toml(study):
    """The resolved copy of the study: full base scenario, ranges expanded."""
    lines = [
        f"# resolved copy of {study.source}: {len(study.runs)} runs",
        "",
        "[study]",
        f"name = {_toml_value(study.name)}",
        f"description = {_toml_value(study.description)}",
        f"replicates = {study.replicates}",
        f"storage = {_toml_value(study.storage)}",
        "",
        "[scenario]",
    ]
    tables = []
    for k, v in study.base.items():
        if k == "name":
            continue
        if isinstance(v, dict) and k != "terrain":
            tables.append((k, v))
        else:
            lines.append(f"{_toml_key(k)} = {_toml_value(v)}")
    for k, v in tables:
        lines += ["", f"[scenario.{k}]"] + [f"{_toml_key(a)} = {_toml_value(b)}" for a, b in v.items()]
    if study.axes:
        lines += ["", "[grid]"] + [f"{_toml_key(k)} = {_toml_value(v)}" for k, v in study.axes.items()]
    for g in study.zips:
        lines += ["", "[[zip]]"] + [f"{_toml_key(k)} = {_toml_value(v)}" for k, v in g.items()]
    for r in study.explicit:
        lines += ["", "[[runs]]"] + [f"{_toml_key(k)} = {_toml_value(v)}" for k, v in r.items()]
    if study.search is not None:
        lines += ["", "[search]"] + [f"{k} = {_toml_value(v)}" for k, v in study.search.as_dict().items()]
    return "\n".join(lines) + "\n"

