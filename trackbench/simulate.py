"""scenario -> xarray.Dataset: the one entry point the CLI, the studies and the API use.

    ds = trackbench.simulate(Scenario.paper(speed=15.0))

The compiled solvers and xarray load on the first call, not at import.
"""

import functools
import json
import time

import numpy as np

from .model import layout as L
from .model.bundles import arm_table, model_arrays, work_arrays
from .model.parameters import arm_damping, pack, total_mass
from .model.terrain import build_ground  # noqa: F401  (part of this module's API)
from .scenario import Scenario


@functools.lru_cache(maxsize=32)
def _equilibrium_cached(key):
    from .model.equilibrium import solve_equilibrium
    vehicle, track, gravity, contact = json.loads(key)
    return solve_equilibrium(vehicle, track, gravity, contact)


def equilibrium(scenario: Scenario):
    """Static equilibrium of the scenario's vehicle on flat ground (cached)."""
    key = json.dumps([scenario["vehicle"], scenario["track"], scenario["gravity"], scenario["contact"]],
                     sort_keys=True)
    return _equilibrium_cached(key)


def initial_state(scenario: Scenario, eq):
    """y0 = (q, qd, W): the equilibrium moving at `speed`, pins nudged if asked."""
    nq = eq.q.size
    y0 = np.zeros(L.n_state(nq))
    y0[:nq] = eq.q
    nw = scenario["vehicle.n_wheels"]
    off = L.pin_offset(nw)
    y0[nq + L.Q_X] = scenario["speed"]
    y0[nq + off:2 * nq:2] = scenario["speed"]
    if scenario["perturbation"] > 0.0:
        rng = np.random.default_rng(scenario["seed"])
        y0[off:nq] += scenario["perturbation"] * rng.uniform(-1.0, 1.0, nq - off)
    return y0


class Model:
    """One scenario's vehicle and ground as the compiled kernels take them: the bundles
    of model/bundles.py, and the sizes and figures the Python side needs."""

    def __init__(self, scenario: Scenario, eq, ground):
        v, tr = scenario["vehicle"], scenario["track"]
        par, piv, ends = pack(v, tr, scenario["gravity"], scenario["contact"])
        self.nw = int(v["n_wheels"])
        self.n_links = int(tr["n_links"])
        arms = arm_table(piv, eq.phi0, arm_damping(v))
        self.arrays = model_arrays(par, arms, ends, ground.segments, ground.corners, self.n_links)
        self.work = work_arrays(self.arrays, self.nw, self.n_links)
        self.weight = total_mass(v, tr) * scenario["gravity"]

    @property
    def par(self):
        return self.arrays.par

    @property
    def arms(self):
        return self.arrays.arms

    @property
    def ends(self):
        return self.arrays.ends

    @property
    def neighbour_rebuilds(self):
        return int(self.arrays.counters[L.C_REBUILDS])


def simulate(scenario: Scenario, progress=None):
    """Run one scenario; returns the Dataset (attrs['status'] is 'completed' or 'failed')."""
    if not isinstance(scenario, Scenario):
        scenario = Scenario.from_dict(scenario)
    t_wall = time.perf_counter()
    eq = equilibrium(scenario)
    ground, resolved = build_ground(scenario, eq)
    model = Model(scenario, eq, ground)
    y0 = initial_state(scenario, eq)
    if scenario["solver"] == "lee":
        from .solvers.lee import run as run_solver
    else:
        from .solvers.rk import run as run_solver
    from .output import build_dataset
    t_solve = time.perf_counter()
    result = run_solver(scenario, model, y0)
    solve_wall = time.perf_counter() - t_solve
    return build_dataset(scenario, model, eq, ground, resolved, result,
                         wall_time=time.perf_counter() - t_wall, solve_time=solve_wall)
