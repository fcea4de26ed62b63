"""Rational functions in SymEngine: exact values, the zero test, and SymPy's `cancel`.

A statement "for all tensors" is a rational function of a dozen or more symbols with
rational coefficients. SymPy takes a second to substitute a rational point into it and
usually runs out of its time limit in `cancel`; SymEngine does both in milliseconds with
the same exact arithmetic (no rounding anywhere), so a point's value and the proof that the
function vanishes identically mean exactly what they meant before, only sooner. Most of
SymPy's `cancel` is expanding the numerator and denominator: `cancel` here has SymEngine
expand them and SymPy do the rest, for the same canonical result.
"""

from __future__ import annotations

from collections.abc import Sequence

import symengine as se
import sympy as sp
from sympy.core.exprtools import factor_terms
from sympy.simplify.simplify import signsimp

from mechbook.core.secalc import to_sympy

MAX_PROOF_SIZE = 400_000  # characters of a statement's text: beyond, no expansion is tried
# (SymEngine's expansion cannot be interrupted, and its cost grows with the terms it makes)


def is_rational_function(e: sp.Basic) -> bool:
    """A rational function of its symbols with rational coefficients: only symbols,
    rational numbers, sums, products and integer powers (one pass over the tree)."""
    for node in sp.preorder_traversal(e):
        if node.is_Symbol or node.is_Rational or node.is_Add or node.is_Mul:
            continue
        if node.is_Pow and node.exp.is_Integer:
            continue
        return False
    return True


def to_symengine(exprs: Sequence[sp.Basic]) -> list:
    """The expressions as SymEngine objects (once: they are evaluated at many points)."""
    return [se.sympify(e) for e in exprs]


def values_at(exprs: Sequence, point: dict) -> list[sp.Expr]:
    """Each SymEngine rational function at `point` ({symbol: Rational}), as an exact SymPy
    number (zoo or nan where a denominator vanishes)."""
    sub = {se.sympify(k): se.sympify(v) for k, v in point.items()}
    return [e.subs(sub)._sympy_() for e in exprs]


def vanishes_identically(expr) -> bool | None:
    """Is the rational function (SymPy or SymEngine) zero: its numerator over a common
    denominator expands to 0? None when it is too large to try."""
    e = se.sympify(expr)
    if len(str(e)) > MAX_PROOF_SIZE:
        return None
    numerator, _ = e.as_numer_denom()
    return se.expand(numerator) == 0


class TooLarge(Exception):
    """The expanded numerator and denominator outgrow the limit `cancel` was given."""


def cancel(expr: sp.Expr, max_growth: float | None = None) -> sp.Expr:
    """`sympy.cancel(expr)`: the same steps and canonical result (common factors of the
    numerator and denominator polynomials removed), with their expansion in SymEngine.

    `max_growth`: raise TooLarge, before the costly part (the polynomials' conversion and
    their greatest common divisor), when the expanded numerator and denominator are more
    than this many times the size of `expr` (printed lengths): a caller that cancels to
    make an expression smaller can stop there (the cancelled form is seldom far smaller
    than the expansion it comes from)."""
    f = signsimp(expr)
    if f.is_Number or not isinstance(f, sp.Expr) or not f.is_commutative \
            or f.has(sp.Piecewise) or len({s.name for s in f.free_symbols}) \
            != len(f.free_symbols):
        return sp.cancel(expr)
    f = factor_terms(f, radical=True)
    p, q = f.as_numer_denom()
    try:
        expanded = [se.expand(se.sympify(x)) for x in (p, q)]
    except Exception:  # noqa: BLE001 - a function SymEngine does not know: SymPy's way
        return sp.cancel(expr)
    if max_growth is not None and sum(len(str(x)) for x in expanded) > \
            max_growth * len(str(se.sympify(expr))):
        raise TooLarge(f"the expansion outgrows {max_growth:g} times the expression")
    try:
        p, q = (to_sympy(x, y.free_symbols) for x, y in zip(expanded, (p, q), strict=True))
    except Exception:  # noqa: BLE001 - a function SymEngine does not know: SymPy's way
        return sp.cancel(expr)
    c, P, Q = sp.cancel((p, q), expand=False)
    return c * (P / Q)
