"""Python side of the IMEX solver: allocate, call the compiled loop."""

from ...model.core import indices as L
from ...model.core.bundles import event_arrays
from ..base import allocate_outputs, control, trimmed
from ..common.pin_jacobian import jacobian_work
from .ark_loop import integrate, loop_arrays
from .ark_tableau import ARK_TABLEAUS


def run(scenario, model, y0):
    tab = ARK_TABLEAUS[scenario["method"]].arrays()
    out = allocate_outputs(scenario, model, y0.size)
    lw = loop_arrays(tab.b.shape[0], y0.size, L.n_diag(model.nw, model.n_links), model.n_links + 1)
    jw = jacobian_work(model, y0.size)
    ev = event_arrays(model.nw, model.n_links, model.arrays.guides.shape[0] if model.closed else None)
    integrate(y0, control(scenario), tab, model.arrays, model.work, ev, lw, jw, out)
    return trimmed(scenario, out)
