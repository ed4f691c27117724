"""Elementary functions that round the same on every machine.

numba's ``math.sin`` and friends call the C library, and glibc picks an implementation of
sin, cos, exp, log, atan2, pow, ... by CPU at load time (FMA or not), which differ in the
last bit for a small share of arguments; a chaotic simulation then diverges between
machines. The functions here are ports of the fdlibm / FreeBSD msun algorithms written
with plain IEEE double operations only (+ - * / sqrt, exact bit manipulation, no FMA, no
fastmath) in a fixed order, so they give the same bits on every x86-64 and ARM machine.

Algorithms and coefficients: fdlibm 5.3 and FreeBSD msun (k_sin, k_cos, k_tan,
e_rem_pio2, e_exp, s_expm1, s_atan, e_atan2, e_asin, e_acos, e_hypot), which carry this
notice: "Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved. Developed at
SunSoft, a Sun Microsystems, Inc. business. Permission to use, copy, modify, and
distribute this software is freely granted, provided that this notice is preserved."
The code is ours. Where it departs from fdlibm (atan2's quotient, the order of
evaluation in exp) the function's docstring says so. log is a table of 182 cells and a
short series (the table from decimal arithmetic at import), pow is exp(y log x) carried
in double-double; the reduction of huge arguments of sin, cos, tan (|x| >= 2^20 pi/2, up
to the largest double) is our own Payne-Hanek variant on fdlibm's table of 2/pi.
Nothing here allocates, so every function may be called from functions compiled without
numba's runtime (jit.BORROW).

Conventions are those of C (and of numba's ``math`` in compiled code): nothing raises;
an invalid argument (sin(inf), log(-1), asin(2), pow(-2, y)) gives a NaN with fixed
bits (0x7ff8000000000000, the same on x86 and ARM), a NaN argument is returned as it
is, overflow gives inf, log(0) = -inf, pow(0, -1) = inf; signed zeros and atan2 on the
axes as C99. ``pow`` takes x >= 0 only (no result of the model raises a negative number
to a power). The array versions (vsin, ..., vsincos: one compiled loop behind them all)
give the same bits as the scalar ones.

Accuracy, max error in ulp against mpmath at 200 bits (10^6 random arguments per range;
log and pow 10^4): sin 0.77, cos 0.76 (|x| < 10, < 1e4, 1e6 .. 1e300, next to multiples of
pi/2), tan 0.85, atan 0.84, asin 0.88, acos 0.90 (on [-1, 1]), exp 0.88 (-700 .. 700),
expm1 0.83 (0.50 for |x| < 1e-3), log 0.50 (1e-300 .. 1e300 and subnormals), atan2 0.83
(all quadrants), hypot 0.88, pow 0.79 (x 1e-8 .. 1e8 with |y| < 3, x 1e-300 .. 1e300).

Speed, ns a call in a compiled loop, warm, against glibc through numba's math.* (in
brackets): sin 16 (15), cos 16 (15), sincos 17 (19 for both), tan 19 (16), atan 6.5 (7.4),
asin 5.4 (9.6), acos 7.2 (9.9), exp 3.3 (2.9), expm1 12 (10), log 6.7 (2.9), atan2 20 (17),
hypot 9.4 (13), pow 14 (8.3): glibc's log and pow use FMA and larger tables.
"""

from .arc import acos, asin, atan, atan2, hypot
from .elementwise import (
    vacos,
    vasin,
    vatan,
    vatan2,
    vcos,
    vexp,
    vexpm1,
    vhypot,
    vlog,
    vpow,
    vsin,
    vsincos,
    vtan,
)
from .exp_log import exp, expm1, log, pow
from .trig import cos, sin, sincos, tan

__all__ = [
    "sin",
    "cos",
    "tan",
    "sincos",
    "atan",
    "atan2",
    "asin",
    "acos",
    "exp",
    "expm1",
    "log",
    "pow",
    "hypot",
    "vsin",
    "vcos",
    "vtan",
    "vatan",
    "vatan2",
    "vasin",
    "vacos",
    "vexp",
    "vexpm1",
    "vlog",
    "vpow",
    "vhypot",
    "vsincos",
]
