"""`trackbench run`: one scenario from the command line, its file and its summary."""

import sys
import tomllib
from pathlib import Path

from trackbench.model.ground.soil import SOIL_CHOICES
from trackbench.outputs.quantities import accounted_balance
from trackbench.outputs.variables import scenario_of
from trackbench.scenario import RULES, UNITS, Scenario, ScenarioError, flatten, paper_step
from trackbench.scenario.check_run import closed_default
from trackbench.scenario.parameters_table import (
    CLOSED_TOLERANCE,
    RANDOM_DEFAULTS,
    TERRAIN_KINDS,
    TERRAIN_RULES,
)
from trackbench.scenario.presets import PRESETS, preset_values


def parse_assignment(text):
    """'terrain.height=0.15' -> ('terrain.height', 0.15); values are read as TOML,
    bare words as text."""
    if "=" not in text:
        raise ScenarioError(f"--set {text!r}: expected NAME=VALUE, e.g. --set speed=15")
    key, raw = (s.strip() for s in text.split("=", 1))
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    return key, value


def scenario_from_sets(sets, duration=None):
    overrides = dict(parse_assignment(s) for s in sets)
    if duration is not None:
        overrides["duration"] = duration
    return Scenario.from_dict(overrides)


def _time(t, digits):
    return "none" if t != t else f"{t:.{digits}f} s"


def _unmet(ds, contact):
    """Why no obstacle was met where the first one was placed by time after the run's end."""
    terrain = scenario_of(ds)["terrain"]
    first = (terrain.get("obstacles") or [terrain])[0]
    planned = first.get("first_contact_time")
    if contact == contact or planned is None or planned <= ds.attrs["t_final"]:
        return ""
    return f" (placed to be met at {planned:g} s, after the run's end at {ds.attrs['t_final']:g} s)"


def _energy_line(ds, s):
    """The paper's balance; where energy leaves on purpose (dampers, friction, soil, drawbar)
    or a drive puts it in, the balance with those counted (quantities.accounted_balance)."""
    tail = f"; work residual {s['max_energy_residual']:.2e}"
    accounted = accounted_balance(ds)
    if accounted is not None:
        closed, label = accounted
        dissipated = float(ds["energy_dissipated"][-1] - ds["energy_dissipated"][0])
        driven = f", drive work {float(ds['drive_work'][-1]) / 1e3:.1f} kJ" if "drive_work" in ds else ""
        return (f"  {label:33s} {100 * float(abs(closed).max()):.4f} % (dissipated "
                f"{dissipated / 1e3:.1f} kJ{driven}){tail}")
    err = 100 * s["max_energy_balance_error"]
    return f"  energy balance error              {err:.4f} % (paper: < 0.06 %){tail}"


def _integrator(ds):
    """The solver, its method and tolerance, as the run's attributes name them; the pins'
    velocities' own tolerance where the method held them to one."""
    a = ds.attrs
    text = f"{a['solver']} {a['method']} at tolerance {a['tolerance']:g}"
    if "tolerance_pin_velocity" in ds:
        text += f" (pins' velocities {float(ds.tolerance_pin_velocity):g})"
    if closed_default(scenario_of(ds)) and a["tolerance"] == CLOSED_TOLERANCE:
        text += " (the closed track's default; `tolerance` sets another)"
    return text


def format_summary(ds, path=None):
    from trackbench.outputs.dataset import summary_numbers
    from trackbench.outputs.quantities import BY_NAME as q
    from trackbench.outputs.quantities import SUMMARY
    s, a = summary_numbers(ds), ds.attrs
    lines = [f"trackbench run '{a['title'].split(': ', 1)[-1]}': {a['status']}"
             + ("" if a["status"] == "completed" else f" at t = {a['t_final']:.6g} s: {a['status_message']}")]
    wheel = q["peak_wheel_force_y"]
    lines.append(f"  {wheel.label} ({wheel.unit}) and time (s):")
    for w, f, t in zip(ds.wheel.values, ds.peak_wheel_force_y.values, ds.peak_wheel_force_y_time.values):
        lines.append(f"    wheel {int(w)}: {wheel.display(f):10.1f}  at {t:.4f}")

    def shown(name):  # the summary number of a quantity, in its display unit
        return s[q[name].display_key(name)]

    def line(label, text):
        return f"  {label:34s}{text}"

    ground, tension, ay, vx = (q[n] for n in ("peak_ground_force_y", "peak_link_tension", "peak_chassis_ay",
                                                "min_chassis_vx"))
    contact, compression = q["first_contact_time"], q["first_compression_time"]
    lines += [
        line(
            ground.label,
            f"{shown(ground.name):10.1f} {ground.unit} at {float(ds.peak_ground_force_y_time):.4f} s",
        ),
        line(tension.label, f"{shown(tension.name):10.1f} {tension.unit}"),
        line(
            "chassis vertical acceleration",
            f"{shown('min_chassis_ay'):+.2f} .. {shown(ay.name):+.2f} {ay.unit}",
        ),
        line(vx.label, f"{shown(vx.name):.4f} {vx.unit}"),
        _seat_line(ds, shown, line),
        line(
            contact.label,
            f"{_time(shown(contact.name), 5)}{_unmet(ds, shown(contact.name))}; "
            f"{compression.label} {_time(shown(compression.name), 4)}",
        ),
    ]
    # the closed track's and the soil's own (sprocket torque, tensioner force, sinkage, pull, slip)
    lines += [
        line(x.label, f"{shown(x.name):10.2f} {x.unit}") for x in SUMMARY if x.needs and x.variable in ds
    ]
    lines += [
        _energy_line(ds, s),
        f"  {_integrator(ds)}: steps {a['steps']} (+{a['rejected_steps']} rejected), wall time "
        f"{a['wall_time']:.3f} s",
    ]
    lines += _ranges_note(ds, shown(compression.name))
    for p in ([path] if isinstance(path, (str, Path)) else path or []):
        lines.append(f"  written: {p}")
    return "\n".join(lines)


