"""Whether SymPy's exact algebra can take an expression at all.

A rational exponent p/q makes `cancel`, `factor` and `simplify` treat base**(1/q) as a
polynomial generator of degree |p|. With a large p or q (a power 2·(1 + 1e-19), that is
x**(10000000000000000001/5000000000000000000), is valid input) the heuristic GCD raises
an integer to that degree, and gmp aborts the whole process ("overflow in mpz type"): no
exception and no time limit can catch it. Such an expression is decided numerically only;
a proof is not attempted.
"""

from __future__ import annotations

import sympy as sp

MAX_EXPONENT_TERM = 10**4  # |p| and q of a rational exponent p/q that exact algebra takes


def within_exact_reach(*exprs: object) -> bool:
    """True if no rational exponent in `exprs` has a numerator or denominator above
    MAX_EXPONENT_TERM (integer exponents are bounded when a file is read).

    Example: within_exact_reach(sp.sqrt(sp.Symbol("x"))) is True;
    within_exact_reach(sp.Symbol("x")**sp.Rational(10**19 + 1, 10**19)) is False.
    """
    for expr in exprs:
        if not isinstance(expr, sp.Basic):
            continue
        for power in expr.atoms(sp.Pow):
            e = power.exp
            if e.is_Rational and not e.is_Integer and \
                    max(abs(e.p), e.q) > MAX_EXPONENT_TERM:
                return False
    return True
