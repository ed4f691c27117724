"""Why a run stopped: integer codes the compiled loops return, each with a readable message."""

from enum import IntEnum


class EquilibriumError(RuntimeError):
    """The static equilibrium a run starts from was not found: the run cannot start."""


class Result(IntEnum):
    SUCCESSFUL = 0
    NAN = 1
    STEP_SIZE_UNDERFLOW = 2
    WHEEL_THROUGH_TRACK = 3
    CORNER_THROUGH_TRACK = 4
    MAX_STEPS = 5
    CONSTRAINT_ITERATION = 6
    PIN_THROUGH_SPROCKET = 7
    IDLER_OFF_GUIDE = 8
    GROUND_CANDIDATES = 9

    @property
    def message(self) -> str:
        return _MESSAGES[self]


_MESSAGES = {
    Result.SUCCESSFUL: "run completed",
    Result.NAN: "the state became NaN or infinite (diverged)",
    Result.STEP_SIZE_UNDERFLOW: (
        "the step size fell below the minimum step (the solution is too stiff or discontinuous here)"
    ),
    Result.WHEEL_THROUGH_TRACK: (
        "a road wheel went through the track (wheel centre crossed a link's centre line)"
    ),
    Result.CORNER_THROUGH_TRACK: (
        "a ground corner went through the track (corner crossed a link's centre line)"
    ),
    Result.MAX_STEPS: "the maximum number of steps was reached (max_steps; by default 400,000 a "
    "simulated second, where the closed track with friction takes about 160,000 with dopri5: raise "
    "max_steps, or loosen the tolerance)",
    Result.CONSTRAINT_ITERATION: "the Lagrange-multiplier iteration did not converge",
    Result.PIN_THROUGH_SPROCKET: "a track pin went into a sprocket tooth (it jumped the teeth)",
    Result.IDLER_OFF_GUIDE: "the idler ran off the end of its guide (idler.travel)",
    Result.GROUND_CANDIDATES: "more ground segments lie near one pin than the contact search holds "
    "(256 on a ground of more segments): the ground's polyline is too dense there; sample it coarser",
}

# plain ints for use inside numba kernels
SUCCESSFUL = int(Result.SUCCESSFUL)
NAN = int(Result.NAN)
STEP_SIZE_UNDERFLOW = int(Result.STEP_SIZE_UNDERFLOW)
WHEEL_THROUGH_TRACK = int(Result.WHEEL_THROUGH_TRACK)
CORNER_THROUGH_TRACK = int(Result.CORNER_THROUGH_TRACK)
MAX_STEPS = int(Result.MAX_STEPS)
CONSTRAINT_ITERATION = int(Result.CONSTRAINT_ITERATION)
PIN_THROUGH_SPROCKET = int(Result.PIN_THROUGH_SPROCKET)
IDLER_OFF_GUIDE = int(Result.IDLER_OFF_GUIDE)
GROUND_CANDIDATES = int(Result.GROUND_CANDIDATES)
