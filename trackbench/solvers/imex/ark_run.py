"""Python side of the IMEX solver: allocate, call the compiled loop."""

from ...model.core import indices as L
from ...model.core.bundles import event_arrays
from ..base import CHUNK_ROWS, allocate_outputs, run_chunks, trimmed
from ..common.pin_jacobian import J_AGE, jacobian_work
from .ark_loop import integrate, loop_arrays
from .ark_tableau import ARK_TABLEAUS


def run(model, y0, controls, sink=None):
    """The run of controls.method in one piece; with a sink (base.run_chunks), streamed to it
    in chunks."""
    tab = ARK_TABLEAUS[controls.method].arrays()
    out = allocate_outputs(controls, model, y0.size, None if sink is None else CHUNK_ROWS)
    out.resume[L.RS_AGE] = J_AGE   # no Jacobian yet
    lw = loop_arrays(tab.b.shape[0], y0.size, L.n_diag(model.nw, model.n_links), model.n_links + 1)
    jw = jacobian_work(model, y0.size)
    ev = event_arrays(model.nw, model.n_links, model.arrays.guides.shape[0] if model.closed else None)
    ctl = controls.loop_control
    run_chunks(lambda: integrate(y0, ctl, tab, model.arrays, model.work, ev, lw, jw, out), out, sink)
    return trimmed(controls, out)
