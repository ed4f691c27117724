"""scenario -> xarray.Dataset: the one entry point the CLI, the studies and the API use.

    ds = trackbench.simulate(Scenario.paper(speed=15.0))

The compiled solvers and xarray load on the first call, not at import.
"""

import time

from trackbench.model.ground.terrain import build_ground  # noqa: F401  (part of this module's API)
from trackbench.run.assemble import Model, closed_parts, equilibrium, initial_state, soil_par  # noqa: F401  (the run's parts: part of this module's API)
from trackbench.scenario import Scenario, ScenarioError
from trackbench.solvers.registry import run_function


def prepare(scenario):
    """What a run starts from: (model, equilibrium, ground, resolved terrain, y0, the solver's run)."""
    eq = equilibrium(scenario)
    try:
        ground, resolved = build_ground(scenario, eq)
    except ValueError as e:   # an obstacle placed where it cannot stand: before the run, one line
        raise ScenarioError(str(e)) from None
    model = Model(scenario, eq, ground)
    y0 = initial_state(scenario, eq)
    return model, eq, ground, resolved, y0, run_function(scenario["solver"], scenario["method"])


def simulate(scenario: Scenario, progress=None):
    """Run one scenario; returns the Dataset (attrs['status'] is 'completed' or 'failed')."""
    if not isinstance(scenario, Scenario):
        scenario = Scenario.from_dict(scenario)
    t_wall = time.perf_counter()
    model, eq, ground, resolved, y0, run_solver = prepare(scenario)
    from trackbench.outputs.dataset import build_dataset
    t_solve = time.perf_counter()
    result = run_solver(scenario, model, y0)
    solve_wall = time.perf_counter() - t_solve
    return build_dataset(scenario, model, eq, ground, resolved, result,
                         wall_time=time.perf_counter() - t_wall, solve_time=solve_wall)
