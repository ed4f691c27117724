"""A run gives the same numbers bit for bit whether numba compiled the kernels in this
process or loaded them from its cache. (With fastmath's reassociation the cached and the
freshly compiled copies of the right-hand side rounded differently and, the motion being
chaotic, a 0.5 s run took 11724 or 11847 steps depending on the cache: model/jit.py.)"""

import os
import subprocess
import sys

CODE = """
import hashlib, sys
import numpy as np
import trackbench as tb
if sys.argv[1] == "rhs-first":   # load the right-hand side on its own before the time loop
    from trackbench.run.simulate import Model, build_ground, equilibrium, initial_state
    from trackbench.model.dynamics.reduced import reduced_rhs
    from trackbench.model.core import indices as L
    sc = tb.Scenario.paper()
    eq = equilibrium(sc)
    m = Model(sc, eq, build_ground(sc, eq)[0])
    y0 = initial_state(sc, eq)
    reduced_rhs(y0, m.arrays, m.work, np.zeros_like(y0), np.zeros(L.n_diag(m.nw, m.n_links)))
ds = tb.simulate(tb.Scenario.paper())
print(ds.attrs["steps"], hashlib.sha1(ds.chassis_y.values.tobytes()).hexdigest())
"""


def _run(cache, mode):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    out = subprocess.run(
        [sys.executable, "-c", CODE, mode], env=env, capture_output=True, text=True, check=True
    )
    return out.stdout.split()


def test_same_numbers_compiled_or_cached(tmp_path):
    cold = _run(tmp_path, "plain")  # empty cache: everything compiled here
    warm = _run(tmp_path, "plain")  # everything loaded from the cache
    other = _run(tmp_path, "rhs-first")  # loaded in another order
    assert cold == warm == other
