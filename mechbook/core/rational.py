"""Rational functions with rational coefficients, evaluated and tested for zero exactly in
SymEngine.

A statement "for all tensors" is such a function of a dozen or more symbols. SymPy takes
a second to substitute a rational point into it and usually runs out of its time limit in
`cancel`; SymEngine does both in milliseconds with the same exact arithmetic (no rounding
anywhere), so a point's value and the proof that the function vanishes identically mean
exactly what they meant before, only sooner.
"""

from __future__ import annotations

from collections.abc import Sequence

import symengine as se
import sympy as sp

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
