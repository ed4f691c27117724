"""The time integrators by name: what `solver = "..."` and `method = "..."` may say, the
function that runs each, and everything the rest of the package needs to know about one
(what it integrates, whether it streams, its own settings, the method name its outputs
carry). Scenario validation, the run layer (run/simulate.py, run/stream.py), the outputs and
the study files ask this table, never a solver's name.

An entry names its module as text, so the registry loads nothing (scenario validation reads
it without numba); `SolverEntry.run_function` imports the solver on first use. A new
integrator adds its folder and one entry here, and follows the contract in solvers/base.py.
The solver names and methods are read from ``SOLVERS`` as it is when a scenario is validated;
the settings tables (``SolverEntry.settings``) when scenario/parameters_table.py is imported."""

import importlib
from dataclasses import dataclass


@dataclass(frozen=True)
class Setting:
    """One value of a solver's own settings table (scenario `<table>.<key>`)."""

    key: str
    default: object
    rule: tuple  # (type, low, high, what is allowed): scenario/parameters_table.py RULES' form
    unit: str = ""


@dataclass(frozen=True)
class SolverEntry:
    name: str  # the value of `solver`
    module: str  # where its run(model, y0, controls[, sink]) -> RunResult lives (solvers/base.py)
    methods: tuple  # the values `method` chooses among (empty: the solver's own, named `label`)
    summary: str
    label: str = ""  # the method its outputs name when `methods` is empty (e.g. "lee-rkn")
    method_modules: tuple = ()  # (method, module) pairs run by a module other than `module`
    closed_track: bool = False  # whether it integrates the closed track layout
    extended_models: bool = False  # whether it runs the models beyond the paper (else the paper's only)
    streams: bool = False  # whether run() takes a sink: a long run streamed in chunks (run/stream.py)
    settings: str = ""  # the scenario table of its own settings ("lee": lee.accel_order, ...), "" none
    setting_rules: tuple = ()  # that table's Settings: defaults, rules and units
    pin_tolerance_methods: tuple = ()  # its methods whose error norm honours tolerance_pin_velocity

    def module_for(self, method):
        return dict(self.method_modules).get(method, self.module)

    def method_of(self, method):
        """The method a run of this solver runs, and its outputs name, when `method` says so."""
        return method if self.methods else self.label

    def run_function(self, method):
        """The solver's run(model, y0, controls[, sink]) for `method` (imported now)."""
        return importlib.import_module(self.module_for(method)).run

    def controls(self, scenario):
        """The solver's base.Controls for a validated scenario: the run-wide settings, the
        method, and its own settings table. The run layer builds them once per run."""
        from .base import controls

        own = dict(scenario[self.settings]) if self.settings else {}
        return controls(scenario["duration"], scenario["output_interval"], scenario["tolerance"],
                        scenario["max_step"], scenario["max_steps"], self.method_of(scenario["method"]), own,
                        _optional(scenario, "tolerance_pin_velocity"), _pi_beta(scenario))


def _pi_beta(scenario):
    """The closed track steps by the PI controller (half the rejected steps of the plain one,
    docs/benchmarks.md); the paper's layout keeps the plain one, bit for bit."""
    from .common.control import PI_BETA

    return PI_BETA if scenario["track"]["layout"] == "closed" else 0.0


def _optional(scenario, name):
    """A setting the paper's defaults leave out (absent: 0, the method's own default)."""
    try:
        return scenario[name]
    except KeyError:
        return 0.0


_LEE_SETTINGS = (
    Setting("accel_order", 10, (int, 1, 50, "an integer in [1, 50]")),
    Setting("eps_iterations", 10, (int, 1, 1000, "an integer in [1, 1000]")),
    Setting("position_tol", 1e-9, (float, 1e-15, 1e-3, "a number in [1e-15, 1e-3] m"), "m"),
    Setting("max_iterations", 500, (int, 1, 100000, "an integer >= 1")),
    Setting("matrix_update_angle", 1e-3,
            (float, 0.0, 1.0, "a number in [0, 1] rad (0: rebuild A_n after every step)"), "rad"),
)

SOLVERS = {
    e.name: e
    for e in (
        SolverEntry(
            "reduced",
            "trackbench.solvers.rk.rk_run",
            ("dop853", "dopri5", "ark436l2sa", "ark548l2sa", "ros34pw2"),
            "reduced coordinates, embedded explicit Runge-Kutta pairs (DOP853, DOPRI5), additive "
            "(IMEX) pairs with the pins' block Jacobian as the implicit part (ARK4(3)6L[2]SA, "
            "ARK5(4)8L[2]SA), or the Rosenbrock-W method ROS34PW2 with the pins' block Jacobian as "
            "its W (its error norm holds the pins' velocities to tolerance_pin_velocity)",
            method_modules=(
                ("ark436l2sa", "trackbench.solvers.imex.ark_run"),
                ("ark548l2sa", "trackbench.solvers.imex.ark_run"),
                ("ros34pw2", "trackbench.solvers.rosenbrock.ros_run"),
            ),
            closed_track=True,
            extended_models=True,
            streams=True,
            pin_tolerance_methods=("ros34pw2",),
        ),
        SolverEntry(
            "lee",
            "trackbench.solvers.lee.lee_run",
            (),
            "the paper's method: absolute coordinates, Lee's accelerated iteration, RKN6(4)",
            label="lee-rkn",
            settings="lee",
            setting_rules=_LEE_SETTINGS,
        ),
    )
}


def all_methods():
    """Every method any registered solver takes, sorted."""
    return tuple(sorted({m for e in SOLVERS.values() for m in e.methods}))


# every method any solver takes at import (the parameter table's text)
METHODS = all_methods()


def pin_tolerance_methods():
    """Every method whose error norm honours tolerance_pin_velocity (any solver's), sorted."""
    return tuple(sorted({m for e in SOLVERS.values() for m in e.pin_tolerance_methods}))


def settings_tables():
    """The scenario tables that hold a solver's own settings (e.g. "lee")."""
    return tuple(e.settings for e in SOLVERS.values() if e.settings)


def run_function(name, method=None):
    """The run(model, y0, controls[, sink]) of the solver called `name` with `method`."""
    return SOLVERS[name].run_function(method)
