"""A string's displacement field as names: u(x, t), its velocity, x, and `integral`.

A continuous string (`string:`) is described by its mode amplitudes q_k; a book also writes
results as integrals over the string of the field u(x, t) = Σ q_k sin(kπx/l) ("p_k =
σ∫ u_t sin(kπx/l) dx"). With `field: u` the string names its field: `u` and `udot` (∂u/∂t)
are expressions in x and the state, `x` the position along the string, and
`integral(f, x, lo, hi)` a definite integral over it, done in closed form (products of
sines turned into sums first; 10 s at most). Problem expressions after the string and the
answer keys of the system may use them; outside an integral x is a free variable, so a
book's u(x, t) is compared as a function of x too (at random x, like a state variable).
"""

from __future__ import annotations

import sympy as sp

from mechbook.core.timeout import Timeout, hard_time_limit
from mechbook.model.expr import Operator

INTEGRAL_SECONDS = 10


def _integral(x: sp.Symbol):
    def integral(f, var, lo, hi):
        if var != x:
            raise ValueError(f"integrate over the string's coordinate {x}")
        if sp.S(lo).has(x) or sp.S(hi).has(x):
            raise ValueError("the limits do not depend on the variable of integration")
        from sympy.simplify.fu import TR8

        try:
            with hard_time_limit(INTEGRAL_SECONDS):
                out = sp.integrate(sp.expand(TR8(sp.expand(f))), (x, lo, hi))
        except Timeout:
            raise ValueError(f"no closed form within {INTEGRAL_SECONDS} s") from None
        if out.has(sp.Integral):
            raise ValueError("no closed form")
        return out

    return integral


def field_names(name: str, x: sp.Symbol, modes: list, q: list, qd: list) -> dict:
    """`name`, `name`dot, x and integral() for the field Σ q_k·mode_k(x)."""
    u = sp.Add(*[a * m for a, m in zip(q, modes, strict=True)])
    ut = sp.Add(*[a * m for a, m in zip(qd, modes, strict=True)])
    return {name: u, name + "dot": ut, "x": x,
            "integral": Operator("integral", _integral(x), (4, 4))}
