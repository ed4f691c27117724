"""The right-hand side of the reduced solver for either track layout, chosen by the type
of the scratch bundle when the solver compiles: a run of the paper's layout never
compiles the closed layout's code (and the other way round)."""

from numba.extending import overload

from ..core.bundles import ClosedWork
from .closed_track_jit import closed_rhs
from .reduced import reduced_rhs


def _closed(w):
    return getattr(w, "instance_class", None) is ClosedWork


def rhs(y, m, w, ydot, diag):
    """ydot = f(y): reduced.reduced_rhs (paper's layout) or closed_track_jit.closed_rhs (closed)."""
    if isinstance(w, ClosedWork):
        return closed_rhs(y, m, w, ydot, diag)
    return reduced_rhs(y, m, w, ydot, diag)


@overload(rhs, jit_options={"cache": True})
def _rhs(y, m, w, ydot, diag):
    if _closed(w):
        return lambda y, m, w, ydot, diag: closed_rhs(y, m, w, ydot, diag)
    return lambda y, m, w, ydot, diag: reduced_rhs(y, m, w, ydot, diag)
