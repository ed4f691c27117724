"""Python side of the reduced-coordinate solver: validate nothing (the scenario did),
allocate, call the compiled loop (solvers/base.py: the contract)."""

from ...model.core import indices as L
from ...model.core.bundles import event_arrays
from ..base import CHUNK_ROWS, allocate_outputs, run_chunks, trimmed
from .rk_loop import integrate, loop_arrays
from .tableau import TABLEAUS


def run(model, y0, controls, sink=None):
    """The run of controls.method in one piece; with a sink (base.run_chunks), streamed to it
    in chunks."""
    if y0.size != model.ny:   # the kernels index y by the model's layout, unchecked
        raise ValueError(f"the state has {y0.size} components, the model's layout {model.ny}")
    tab = TABLEAUS[controls.method].arrays()
    out = allocate_outputs(controls, model, y0.size, None if sink is None else CHUNK_ROWS)
    lw = loop_arrays(tab.b.shape[0], y0.size, L.n_diag(model.nw, model.n_links), model.n_links + 1)
    ev = event_arrays(model.nw, model.n_links, model.arrays.guides.shape[0] if model.closed else None)
    ctl = controls.loop_control
    run_chunks(lambda: integrate(y0, ctl, tab, model.arrays, model.work, ev, lw, out), out, sink)
    return trimmed(controls, out)
