"""Linearizations whose coefficients are periodic in time: the period, or why there is none.

About a rest point of a system with a driven coordinate (a pivot moved up and down, a
stiffness modulated, a swing's length pumped) the linear equations
M(t)·δq̈ + C(t)·δq̇ + K(t)·δq = 0 keep t. Floquet theory (mechbook.numerics.floquet)
needs their period T. It is read off the coefficients: every occurrence of t must sit inside
a sine or cosine (or tan, sec, csc, cot) of an argument linear in t, a·t + b, and the
frequencies a must be rational multiples of one another; T = 2π/Ω with Ω their greatest
common divisor (a ratio that SymPy cannot show rational, t outside such a function, or a
growing coefficient is refused with the reason). A period the author declares is used as
given and verified numerically instead (`declared_period_holds`).
"""

from __future__ import annotations

import math
from fractions import Fraction
from functools import reduce

import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate_mp
from mechbook.core.timeout import Timeout, time_limit
from mechbook.engine.linear import LinearSystem
from mechbook.errors import UnsupportedError

TRIG = (sp.sin, sp.cos, sp.tan, sp.sec, sp.csc, sp.cot)


def time_dependent(lin: LinearSystem) -> bool:
    """Do M, C or K depend on t (a driven coordinate, a prescribed modulation)? A
    first-order linearization (mechbook.engine.state_space) is built free of t."""
    if lin.first_order:
        return False
    t = lin.dyn.sys.t
    return any(x.has(t) for A in (lin.M, lin.C, lin.K) for x in A)


def _frequencies(expr: sp.Expr, t: sp.Symbol) -> list[sp.Expr]:
    """The coefficients a of the trigonometric arguments a·t + b in `expr` (UnsupportedError
    where t occurs otherwise)."""
    out: list[sp.Expr] = []
    stand_in = {}
    for f in expr.atoms(*TRIG):
        arg = f.args[0]
        if not arg.has(t):
            continue
        a = sp.diff(arg, t)
        if a.has(t):
            raise UnsupportedError(f"coefficients not periodic in t: {sp.sstr(f)[:80]} has an "
                                   "argument that is not linear in t")
        out.append(sp.simplify(a))
        stand_in[f] = sp.Dummy()
    if expr.xreplace(stand_in).has(t):
        raise UnsupportedError("coefficients not periodic in t: t occurs outside a sine or "
                               f"cosine in {sp.sstr(expr)[:100]}")
    return out


def period(lin: LinearSystem) -> sp.Expr:
    """T such that M, C, K are T-periodic: 2π over the greatest common divisor of the
    trigonometric frequencies in them."""
    t = lin.dyn.sys.t
    freqs: list[sp.Expr] = []
    for A in (lin.M, lin.C, lin.K):
        for x in A:
            if x.has(t):
                freqs += _frequencies(x, t)
    if not freqs:
        raise UnsupportedError("coefficients not periodic in t (no sine or cosine of t)")
    base = freqs[0]
    ratios = []
    for a in freqs:
        try:
            with time_limit(5):
                r = sp.simplify(a / base)
        except Timeout:
            r = None
        if r is None or not r.is_Rational or r == 0:
            raise UnsupportedError(f"coefficients not periodic in t: the frequencies {base} "
                                   f"and {a} are not rational multiples of one another")
        ratios.append(Fraction(int(r.p), int(r.q)))
    num = reduce(math.gcd, (abs(r.numerator) for r in ratios))
    den = reduce(lambda x, y: x * y // math.gcd(x, y), (r.denominator for r in ratios))
    omega = base * sp.Rational(num, den)
    return 2 * sp.pi / omega


def declared_period_holds(lin: LinearSystem, T: sp.Expr, values: dict, dps: int = 30) -> bool:
    """M, C, K at t and t + T agree (to 1e-20 of their size) at a few times: a period the
    author declares is checked, not trusted."""
    import mpmath

    t = lin.dyn.sys.t
    with mpmath.workdps(dps):
        Tv = evaluate_mp(T, values, dps)
        for t0 in ("0.1234", "0.71", "1.9"):
            for A in (lin.M, lin.C, lin.K):
                for x in A:
                    if not x.has(t):
                        continue
                    try:
                        v0 = evaluate_mp(x, {**values, t: sp.Float(t0, dps)}, dps)
                        v1 = evaluate_mp(x, {**values, t: sp.Float(
                            str(mpmath.mpf(t0) + Tv), dps)}, dps)
                    except (NotNumeric, ZeroDivisionError, ValueError, TypeError):
                        return False
                    if abs(v1 - v0) > mpmath.mpf(10) ** -20 * max(1, abs(v0)):
                        return False
    return True
