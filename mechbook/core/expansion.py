"""Taylor expansion of a Lagrangian about a point, counting small quantities by order.

Displacements from the point, velocities and parameters declared `small` are all first
order; the expansion keeps terms up to the requested order (the constant term is dropped,
as it does not affect the motion).
"""

from __future__ import annotations

import sympy as sp

EPS = sp.Symbol("epsilon_order", positive=True)


def expand_lagrangian(lag: sp.Expr, q: list, qd: list, point: dict, small: list,
                      order: int = 2) -> sp.Expr:
    """L to `order` in (q − point, q̇, small parameters), in the original coordinates."""
    sub = {c: point.get(c, sp.S.Zero) + EPS * c for c in q}
    sub.update({v: EPS * v for v in qd})
    sub.update({s: EPS * s for s in small})
    scaled = lag.xreplace(sub)  # pure replacements: xreplace, not subs (far cheaper)
    out = sp.S.Zero
    term = scaled
    for k in range(1, order + 1):
        term = sp.diff(term, EPS)
        out += term.xreplace({EPS: sp.S.Zero}) / sp.factorial(k)
    back = {c: c - point.get(c, sp.S.Zero) for c in q}
    return sp.expand(out.xreplace(back))


def trig_canonical(expr: sp.Expr, velocities: list | None = None) -> sp.Expr:
    """expr expanded, with every sin(x)**2 written 1 - cos(x)**2: an exact rewriting, far
    cheaper than simplify, that lets a kinetic energy built from Cartesian positions
    collapse (cos**2 + sin**2 terms cancel) before Routh's reduction differentiates it.
    With `velocities`, the coefficient of each monomial in them is factored (small
    polynomials: (l - r)**2*sin(theta)**2 stays one product instead of six terms)."""
    e = sp.expand(expr)
    sines = {x for x in e.atoms(sp.sin)}
    if sines:
        e = sp.expand(e.subs({x**2: 1 - sp.cos(x.args[0]) ** 2 for x in sines}))
    if not velocities:
        return e
    parts = sp.collect(e, list(velocities), evaluate=False)
    return sp.Add(*[sp.factor(c) * m for m, c in parts.items()])
