"""Compile options shared by the model kernels and the time loops.

FASTMATH lets LLVM contract a*b+c into FMAs, reassociate sums and min/max reductions
(so they vectorise), and divide by multiplying with a reciprocal: results change in the
last bits only. It leaves out "nnan" and "ninf" on purpose: the solvers detect a
diverged run by NaN/inf checks, which those flags would let the compiler delete.

The contact kernels are small and called once per right-hand side: INLINE folds them
into their caller at numba-IR level (no call overhead, array reference counts pruned
across the whole right-hand side; ~20 % of its time).
"""

FASTMATH = {"contract", "reassoc", "arcp", "nsz"}
KERNEL = {"cache": True, "error_model": "numpy", "fastmath": FASTMATH}
INLINE = dict(KERNEL, inline="always")
