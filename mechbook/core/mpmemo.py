"""mpmath's elementary functions remembered by argument and precision, for lambdify.

A 30-digit quadrature of a curve's functional evaluates its integrand at the same nodes
again and again: the perturbed curves J(±ε), J(0) of one variation, and the variations of
one curve, share the tanh-sinh nodes, so sin, cos, sinh and sqrt are asked for the same
arguments at the same precision two or three times over (brachistochrone: 11 282 sines of
3 582 distinct arguments; the hanging chain: 25 798 sinh of 12 068). Each is 2–7 µs at 30
digits; a dictionary look-up is a tenth of that. mpmath's functions are deterministic in
(argument, precision, rounding), so a remembered value is the same number bit for bit.

`NAMESPACE` is a lambdify module (`modules=[NAMESPACE, "mpmath"]`): the remembered
functions under mpmath's names, everything else mpmath's own.
"""

from __future__ import annotations

from collections.abc import Callable

import mpmath

KEPT = 1 << 16  # values a function keeps before its memory is cleared (about 10 MB at most)
NAMES = ("sin", "cos", "tan", "sinh", "cosh", "tanh", "exp", "log", "sqrt", "asin",
         "acos", "atan", "asinh", "acosh", "atanh")


def remembered(fn: Callable) -> Callable:
    """fn (one argument, an mpmath elementary function) remembering its values for mpf
    and mpc arguments by (the argument's exact value, the working precision and
    rounding); any other argument (a Python int or float) goes to fn as it is.
    Example: remembered(mpmath.sin)(mpmath.mpf(1)) == mpmath.sin(mpmath.mpf(1))."""
    memory: dict = {}
    ctx = mpmath.mp
    mpf, mpc = mpmath.mpf, mpmath.mpc

    def f(x):
        t = type(x)
        if t is mpf:
            key = (x._mpf_, *ctx._prec_rounding)
        elif t is mpc:
            key = (x._mpc_, *ctx._prec_rounding)
        else:
            return fn(x)
        got = memory.get(key)
        if got is None:
            if len(memory) >= KEPT:
                memory.clear()
            got = memory[key] = fn(x)
        return got

    f.__name__ = getattr(fn, "__name__", "remembered")
    f.__doc__ = f"mpmath's {f.__name__}, remembered by argument and precision."
    return f


NAMESPACE = {name: remembered(getattr(mpmath, name)) for name in NAMES}
