"""Evaluating a SymPy expression at a point, fast, with a measure of its cancellation.

Checking that an expression vanishes needs its value at a point *and* a scale to judge that
value against: the sum of the magnitudes of everything that was added on the way (a rounding
error analysis's condition number). Expanding the expression to read off its terms costs far
more than the check itself on large equations of motion, so this module walks the expression
once, bottom-up, sharing repeated subexpressions, in mpmath arithmetic, and carries both the
value and that magnitude. Nothing here parses text: the input is an expression already built
by the safe parser or the engine.
"""

from __future__ import annotations

import mpmath
import sympy as sp

_FUNCS = {
    sp.sin: mpmath.sin, sp.cos: mpmath.cos, sp.tan: mpmath.tan, sp.cot: mpmath.cot,
    sp.sec: mpmath.sec, sp.csc: mpmath.csc, sp.asin: mpmath.asin, sp.acos: mpmath.acos,
    sp.atan: mpmath.atan, sp.sinh: mpmath.sinh, sp.cosh: mpmath.cosh, sp.tanh: mpmath.tanh,
    sp.asinh: mpmath.asinh, sp.acosh: mpmath.acosh, sp.atanh: mpmath.atanh,
    sp.exp: mpmath.exp, sp.log: mpmath.log, sp.Abs: abs, sp.sign: mpmath.sign,
    sp.atan2: mpmath.atan2, sp.re: mpmath.re, sp.im: mpmath.im,
    sp.conjugate: mpmath.conj,
}


class NotNumeric(ValueError):
    """The expression has a part this evaluator cannot give a number for."""


def evaluate(expr: sp.Basic, point: dict, digits: int = 30) -> tuple[complex, float]:
    """(value, magnitude) of expr at `point`: magnitude bounds what cancelled in sums.

    Raises NotNumeric for a free symbol missing from the point or an unknown function, and
    ZeroDivisionError or ValueError where the expression is singular at the point."""
    with mpmath.workdps(digits):
        memo: dict = {}
        pt = {k: _number(v) for k, v in point.items()}
        v, m = _walk(expr, pt, memo)
        return complex(v), float(m)


def _number(v):
    """A point's value (a SymPy number or a Python number; never text) as an mpmath number."""
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return mpmath.mpf(v)
    if isinstance(v, complex):
        return mpmath.mpc(v)
    if not isinstance(v, sp.Basic):
        raise NotNumeric(f"not a number: {type(v).__name__}")
    if isinstance(v, sp.Float):
        return mpmath.mpf(v._mpf_)
    if v.is_real:
        return mpmath.mpf(sp.Float(v, mpmath.mp.dps)._mpf_)
    return mpmath.mpmathify(complex(v))


def _walk(e: sp.Basic, pt: dict, memo: dict):
    hit = memo.get(e)
    if hit is not None:
        return hit
    out = _node(e, pt, memo)
    memo[e] = out
    return out


def _node(e: sp.Basic, pt: dict, memo: dict):
    if e.is_Symbol:
        if e not in pt:
            raise NotNumeric(f"no value for {e}")
        v = pt[e]
        return v, abs(v)
    if e.is_Number or e.is_NumberSymbol or e is sp.I:
        v = mpmath.mpmathify(complex(e)) if e is sp.I else mpmath.mpf(sp.Float(e, mpmath.mp.dps)
                                                                      ._mpf_)
        return v, abs(v)
    if e.is_Add:
        v, m = mpmath.mpf(0), mpmath.mpf(0)
        for a in e.args:
            va, ma = _walk(a, pt, memo)
            v += va
            m += ma
        return v, m
    if e.is_Mul:
        v, m = mpmath.mpf(1), mpmath.mpf(1)
        for a in e.args:
            va, ma = _walk(a, pt, memo)
            v *= va
            m *= ma
        return v, m
    if e.is_Pow:
        vb, mb = _walk(e.base, pt, memo)
        ex = e.exp
        if ex.is_Integer and ex > 0:
            return vb ** int(ex), mb ** int(ex)
        ve, me = _walk(ex, pt, memo)
        if ex.is_Integer:
            v = vb ** int(ex)
        elif ex.is_Rational and ex.q == 2 and mpmath.im(vb) == 0 and vb >= 0:
            v = mpmath.sqrt(vb) ** int(ex.p)
        else:
            v = mpmath.power(vb, ve)
        # first-order propagation: what the base's (and exponent's) cancellation can do
        m = abs(v) + abs(ve * v / vb) * mb if vb != 0 else abs(v)
        if not ex.is_Number and vb != 0:
            m += abs(v * mpmath.log(vb)) * me
        return v, m
    f = _FUNCS.get(e.func)
    if f is not None:
        walked = [_walk(a, pt, memo) for a in e.args]
        args = [w[0] for w in walked]
        v = f(*args)
        if len(args) == 1 and f not in (abs, mpmath.sign, mpmath.re, mpmath.im, mpmath.conj):
            slope = abs(mpmath.diff(f, args[0]))
            return v, abs(v) + slope * walked[0][1]
        if f is mpmath.atan2:
            (y, my), (x, mx) = walked
            r2 = abs(x) ** 2 + abs(y) ** 2
            return v, abs(v) + ((abs(x) * my + abs(y) * mx) / r2 if r2 else 0)
        return v, abs(v) + sum(w[1] for w in walked)
    if isinstance(e, sp.Piecewise) or not e.args:
        raise NotNumeric(f"cannot evaluate {type(e).__name__}")
    # Anything else SymPy knows how to evaluate (rare): substitute the numbers and ask it.
    subs = {k: sp.Float(str(v), mpmath.mp.dps) if mpmath.im(v) == 0 else
            sp.Float(str(mpmath.re(v))) + sp.I * sp.Float(str(mpmath.im(v)))
            for k, v in pt.items() if k in e.free_symbols}
    try:
        v = mpmath.mpmathify(complex(sp.N(e.subs(subs), mpmath.mp.dps)))
    except (TypeError, ValueError) as exc:
        raise NotNumeric(f"cannot evaluate {e}") from exc
    return v, abs(v)
