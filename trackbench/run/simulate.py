"""scenario -> xarray.Dataset: the one entry point the CLI, the studies and the API use.

    ds = trackbench.simulate(Scenario.paper(speed=15.0))

The compiled solvers and xarray load on the first call, not at import.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any, NamedTuple

from trackbench.model.ground.terrain import build_ground  # noqa: F401  (part of this module's API)
from trackbench.run.assemble import Model, closed_parts, equilibrium, initial_state, soil_par  # noqa: F401  (the run's parts: part of this module's API)
from trackbench.scenario import Scenario, ScenarioError
from trackbench.solvers.base import Controls, RunResult
from trackbench.solvers.registry import SOLVERS

if TYPE_CHECKING:
    import numpy as np
    import xarray as xr


def controls(scenario: Scenario) -> Controls:
    """The run's solver controls (solvers/base.py Controls), from its registry entry."""
    return SOLVERS[scenario["solver"]].controls(scenario)


class Prepared(NamedTuple):
    """A run ready to go, the one pipeline of every run: its parts, then solve(sink=None)
    (the scenario's solver on the model, y0 and the run's controls; with a sink, where the
    solver's registry entry streams, the samples go to it chunk by chunk: run/stream.py), then
    dataset(result) (outputs/dataset.py)."""

    scenario: Scenario
    model: Model
    eq: Any                # the static equilibrium (solvers/equilibrium)
    ground: Any            # the ground's polyline and corners (model/ground/terrain.py)
    resolved: Any          # the terrain as placed (obstacles' positions)
    y0: np.ndarray
    solve: Callable[..., RunResult]

    def dataset(self, result: RunResult, wall_time: float = 0.0, solve_time: float = 0.0) -> xr.Dataset:
        from trackbench.outputs.dataset import build_dataset
        return build_dataset(self.scenario, self.model, self.eq, self.ground, self.resolved, result,
                             wall_time, solve_time)


def prepare(scenario: Scenario) -> Prepared:
    """What a run starts from; its controls built here, once."""
    eq = equilibrium(scenario)
    try:
        ground, resolved = build_ground(scenario, eq)
    except ValueError as e:   # an obstacle placed where it cannot stand: before the run, one line
        raise ScenarioError(str(e)) from None
    model = Model(scenario, eq, ground)
    y0 = initial_state(scenario, eq)
    entry = SOLVERS[scenario["solver"]]
    ctl = entry.controls(scenario)
    solve = functools.partial(entry.run_function(ctl.method), model, y0, ctl)
    return Prepared(scenario, model, eq, ground, resolved, y0, solve)


def simulate(scenario: Scenario | Mapping[str, Any]) -> xr.Dataset:
    """Run one scenario (a Scenario, or a dict Scenario.from_dict takes) in memory; returns the
    Dataset (attrs['status'] is 'completed' or 'failed')."""
    if not isinstance(scenario, Scenario):
        scenario = Scenario.from_dict(scenario)
    t_wall = time.perf_counter()
    run = prepare(scenario)
    t_solve = time.perf_counter()
    result = run.solve()
    solve_time = time.perf_counter() - t_solve
    return run.dataset(result, wall_time=time.perf_counter() - t_wall, solve_time=solve_time)
