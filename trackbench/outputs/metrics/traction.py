"""Drawbar-test figures of a run of the closed track on flat soft soil: the steady means of
slip, thrust and drawbar pull, the contact the track makes, and Wong's closed form for a
track under uniform pressure beside them (model/ground/soil.py). The benchmark, the tests and the
study plot read a run through these functions, so each figure is computed one way.

On flat soil the soil's pressure on a pin acts along the surface normal (vertical), so the
ground's net horizontal force on the track (`drawbar_pull`) is the sum of the soil shear
forces' x components: the gross thrust. The soil's compaction is paid through the sprocket
instead (a deeper rut is more work of the pins' pressure), so it shows as sprocket pull
(torque / pitch radius) beyond the thrust, not as a horizontal ground force.

Two slips: `slip`, the run's output, is 1 - chassis speed / (sprocket speed x pitch radius),
the one the towing rig holds; `track_slip` is the slip the soil sees, 1 - chassis speed / the
track's own speed relative to the chassis in the contact, measured on the pins (Wong's
i = j / x: the shear displacement per length of track run past). They differ by the
sprocket's chordal action (the pins ride a polygon: one pitch p per tooth, a mean track speed
omega N p / (2 pi) = 0.984 omega r_p for 10 teeth, 1.6 % of slip) and by the links' stretch
(a link under tension T is L + T / k long; the teeth are spaced for track.tension): with the
paper's soft links the ground run's tension rises from the front of the contact to the rear,
and with it the pins' slip (docs/validation.md). Wong's form is evaluated at `track_slip`.
"""

import json

import numpy as np

from trackbench.model.ground.soil import (
    bekker_pressure,
    janosi_shear,
    resolve_soil,
    static_sinkage,
    wong_thrust,
)
from trackbench.outputs.variables import scenario_of

TRACK_STILL = 1e-3      # m/s: slower than this, the sprocket lays no track and there is no slip


def slip(chassis_speed, track_speed):
    """1 - chassis speed / track speed (the sprocket's speed x pitch radius), sample by sample;
    NaN where the track stands still."""
    track = np.asarray(track_speed, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(np.abs(track) > TRACK_STILL, 1.0 - np.asarray(chassis_speed) / track, np.nan)


def mean_slip(chassis_speed, track_speed):
    """The slip over a stretch of run: 1 - distance travelled / track laid, the ratio of the
    means (NaN without track laid). Not the mean of the instantaneous slip: on soil the
    sprocket rattles on its teeth (its speed swings by half either way as each pin engages),
    and the samples where it lags weigh that mean down (-5 % against +7 % on a run of the
    soft_soil study)."""
    track = float(np.mean(track_speed)) if len(track_speed) else 0.0
    return 1.0 - float(np.mean(chassis_speed)) / track if abs(track) > TRACK_STILL else float("nan")


def run_soil(ds):
    """The soil values of a run's scenario (None on rigid ground)."""
    terrain = scenario_of(ds)["terrain"]
    return resolve_soil(terrain.get("soil", "rigid"))


def _scenario(ds):
    return scenario_of(ds)


def has_traction(ds):
    """A closed track on soft soil: the runs these figures apply to."""
    return "slip" in ds and run_soil(ds) is not None


def steady(ds, since):
    """Means over t >= since: slip (the sprocket's, mean_slip), track_slip (the soil's: track_slip()),
    thrust (N), drawbar load at the hitch (N), sprocket pull (N), ground's vertical force W (N),
    pins in contact, contact length l (m) and area A (m^2)."""
    sc = _scenario(ds)
    late = ds.time.values >= since
    pitch_radius = json.loads(ds.attrs["closed_layout"])["pitch_radius"]
    in_contact = ds.sinkage.values[late] > 0.0
    n = float(in_contact.sum(axis=1).mean())
    length = n * sc["track"]["link_length"]    # each pin stands for one link's length of ground
    return {
        "slip": mean_slip(ds.chassis_vx.values[late], ds.sprocket_speed.values[late] * pitch_radius),
        "track_slip": track_slip(ds, since),
        "thrust": float(ds.drawbar_pull.values[late].mean()),
        "drawbar_load": float(ds.drawbar_load.values[late].mean()) if "drawbar_load" in ds else float("nan"),
        "sprocket_pull": float(ds.sprocket_torque.values[late].mean()) / pitch_radius,
        "weight": float(ds.ground_force_y.values[late].mean()),
        "pins": n,
        "length": length,
        "area": length * sc["track"]["width"],
    }


def track_slip(ds, since):
    """The slip the soil sees over t >= since: the pins' mean speed backwards over the ground
    divided by their mean speed relative to the chassis (chassis speed + that), over the pins
    on the soil at two successive samples (their speed: the difference of their x); NaN
    without any."""
    t = ds.time.values
    pair = t[:-1] >= since
    on = (ds.sinkage.values[:-1] > 0.0) & (ds.sinkage.values[1:] > 0.0) & pair[:, None]
    if not on.any():
        return float("nan")
    ground = np.diff(ds.pin_x.values, axis=0) / np.diff(t)[:, None]
    chassis = 0.5 * (ds.chassis_vx.values[:-1] + ds.chassis_vx.values[1:])[:, None]
    backwards = -ground[on].sum()
    return float(backwards / (np.broadcast_to(chassis, on.shape)[on].sum() + backwards))


def wong(fig, soil):
    """Wong's thrust of a track of the run's contact length, area and weight at the slip its
    soil sees (track_slip),
    and his compaction resistance b k z0^(n+1) / (n+1) at the sinkage z0 of the uniform
    pressure W / A (Theory of Ground Vehicles): (thrust, resistance) in N."""
    thrust = wong_thrust(
        fig["area"], fig["weight"], fig["length"], min(max(fig["track_slip"], 0.0), 1.0), soil
    )
    b = fig["area"] / fig["length"]
    z0 = static_sinkage(fig["weight"] / fig["area"], soil, b)
    resistance = b * float(bekker_pressure(z0, soil, b)) * z0 / (soil["n"] + 1.0)
    return float(thrust), resistance


def pressure_effect(ds, since, slip, soil):
    """Wong's integral summed over the pins in contact, once with each pin's own share of the
    load (its Bekker pressure at its sinkage, scaled so that the shares add up to the
    measured vertical force) and once with equal shares; returns (non-uniform, uniform) in N,
    means over t >= since. Their ratio is what the pressure under the road wheels does to
    the thrust. A pin's shear displacement is slip x its distance behind the front contact
    pin, plus half a link (on average the front pin touched down half a link ahead)."""
    sc = _scenario(ds)
    late = ds.time.values >= since
    link = sc["track"]["link_length"]
    area = sc["track"]["width"] * link
    sink = ds.sinkage.values[late]
    px = ds.pin_x.values[late]
    w = ds.ground_force_y.values[late]
    b = sc["track"]["width"]
    out = np.zeros(2)
    for z, x, weight in zip(sink, px, w):
        on = z > 0.0
        if not on.any():
            continue
        p = bekker_pressure(z[on], soil, b) * area
        j = slip * (x[on].max() - x[on] + 0.5 * link)
        for k, load in enumerate((weight * p / p.sum(), np.full(on.sum(), weight / on.sum()))):
            out[k] += float(np.sum(janosi_shear(load / area, j, soil))) * area
    return tuple(out / max(len(w), 1))