# The peaks measured ill-conditioned on the driven models' step run (the closed, damped track,
# mu 0.6, speed drive at 10 m/s over the paper's step; benchmarks/accuracy.py): eight dopri5 runs
# at 1e-11 nudged by 1e-7 m spread them by 0.5 % or more (the spread in %), every other peak by
# less. docs/validation.md, "Judging a driven run".
ILL_CONDITIONED = {
    "regularised": {"peak_wheel5_force_y": 8.4, "min_chassis_ay": 4.5},
    "bristle": {"peak_wheel5_force_y": 0.66},
    "lete_sand": {"min_chassis_ay": 2.3},
}


def _measured_model(sc):
    """The ILL_CONDITIONED key of a run that is a measured driven step run, else None."""
    terrain = sc.get("terrain", {})
    c = sc.get("contact", {})
    step = terrain.get("kind") == "step" and terrain.get("height") == 0.1 and "obstacles" not in terrain
    driven = sc.get("drive", {}).get("kind") == "speed" and sc.get("drive", {}).get("target") == 10.0
    if not (sc.get("track", {}).get("layout") == "closed" and sc.get("preset") == "damped" and step and driven
            and sc.get("speed") == 10.0 and c.get("friction") == 0.6):
        return None
    soil = terrain.get("soil", "rigid")
    return soil if soil != "rigid" else c.get("friction_law")


def _ranges_note(ds, compression):
    """Which peaks to compare as ranges: on a measured driven step run, those measured
    ill-conditioned (ILL_CONDITIONED); on another run with a link compression, every later one."""
    from trackbench.outputs.quantities import quantity_of

    measured = ILL_CONDITIONED.get(_measured_model(scenario_of(ds)))
    if measured:
        names = []
        for column, spread in measured.items():
            q, wheel = quantity_of(column)
            names.append(f"{q.label}{f' (wheel {wheel})' if wheel else ''}, {spread:g} %")
        return [f"  note: ill-conditioned on this run, compare as ranges: {'; '.join(names)} (spread over "
                "runs nudged by 1e-7 m); every other peak reproduces to 0.5 %."]
    if compression == compression:  # a link went into compression
        return ["  note: peaks after the first compression are sensitive to tiny changes (chaotic motion); "
                "compare them as ranges."]
    return []


def _seat_line(ds, shown, line):
    """The driver's seat: its peak through the 30 Hz low-pass and the ride figures of the run's
    second half (NaN where the samples are too far apart for the weightings)."""
    peak = shown("peak_seat_acceleration_g")
    if peak != peak:
        return line("driver's seat", "- (ride metrics need output_interval <= 1/250 s)")
    # a run that stopped early: the least the whole run's could be (outputs/metrics/ride.py)
    least = "" if ds.attrs["status"] == "completed" else "at least "
    return line("driver's seat", f"{least}{peak:.3f} g at {float(ds.peak_seat_acceleration_g_time):.4f} s "
                f"(30 Hz); 2nd half: {least}{shown('absorbed_power'):.3g} W absorbed, Wk RMS "
                f"{shown('weighted_rms_acceleration'):.3g} m/s^2, VDV {shown('vdv'):.3g} m/s^1.75")


DEFAULT_NAME = "paper_step"


def run_name(name, sc):
    """The run's name (the file name): --name, else --set name=..., else paper_step; one that
    would not be a plain file name raises ScenarioError."""
    given = sc.to_dict().get("name")
    if name is not None and given not in (None, DEFAULT_NAME, name):
        raise ScenarioError(f"--name {name!r} and --set name={given!r} disagree: give the name once")
    name = name if name is not None else (given or DEFAULT_NAME)
    if not name or name.startswith(".") or any(c in name for c in "/\\\0") or not name.isprintable():
        raise ScenarioError(f"name {name!r} is not allowed: it names the files, so no /, \\, leading dot "
                            "or control characters, e.g. --name fast_step")
    return name


