"""How each entity of a recording is drawn (colours, radii, labels): rerun's static
archetypes, built once per process (its constructors are slow next to logging them)."""

import functools

import rerun as rr

from trackbench.outputs.recording.entities import (
    ARM_RGB,
    CHASSIS_RGB,
    E_ARMS,
    E_AY,
    E_CHASSIS,
    E_ENERGY,
    E_GROUND_FORCE,
    E_GUIDE,
    E_IDLER,
    E_IDLER_FORCE,
    E_LINKS,
    E_PINS,
    E_ROLLERS,
    E_SEAT,
    E_SPROCKET,
    E_SPROCKET_TORQUE,
    E_TENSION,
    E_VX,
    E_WHEEL_FORCE,
    E_WHEEL_FY,
    E_WHEELS,
    ENERGY_SERIES,
    GROUND_FORCE_RGB,
    GUIDE_RGB,
    IDLER_RGB,
    ROLLER_RGB,
    SPROCKET_RGB,
    WHEEL_FORCE_RGB,
    wheel_rgb,
)


@functools.lru_cache(maxsize=16)
def _static_styles(radii):
    """The static archetypes that depend only on the wheels' radii (one per wheel; built once per
    process: rerun's archetype constructors are slow next to logging them): entity -> archetype."""
    nw = len(radii)
    return {
        E_CHASSIS: rr.LineStrips2D.from_fields(colors=[CHASSIS_RGB], radii=[0.02]),
        E_ARMS: rr.LineStrips2D.from_fields(colors=[ARM_RGB], radii=[0.03]),
        E_WHEELS: rr.Ellipses2D.from_fields(
            half_sizes=[[r, r] for r in radii],
            colors=[wheel_rgb(i) for i in range(nw)],
            line_radii=[0.012],
            labels=[f"wheel {i + 1}" for i in range(nw)],
        ),
        E_LINKS: rr.LineStrips2D.from_fields(radii=[0.012]),
        E_PINS: rr.Points2D.from_fields(radii=[0.02], colors=[(30, 30, 30)]),
        E_WHEEL_FORCE: rr.Arrows2D.from_fields(colors=[WHEEL_FORCE_RGB], radii=[0.015]),
        E_GROUND_FORCE: rr.Arrows2D.from_fields(
            colors=[GROUND_FORCE_RGB], radii=[0.02], labels=["ground force (total)"]
        ),
        E_WHEEL_FY: rr.SeriesLines(
            colors=[wheel_rgb(i) for i in range(nw)], names=[f"wheel {i + 1}" for i in range(nw)]
        ),
        E_AY: rr.SeriesLines(colors=[(0, 0, 0)], names=["chassis a_y (m/s^2)"]),
        E_VX: rr.SeriesLines(colors=[(0, 0, 0)], names=["chassis v_x (m/s)"]),
        E_SEAT: rr.SeriesLines(colors=[(178, 34, 34)], names=["seat a_y (m/s^2)"]),
        E_ENERGY: rr.SeriesLines(
            colors=[rgb for _, _, rgb in ENERGY_SERIES], names=[name for name, _, _ in ENERGY_SERIES]
        ),
        E_TENSION: rr.SeriesLines(colors=[(200, 0, 0)], names=["max link tension (N)"]),
    }


@functools.lru_cache(maxsize=16)
def _closed_styles(idler_radius, roller_radius, n_rollers):
    """The closed layout's static archetypes (as _static_styles): entity -> archetype."""
    ri, rr_ = idler_radius, roller_radius
    styles = {
        E_SPROCKET: rr.LineStrips2D.from_fields(colors=[SPROCKET_RGB], radii=[0.008], labels=["sprocket"]),
        E_IDLER: rr.Ellipses2D.from_fields(
            half_sizes=[[ri, ri]], colors=[IDLER_RGB], line_radii=[0.012], labels=["idler"]
        ),
        E_GUIDE: rr.LineStrips2D.from_fields(colors=[GUIDE_RGB], radii=[0.03], labels=["idler guide"]),
        E_SPROCKET_TORQUE: rr.SeriesLines(colors=[SPROCKET_RGB], names=["sprocket drive torque (N m)"]),
        E_IDLER_FORCE: rr.SeriesLines(colors=[(0, 0, 0)], names=["idler tensioner force (N)"]),
    }
    if n_rollers:  # a layout without rollers has no roller entity at all
        styles[E_ROLLERS] = rr.Ellipses2D.from_fields(
            half_sizes=[[rr_, rr_]] * n_rollers,
            colors=[ROLLER_RGB],
            line_radii=[0.01],
            labels=[f"roller {i + 1}" for i in range(n_rollers)],
        )
    return styles
