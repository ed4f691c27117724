"""Compile options shared by the model kernels.

The contact kernels are small and called once per right-hand side: INLINE folds them
into their caller at numba-IR level (no call overhead, array reference counts pruned
across the whole right-hand side; ~20 % of its time). It costs compile time (numba
copies the inlined IR), so only the right-hand sides inline them.

No fastmath: with "reassoc" LLVM may order a sum differently in each place a function
is compiled into, and a run then gave other numbers (after 0.25 s: the motion is
chaotic) depending on which cached copy numba loaded first. Without it every copy
rounds alike and a run is reproducible bit for bit.
"""

KERNEL = {"cache": True, "error_model": "numpy"}
INLINE = dict(KERNEL, inline="always")
# Small functions of scalars (and of an array read or two): LLVM inlines them where they
# pay, and inlining them at numba-IR level as well only costs compile time.
SCALAR = KERNEL

# The solver loops and the right-hand sides never allocate: every array they touch is
# allocated and held by the Python side for the whole run. Their bundles (named tuples of
# arrays) would otherwise have every member's reference count raised and lowered,
# atomically, at each call and at each field read (a quarter of the reduced solver's and
# half of the lee solver's time). Without the runtime (NRT) no counts are kept: such a
# function must not create an array.
BORROW = dict(KERNEL, _nrt=False)
