"""scenario -> xarray.Dataset: the one entry point the CLI, the studies and the API use.

    ds = trackbench.simulate(Scenario.paper(speed=15.0))

The compiled solvers and xarray load on the first call, not at import.
"""

import functools
import time

from trackbench.model.ground.terrain import build_ground  # noqa: F401  (part of this module's API)
from trackbench.run.assemble import Model, closed_parts, equilibrium, initial_state, soil_par  # noqa: F401  (the run's parts: part of this module's API)
from trackbench.scenario import Scenario, ScenarioError
from trackbench.solvers.registry import SOLVERS


def controls(scenario):
    """The run's solver controls (solvers/base.py Controls), from its registry entry."""
    return SOLVERS[scenario["solver"]].controls(scenario)


def prepare(scenario):
    """What a run starts from: (model, equilibrium, ground, resolved terrain, y0, solve), where
    solve(sink=None) runs the scenario's solver on the model, y0 and the run's controls (built
    here, once; a sink only where the solver's registry entry streams)."""
    eq = equilibrium(scenario)
    try:
        ground, resolved = build_ground(scenario, eq)
    except ValueError as e:   # an obstacle placed where it cannot stand: before the run, one line
        raise ScenarioError(str(e)) from None
    model = Model(scenario, eq, ground)
    y0 = initial_state(scenario, eq)
    entry = SOLVERS[scenario["solver"]]
    ctl = entry.controls(scenario)
    return model, eq, ground, resolved, y0, functools.partial(entry.run_function(ctl.method), model, y0, ctl)


def simulate(scenario: Scenario, progress=None):
    """Run one scenario; returns the Dataset (attrs['status'] is 'completed' or 'failed')."""
    if not isinstance(scenario, Scenario):
        scenario = Scenario.from_dict(scenario)
    t_wall = time.perf_counter()
    model, eq, ground, resolved, y0, solve = prepare(scenario)
    from trackbench.outputs.dataset import build_dataset
    t_solve = time.perf_counter()
    result = solve()
    solve_wall = time.perf_counter() - t_solve
    return build_dataset(scenario, model, eq, ground, resolved, result,
                         wall_time=time.perf_counter() - t_wall, solve_time=solve_wall)
