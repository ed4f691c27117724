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

# The functions generated from a table when their caller is first compiled (the contact
# laws' dispatch by code: model/contact/laws_jit.py). They are closures over the rows'
# compiled functions, and numba keys a closure's cache entry by its cells, which differ in
# every process: they are compiled into their callers, which are cached, never on their own.
GENERATED = dict(KERNEL, cache=False)


def _copy_inlined_ir_once():
    """Compile time: numba (0.68 and before, numba issue 8989) copies a function's IR for
    each place it is inlined one block at a time, each block with a fresh deepcopy memo,
    so every block drags along its own copy of the function's whole variable scope: the
    work grows with blocks x variables, and inlining the contact kernels into the
    right-hand sides spent about a quarter of the cold start copying scopes. Here the
    blocks copied within one inlining share one memo, so the scope (shared by all blocks
    of the original, as numba's own inliner asserts) is copied once. Same IR, same machine
    code (the golden tests compare results bit for bit); nothing else in numba changes."""
    import copy

    from numba.core import inline_closurecall as icc
    from numba.core import ir

    worker = getattr(icc, "InlineWorker", None)
    if (
        worker is None
        or getattr(icc, "copy", None) is not copy
        or getattr(worker, "_trackbench_shared", False)
    ):
        return  # another numba layout: leave it alone

    class _SharedMemoCopy:
        memos = None    # {id(scope): memo} while an inlining runs

        def deepcopy(self, x, memo=None):
            if memo is None and self.memos is not None and isinstance(x, ir.Block):
                memo = self.memos.setdefault(id(x.scope), {})
            return copy.deepcopy(x, memo)

    shim = _SharedMemoCopy()
    inline_ir = worker.inline_ir

    def inline_ir_shared(self, *args, **kwargs):
        outer, shim.memos = shim.memos, {}
        try:
            return inline_ir(self, *args, **kwargs)
        finally:
            shim.memos = outer

    icc.copy = shim
    worker.inline_ir = inline_ir_shared
    worker._trackbench_shared = True


_copy_inlined_ir_once()
