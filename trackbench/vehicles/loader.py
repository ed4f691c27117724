"""Reading a vehicle file: where it is (a catalogue name or a path), its TOML, its tables and
keys against the catalogue's reference file (lee2000.toml holds every name a vehicle file
may set), each mistake a one-line VehicleError naming the file and the key."""

import difflib
import functools
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).parent
GROUPS = ("vehicle", "track", "sprocket", "idler", "rollers")   # the tables of values
REFERENCE = "lee2000"   # the paper's vehicle: complete, so its names are every name allowed


class VehicleError(ValueError):
    """A vehicle file that cannot be used; the message is one line naming the file and the key."""


@dataclass(frozen=True)
class VehicleFile:
    name: str                  # the catalogue name, or the file's stem
    path: Path
    values: dict               # {dotted name: value} as the file gives them
    source: dict = field(default_factory=dict)   # the [source] table
    in_catalogue: bool = False

    @property
    def label(self):
        """How errors name the file: the catalogue name, or the path."""
        return f"vehicle '{self.name}'" if self.in_catalogue else str(self.path)

    @property
    def description(self):
        return str(self.source.get("description", ""))

    @property
    def reference(self):
        return str(self.source.get("reference", ""))


def catalogue():
    """The catalogue's vehicle names, the paper's first."""
    names = sorted(p.stem for p in HERE.glob("*.toml"))
    return [REFERENCE] + [n for n in names if n != REFERENCE]


def catalogue_path(name):
    return HERE / f"{name}.toml"


def locate(model, folder=None):
    """The file vehicle.model names: a catalogue name, else a path (relative ones against
    folder: the study file's, or the current one). (path, in_catalogue)."""
    if not isinstance(model, str) or not model.strip():
        raise VehicleError(f"vehicle.model = {model!r} is not allowed: expected a catalogue name "
                           f"({', '.join(catalogue())}) or a vehicle file (.toml)")
    if model in catalogue():
        return catalogue_path(model), True
    path = Path(model).expanduser()
    if not path.is_absolute():
        path = Path(folder or ".") / path
    if path.is_file():
        return path, False
    close = difflib.get_close_matches(model, catalogue(), n=1, cutoff=0.6)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    raise VehicleError(f"vehicle.model = '{model}': no such vehicle: not in the catalogue "
                       f"({', '.join(catalogue())}) and no file {path}{hint}")


def read(model, folder=None):
    """The VehicleFile vehicle.model names (read again when the file changes)."""
    path, in_catalogue = locate(model, folder)
    stat = path.stat()
    return _read(str(path.resolve()), stat.st_mtime_ns, stat.st_size, in_catalogue)


@functools.lru_cache(maxsize=32)
def _read(path, _mtime, _size, in_catalogue):
    p = Path(path)
    label = f"vehicle '{p.stem}'" if in_catalogue else path
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise VehicleError(f"{label}: not valid TOML: {e}") from None
    values = _values(label, doc)
    source = doc.get("source", {})
    if not isinstance(source, dict):
        raise VehicleError(f"{label}: source must be a table ([source]) of where the numbers come from")
    return VehicleFile(p.stem, p, values, source, in_catalogue)


def _values(label, doc):
    """{dotted name: value} of the file's tables, every name one the reference file has."""
    allowed = known_names() | OPTIONAL_NAMES
    out = {}
    for table, body in doc.items():
        if table == "source":
            continue
        if table not in GROUPS:
            close = difflib.get_close_matches(table, GROUPS, n=1, cutoff=0.5)
            hint = f"; did you mean [{close[0]}]?" if close else ""
            raise VehicleError(f"{label}: unknown table [{table}]{hint} allowed: [source], "
                               + ", ".join(f"[{g}]" for g in GROUPS))
        if not isinstance(body, dict):
            raise VehicleError(f"{label}: {table} must be a table ([{table}]) of values, not {body!r}")
        for key, value in body.items():
            name = f"{table}.{key}"
            if name not in allowed:
                close = difflib.get_close_matches(name, sorted(allowed), n=1, cutoff=0.6)
                hint = f"; did you mean {close[0]}?" if close else f"; see the names in {REFERENCE}.toml"
                raise VehicleError(f"{label}: unknown key {name}{hint}")
            out[name] = value
    return out


@functools.lru_cache(maxsize=1)
def known_names():
    """Every dotted name the reference file sets (the paper's vehicle, complete)."""
    doc = tomllib.loads(catalogue_path(REFERENCE).read_text(encoding="utf-8"))
    return frozenset(f"{g}.{k}" for g in GROUPS for k in doc.get(g, {}))


# the names a vehicle file may set that the paper's vehicle has not: the bump stops and the
# torsion bars' free angle (model/vehicle/parameters.ARM_OPTIONS, which a test holds alike)
OPTIONAL_NAMES = frozenset({"vehicle.jounce_stop_angle", "vehicle.rebound_stop_angle",
                            "vehicle.bump_stop_stiffness", "vehicle.torsion_free_angle"})