def run_one(sets, duration, out, name=None, force=False, storage="full"):
    """Run, write OUT/NAME.nc (+ NAME.rrd) as ``storage`` says (trackbench/storage.py); a
    failed run is kept for diagnosis as NAME.failed.nc, never under the name of a complete
    result. Existing files of that name are only replaced with force. NAME: ``name``, else the
    scenario's name (--set name=...), else paper_step. Returns (text, ok)."""
    from trackbench.outputs.files.atomic import writable_folder
    from trackbench.outputs.files.storage import check_storage
    try:
        check_storage(storage)
    except ValueError as e:
        raise ScenarioError(str(e)) from None
    sc = scenario_from_sets(sets, duration)   # bad input fails here, before the solver libraries load
    name = run_name(name, sc)
    sc = sc.with_overrides({"name": name})
    try:
        writable_folder(out)
    except ValueError as e:
        raise ScenarioError(f"--out {e}") from None
    targets = [Path(out) / f"{name}{ext}" for ext in (".nc", ".rrd", ".failed.nc")]
    existing = [p for p in targets if p.exists()]
    if existing and not force:
        hint = (
            "give this run its own name with --name NAME" if name == DEFAULT_NAME else "choose another --name"
        )
        raise ScenarioError(f"{existing[0]} exists: {hint} (or another --out), or --force to replace it")
    from trackbench._jitcache import CompileNotice
    from trackbench.outputs.recording.record import maybe_write_recording
    with CompileNotice(sys.stderr) as compiled:
        ds, path = _run_to_file(sc, targets, storage)
    ok = ds.attrs["status"] == "completed"
    for stale in existing:
        if stale != path and not (ok and stale == targets[1]):
            stale.unlink(missing_ok=True)
    paths = [path]
    if ok:
        rrd = maybe_write_recording(ds, Path(out), name=f"{name}.rrd", storage=storage)
        if rrd is None:
            targets[1].unlink(
                missing_ok=True
            )  # recording off: no stale recording of an earlier run beside it
        else:
            paths.append(rrd)
    text = format_summary(ds, paths)
    ds.close()
    if compiled.seconds > 0.0:
        text += (
            f"\n  of the wall time, {compiled.seconds:.1f} s compiling "
            "(once: later runs load the model from the cache)"
        )
    return text, ok


def _run_to_file(sc, targets, storage):
    """(Dataset, path): a long run streamed to its file and opened from it lazily (its memory
    does not grow with its duration: trackbench/stream.py), any other built in memory and
    written whole."""
    from trackbench.run.stream import stream_run, streamable
    if streamable(sc, storage):
        import netCDF4
        import xarray as xr
        path, _ = stream_run(sc, targets[0], targets[2])
        # the summary and the recording read the file block by block, each chunk once: HDF5's
        # cache (64 MB a variable by default) would keep every chunk read
        cache = netCDF4.get_chunk_cache()
        netCDF4.set_chunk_cache(size=1, nelems=1)
        try:
            return xr.open_dataset(path, cache=False), path
        finally:
            netCDF4.set_chunk_cache(*cache)
    from trackbench.outputs.files.netcdf import write_netcdf
    from trackbench.run.simulate import simulate
    ds = simulate(sc)
    ok = ds.attrs["status"] == "completed"
    return ds, write_netcdf(ds, targets[0] if ok else targets[2], storage)


def parameter_table():
    base = flatten({k: v for k, v in paper_step().items() if k != "terrain"})
    rows = [f"{'name':32s} {'paper value':>16s}  {'unit':9s} allowed"]

    def row(name, value, allowed):
        return f"{name:32s} {value:>16s}  {UNITS.get(name, ''):9s} {allowed}"

    for k, rule in RULES.items():
        rows.append(row(k, str(base.get(k, "")), rule[3]))
    rows.append(row("terrain.kind", "step", ", ".join(TERRAIN_KINDS)))
    rows.append(
        "terrain.height / length / position / first_contact_time / gap / points / obstacles: see README"
    )
    for k in ("roughness_class", "rms", "seed", "wavelength_min", "wavelength_max", "run_in", "file"):
        default = RANDOM_DEFAULTS.get(k, "")
        kind = "profile" if k == "file" else "random"
        rows.append(row("terrain." + k, str(default), f"{TERRAIN_RULES[k][3]} (kind {kind})"))
    rows.append(
        row("terrain.soil", "rigid", "rigid, " + ", ".join(SOIL_CHOICES[1:]) + ", or a table (docs/usage.md)")
    )
    for name in PRESETS:
        if name == "paper":
            continue
        rows.append(f"\npreset = \"{name}\" sets (explicit parameters win; derivation: docs/model.md):")
        for k, v in preset_values(name, paper_step()).items():
            rows.append(f"  {k:30s} {str(v):>16s}")
    return "\n".join(rows)
