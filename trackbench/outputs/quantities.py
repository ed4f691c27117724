"""The summary quantities of a run, in one table.

Every place that shows or stores a run's summary reads this table: the one-screen summary
of `trackbench run` (cli/single_run.format_summary, outputs/dataset.summary_numbers), a study
run's run.json ``results`` and summary.csv columns (study/execute/executors.py,
study/read/summary.py), the replicate statistics, the study table on screen, the study plots
and the solver text of a recording. The Dataset variables themselves are built by
outputs/dataset.py (SI units, with long_names).

Kinds: a "peak" is an extremum of the motion, stored with its time (``<column>_time``) and
given replicate statistics; a "mean" is a mean over the run's second half (t >= t_final / 2:
a steady value where the run settles), also given replicate statistics; an "event" is the
time something first happened; a "check" is an accuracy figure of the run. A quantity that
``needs`` a feature ("closed": the closed track; "soil": soft soil) is in a run's summary only
when the run has it, and in a study's when any of its runs has it.
"""

import math
import re
from dataclasses import dataclass

from trackbench.outputs.variables import scenario_of


@dataclass(frozen=True)
class Quantity:
    name: str            # summary column (run.json key); "{}" stands for the wheel number
    variable: str        # Dataset variable (SI units; along `wheel` when the name has "{}")
    kind: str            # "peak", "event" or "check" (module docstring)
    unit: str            # display unit
    per_unit: float      # SI value of one display unit: shown value = SI value / per_unit
    label: str           # words for people: summaries, plot legends
    heading: str | None  # column heading in the study table on screen ("{}": wheel number)
    late: bool           # decided after the motion turns chaotic (first link compression):
    #                      differs by 10-60 % between correct runs, compare as a range
    summary: bool = True  # in the summary (run.json, summary.csv, one-screen summary)
    needs: str = ""       # "closed" / "soil": that model's only (module docstring)

    @property
    def per_wheel(self):
        return "{}" in self.name

    def columns(self, n_wheels):
        """Summary column names, one per road wheel for a per-wheel quantity."""
        if self.per_wheel:
            return [self.name.format(w) for w in range(1, n_wheels + 1)]
        return [self.name]

    def present(self, columns):
        """This quantity's summary columns among ``columns``, in their order."""
        return [c for c in columns if c == self.name or self.wheel_of(c) is not None]

    def display(self, si_value):
        return si_value / self.per_unit

    def display_key(self, column):
        """output.summary_numbers' key: the column, with the unit when it is not SI."""
        return column if self.per_unit == 1 else f"{column}_{self.unit}"

    def wheel_of(self, column):
        """The wheel number of one of this quantity's columns, else None."""
        m = re.fullmatch(re.escape(self.name).replace(r"\{\}", r"(\d+)"), column) if self.per_wheel else None
        return int(m.group(1)) if m else None


Q = Quantity
TABLE = (
    Q(
        "peak_wheel{}_force_y",
        "peak_wheel_force_y",
        "peak",
        "kN",
        1e3,
        "peak vertical wheel-track force",
        "w{} kN",
        late=True,
    ),
    Q(
        "peak_ground_force_y",
        "peak_ground_force_y",
        "peak",
        "kN",
        1e3,
        "peak total ground force",
        "ground kN",
        late=True,
    ),
    Q(
        "peak_link_tension",
        "peak_link_tension",
        "peak",
        "kN",
        1e3,
        "peak link tension",
        "tension kN",
        late=True,
    ),
    Q(
        "min_link_tension",
        "min_link_tension",
        "peak",
        "kN",
        1e3,
        "min link tension",
        None,
        late=True,
        summary=False,
    ),
    Q(
        "peak_chassis_ay",
        "peak_chassis_ay",
        "peak",
        "m/s^2",
        1.0,
        "peak chassis vertical acceleration",
        "ay max m/s2",
        late=True,
    ),
    Q(
        "min_chassis_ay",
        "min_chassis_ay",
        "peak",
        "m/s^2",
        1.0,
        "min chassis vertical acceleration",
        "ay min m/s2",
        late=True,
    ),
    Q("min_chassis_vx", "min_chassis_vx", "peak", "m/s", 1.0, "min chassis speed", "vx min m/s", late=True),
    Q(
        "peak_sprocket_torque",
        "peak_sprocket_torque",
        "peak",
        "kN m",
        1e3,
        "peak drive torque on the sprocket",
        "sprk kNm",
        late=True,
        needs="closed",
    ),
    Q(
        "peak_idler_force",
        "peak_idler_force",
        "peak",
        "kN",
        1e3,
        "peak tensioner force",
        "idler kN",
        late=True,
        needs="closed",
    ),
    Q(
        "peak_sinkage",
        "peak_sinkage",
        "peak",
        "cm",
        1e-2,
        "deepest sinkage into the soil",
        "sink cm",
        late=True,
        needs="soil",
    ),
    Q(
        "mean_drawbar_pull",
        "mean_drawbar_pull",
        "mean",
        "kN",
        1e3,
        "mean drawbar pull, 2nd half",
        "pull kN",
        late=True,
        needs="soil",
    ),
    Q(
        "mean_slip",
        "mean_slip",
        "mean",
        "%",
        1e-2,
        "mean slip (sprocket), 2nd half",
        "slip %",
        late=True,
        needs="soil",
    ),
    # the driver's seat (ride_metrics.py): the obstacle criterion over the whole run, the ride
    # figures over its second half (results_schema.md)
    Q(
        "peak_seat_acceleration_g",
        "peak_seat_acceleration_g",
        "peak",
        "g",
        1.0,
        "peak seat acceleration, 30 Hz low-pass",
        "seat g",
        late=True,
    ),
    Q(
        "absorbed_power",
        "absorbed_power",
        "mean",
        "W",
        1.0,
        "absorbed power at the seat, 2nd half",
        "abs W",
        late=True,
    ),
    Q(
        "weighted_rms_acceleration",
        "weighted_rms_acceleration",
        "mean",
        "m/s^2",
        1.0,
        "Wk-weighted RMS seat acceleration, 2nd half",
        "aw m/s2",
        late=True,
    ),
    Q("vdv", "vdv", "mean", "m/s^1.75", 1.0, "vibration dose value, 2nd half", None, late=True),
    Q(
        "first_contact_time",
        "first_contact_time",
        "event",
        "s",
        1.0,
        "first obstacle contact",
        None,
        late=False,
    ),
    Q(
        "first_compression_time",
        "first_compression_time",
        "event",
        "s",
        1.0,
        "first link compression",
        "1st compr s",
        late=False,
    ),
    # whole-run maxima: set by a few contact switches that the chaotic motion places
    Q(
        "max_energy_balance_error",
        "max_energy_balance_error",
        "check",
        "1",
        1.0,
        "energy balance error",
        None,
        late=True,
    ),
    Q("max_energy_residual", "max_energy_residual", "check", "1", 1.0, "work residual", None, late=True),
)
del Q
BY_NAME = {q.variable: q for q in TABLE}
SUMMARY = tuple(q for q in TABLE if q.summary)
PEAKS = tuple(q for q in SUMMARY if q.kind in ("peak", "mean"))


