"""Is a symbol-free expression a finite real number? Decided in double precision.

The safe parser asks this of every constant a problem file builds (mechbook/model/expr.py).
SymPy's own answers (`is_finite`, `is_extended_real`, `evalf`) may evaluate with mpmath at
unbounded precision: `exp(exp(exp(exp(100)))).evalf()` runs for minutes, and assumption
queries on such numbers overflow inside mpmath. Here the value is computed with Python
floats over the expression's tree (each distinct node once), which cannot hang: a constant
whose value overflows a double, has no real value (`sqrt(-1)`, `asin(2)`, `log(-1)`) or is
SymPy's complex infinity or NaN (`1/0`, `0/0`) is refused. Every textbook constant is far
inside that range.
"""

from __future__ import annotations

import math

import mpmath
import sympy as sp

from mechbook.core import special

_NOT_FINITE = (sp.zoo, sp.oo, -sp.oo, sp.nan)


def _real_mp(f):
    """An mpmath function at double precision, refused (ValueError) where it is not real:
    K(m) and E(m) are complex for m > 1."""
    def value(*args):
        with mpmath.workprec(53):
            v = f(*(mpmath.mpf(a) for a in args))
        if mpmath.im(v) != 0:
            raise ValueError("not real")
        return float(mpmath.re(v))

    return value


_FUNCTIONS = {
    sp.sin: math.sin, sp.cos: math.cos, sp.tan: math.tan,
    sp.cot: lambda x: 1 / math.tan(x), sp.sec: lambda x: 1 / math.cos(x),
    sp.csc: lambda x: 1 / math.sin(x),
    sp.asin: math.asin, sp.acos: math.acos, sp.atan: math.atan, sp.atan2: math.atan2,
    sp.sinh: math.sinh, sp.cosh: math.cosh, sp.tanh: math.tanh,
    sp.asinh: math.asinh, sp.acosh: math.acosh, sp.atanh: math.atanh,
    sp.exp: math.exp, sp.log: math.log, sp.Abs: abs,
    sp.sign: lambda x: math.copysign(1.0, x) if x else 0.0,
    sp.elliptic_k: _real_mp(mpmath.ellipk), sp.elliptic_e: _real_mp(mpmath.ellipe),
    sp.gamma: math.gamma,
    **{f: _real_mp(mp) for f, mp in special.MPMATH.items()},
}


_ONLY_NOT_REAL = ("is not real", "has no finite real value")


class NotAConstant(Exception):
    """The expression is not a finite real number in double precision (message: why)."""


def _value(expr: sp.Basic, memo: dict) -> float | None:
    """The float value of a numeric expression, None if it holds something this evaluator
    does not know (then nothing is claimed); NotAConstant if it is not finite and real."""
    if expr in memo:
        return memo[expr]
    if expr.is_Integer or expr.is_Rational:
        try:
            v = expr.p / expr.q
        except OverflowError:
            raise NotAConstant("is too large for double precision") from None
    elif expr.is_Float:
        v = float(expr)
    elif expr is sp.pi:
        v = math.pi
    elif expr is sp.E:
        v = math.e
    elif expr is sp.I:
        raise NotAConstant("is not real")
    elif expr in _NOT_FINITE:
        raise NotAConstant("is not finite")
    else:
        args = [_value(a, memo) for a in expr.args]
        if any(a is None for a in args):
            v = None
        else:
            v = _apply(expr, args)
    if v is not None and not math.isfinite(v):
        raise NotAConstant("is not finite in double precision")
    memo[expr] = v
    return v


def _apply(expr: sp.Basic, args: list[float]) -> float | None:
    try:
        if expr.is_Add:
            return math.fsum(args)
        if expr.is_Mul:
            return math.prod(args)
        if expr.is_Pow:
            base, exp = args
            if base < 0 and not float(exp).is_integer():
                raise NotAConstant("is not real")
            if base == 0 and exp < 0:
                raise NotAConstant("is not finite")
            return math.pow(base, exp)
        fn = _FUNCTIONS.get(expr.func)
        return fn(*args) if fn is not None else None
    except OverflowError:
        raise NotAConstant("is too large for double precision") from None
    except special.DomainError as exc:  # a special function outside its domain: why
        raise NotAConstant(f"is outside its function's domain: {exc}") from None
    except (ValueError, ZeroDivisionError):  # a math domain error: no real value
        raise NotAConstant("has no finite real value") from None


def bad_constant(expr: sp.Basic, memo: dict | None = None,
                 complex_ok: bool = False) -> str | None:
    """Why a symbol-free expression is not a finite real number (None if it is, or if it
    has free symbols, or is not a number at all). With `complex_ok` (tensor expressions,
    whose eigenvalues are complex on purpose) only a non-finite value is refused."""
    # is_number stops at the first symbol it meets; free_symbols walks the whole tree, and
    # the parser asks this of every node it builds (quadratic in a large tensor formula)
    if not isinstance(expr, sp.Expr) or expr.is_Rational or not expr.is_number:
        return None
    if expr.has(*_NOT_FINITE):
        return "is not finite"
    try:
        _value(expr, {} if memo is None else memo)
    except NotAConstant as exc:
        if complex_ok and str(exc) in _ONLY_NOT_REAL:
            return None  # complex on purpose; it is finite
        return str(exc)
    return None

