"""The time integrators by name: what `solver = "..."` and `method = "..."` may say, and the
function that runs each. An entry names its module and function as text, so the registry
loads nothing (scenario validation reads it without numba); `run_function` imports the
solver on first use. A new integrator adds one entry here and follows the contract in
solvers/base.py."""

import importlib
from dataclasses import dataclass


@dataclass(frozen=True)
class SolverEntry:
    name: str  # the value of `solver`
    module: str  # where its run(scenario, model, y0) -> RunResult lives
    methods: tuple  # the values `method` chooses among (empty: the solver's own pair, no choice)
    closed_track: bool  # whether it integrates the closed track
    summary: str
    method_modules: tuple = ()  # (method, module) pairs run by a module other than `module`

    def module_for(self, method):
        return dict(self.method_modules).get(method, self.module)


SOLVERS = {
    e.name: e
    for e in (
        SolverEntry(
            "reduced",
            "trackbench.solvers.rk.rk_run",
            ("dop853", "dopri5", "ark436l2sa", "ark548l2sa"),
            True,
            "reduced coordinates, embedded explicit Runge-Kutta pairs (DOP853, DOPRI5) or additive "
            "(IMEX) pairs with the pins' block Jacobian as the implicit part (ARK4(3)6L[2]SA, "
            "ARK5(4)8L[2]SA)",
            (
                ("ark436l2sa", "trackbench.solvers.imex.ark_run"),
                ("ark548l2sa", "trackbench.solvers.imex.ark_run"),
            ),
        ),
        SolverEntry(
            "lee",
            "trackbench.solvers.lee.lee_run",
            (),
            False,
            "the paper's method: absolute coordinates, Lee's accelerated iteration, RKN6(4)",
        ),
    )
}
# every method any solver takes (scenario validation's allowed values)
METHODS = tuple(sorted({m for e in SOLVERS.values() for m in e.methods}))


def run_function(name, method=None):
    """The run(scenario, model, y0) of the solver called `name` with `method`."""
    return importlib.import_module(SOLVERS[name].module_for(method)).run