def summary_columns(n_wheels, times=True, features=()):
    """The summary's result columns in order: each peak with its _time, then the rest
    (those of the models in ``features``, "closed" and "soil", where given)."""
    out = []
    for q in SUMMARY:
        if q.needs and q.needs not in features:
            continue
        for c in q.columns(n_wheels):
            out += [c, c + "_time"] if times and q.kind == "peak" else [c]
    return out


def shape_of(scenarios):
    """(most road wheels, the models that add quantities: "closed", "soil") of resolved scenarios:
    the columns a study's summary has."""
    wheels, features = 0, set()
    for sc in scenarios:
        wheels = max(wheels, int(sc["vehicle"]["n_wheels"]))
        if sc["track"].get("layout") == "closed":
            features.add("closed")
        if sc["terrain"].get("soil", "rigid") != "rigid":
            features.add("soil")
    return wheels, features


def peak_columns(n_wheels, features=()):
    """The peaks' and means' columns (those with replicate statistics)."""
    return [c for q in PEAKS if not q.needs or q.needs in features for c in q.columns(n_wheels)]


def quantity_of(column):
    """(quantity, wheel or None) of a summary column or of a peak's _time companion, else None."""
    for q in SUMMARY:
        if column == q.name or q.wheel_of(column) is not None:
            return q, q.wheel_of(column)
    if column.endswith("_time"):
        found = quantity_of(column[:-len("_time")])
        if found and found[0].kind == "peak":
            return found
    return None


def entries(ds):
    """(quantity, column, SI value, time or None) of a run's Dataset, in table order; plain
    floats, NaN kept (a run without a link compression has no first_compression_time)."""
    for q in SUMMARY:
        if q.needs and q.variable not in ds:
            continue
        v = ds[q.variable]
        t = ds[q.variable + "_time"] if q.kind == "peak" else None
        if q.per_wheel:
            for k, w in enumerate(ds["wheel"].values):
                yield q, q.name.format(int(w)), float(v.values[k]), None if t is None else float(t.values[k])
        else:
            yield q, q.name, float(v), None if t is None else float(t)


def values(ds, times=True):
    """column -> SI value of a run's summary quantities; with times, each peak's time as
    ``<column>_time`` after it (the order of summary_columns)."""
    out = {}
    for _, column, value, t in entries(ds):
        out[column] = value
        if times and t is not None:
            out[column + "_time"] = t
    return out


def without_nan(d):
    """NaN -> None (JSON null) in a dict of numbers."""
    return {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in d.items()}


def run_summary(ds):
    """The numbers of a run the summary shows (plain floats, SI units; NaN -> None)."""
    return without_nan(values(ds))


def tensioner_energy(ds):
    """The tensioner spring's potential along the idler's guide, U = -F0 s + k s^2 / 2 (s from
    the guide's middle, where the spring pushes with its preload F0), or None without an idler.
    The paper's balance (energy_elastic) leaves it out."""
    if "idler_position" not in ds:
        return None
    idler = scenario_of(ds)["idler"]
    s = ds["idler_position"].values
    return -idler["preload"] * s + 0.5 * idler["stiffness"] * s * s


def accounted_balance(ds):
    """The paper's balance error with the energy that left or entered on purpose counted:
    (deviation relative to E0 over time, label). What dampers, friction, soft soil and the
    drawbar took out (energy_dissipated) is added back, what the drive put in (drive_work)
    taken out, and the tensioner spring's energy counted with the elastic energy, so the
    deviation shows only the contact model's jumps and the integration. None where nothing
    applies (the paper's model: its own balance error is the figure)."""
    dissipated = ds["energy_dissipated"].values if "energy_dissipated" in ds else None
    driven = "drive_work" in ds
    if not driven and (dissipated is None or not (abs(dissipated) > 0.0).any()):
        return None
    net = dissipated - dissipated[0]
    label = "balance + dissipated"
    spring = tensioner_energy(ds)
    if spring is not None:
        net = net + spring - spring[0]
        label = "balance + tensioner + dissipated"
    if driven:
        net = net - (ds["drive_work"].values - ds["drive_work"].values[0])
        label += " - drive work"
    return ds["energy_balance_error"].values + net / float(ds.attrs["initial_total_energy"]), label
