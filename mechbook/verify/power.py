"""When a changed answer still means the same: the equivalent mutants of a power measurement.

A mutant that the checker passes is a miss only if it is wrong. It is not wrong when it
provably means what the original meant: the same value (a factor that cancels), an
equation multiplied by a factor free of the motion (q, q̇, q̈, t), a relation true at
exactly the same points (compared at its boundary, mechbook.verify.boundary), or a change
the quantity declares it cannot see (`equivalent=` in its registration): a conserved
quantity's function ("function"), a constant added ("shift"), a factor ("scale"), a mode
shape's length ("direction"). Each rule is decided at 30-digit random points.
"""

from __future__ import annotations

import sympy as sp

from mechbook.core.numeval import holds
from mechbook.model.expr import _split_single_equals
from mechbook.verify import boundary
from mechbook.verify.compare import equal, vanishes
from mechbook.verify.context import Context, strip_const
from mechbook.verify.registry import quantities


def _motion(ctx: Context) -> list[sp.Symbol]:
    sys = ctx.system
    if sys is None:
        return []
    dyn = ctx.dyn
    return list(sys.q) + list(sys.qd) + list(dyn.qdd) + [sys.t]


def _kind(text: str) -> str:
    if any(c in text for c in "<>"):
        return "relation"
    pieces = _split_single_equals(text)
    if len(pieces) == 2 and pieces[1].strip() not in ("const", "constant"):
        return "equation"
    return "expression"


def _free_of_motion(expr: sp.Expr, ctx: Context) -> bool:
    grads = [sp.diff(expr, x) for x in _motion(ctx) if expr.has(x)]
    return all(vanishes(g, ctx.sampler, symbolic=False).ok for g in grads)


def _proportional(a: sp.Expr, b: sp.Expr, ctx: Context) -> bool:
    """a = c·b with c free of the motion (and nonzero)."""
    xs = [x for x in _motion(ctx) if a.has(x) or b.has(x)]
    return all(vanishes(a * sp.diff(b, x) - b * sp.diff(a, x), ctx.sampler, symbolic=False).ok
               for x in xs)


def _functionally_dependent(a: sp.Expr, b: sp.Expr, ctx: Context) -> bool:
    """a is a function of b (their gradients in the motion variables are parallel)."""
    xs = [x for x in _motion(ctx) if a.has(x) or b.has(x)]
    ga = [sp.diff(a, x) for x in xs]
    gb = [sp.diff(b, x) for x in xs]
    return all(vanishes(ga[i] * gb[j] - ga[j] * gb[i], ctx.sampler, symbolic=False).ok
               for i in range(len(xs)) for j in range(i + 1, len(xs)))


def same_meaning(ctx: Context, path: tuple, old, new) -> str:
    """Why the value `new` at `path` means the same as `old` ('' if it does not, or if that
    cannot be shown)."""
    if isinstance(new, bool) or not isinstance(new, str):
        return ""
    sub = path
    old_text = str(old)
    kind = _kind(old_text)
    declared = quantities()[ctx.part.quantity].equivalent
    if callable(declared):
        declared = declared(ctx.part.data)
    if kind == "relation":
        a = ctx.parse(old_text, sub, relation=True)
        b = ctx.parse(new, sub, relation=True)
        got = boundary.compare(b, lambda pt, near: holds(a, pt), ctx.sampler,
                               ("true", "false"))
        return "the same relation (boundaries agree)" if got.ok else ""
    if kind == "equation":
        a = ctx.parse(old_text, sub, equation=True)
        b = ctx.parse(new, sub, equation=True)
        return "the same equation times a factor" if _proportional(b, a, ctx) else ""
    a = ctx.parse(strip_const(old_text), sub)
    b = ctx.parse(strip_const(new), sub)
    if equal(a, b, ctx.sampler, symbolic=False).ok:
        return "the same value"
    if "limit" in ctx.part.data and _asymptotically_equal(ctx, a, b):
        return "the same to the order the `limit:` states (they differ beyond it)"
    if "gauge" in declared and _total_derivative(b - a, ctx):
        return "a total time derivative added (the same equations of motion)"
    if "shift" in declared and _free_of_motion(b - a, ctx):
        return "a constant added (the quantity is defined up to one)"
    if "scale" in declared and _proportional(b, a, ctx):
        return "a constant factor (the quantity is defined up to one)"
    if "function" in declared and _functionally_dependent(b, a, ctx):
        return "a function of the same conserved quantity"
    if "direction" in declared and _only_component(ctx, path):
        return "the only nonzero component of a mode shape scaled (its direction is kept)"
    return ""


def _total_derivative(d: sp.Expr, ctx: Context) -> bool:
    """d/dt ∂D/∂q̇ − ∂D/∂q vanishes identically for every coordinate: D is a total
    derivative (a null Lagrangian), which changes no equation of motion."""
    sys = ctx.system
    if sys is None:
        return False
    return all(vanishes(sys.dt(sp.diff(d, v)) - sp.diff(d, q), ctx.sampler,
                        symbolic=False).ok for q, v in zip(sys.q, sys.qd, strict=True))


def _asymptotically_equal(ctx: Context, a: sp.Expr, b: sp.Expr) -> bool:
    """Do a and b agree toward the part's limit to its stated order (their relative
    difference falls as fast as the book's error must)? Then both are equally right."""
    from mechbook.verify.compare import value
    from mechbook.verify.quantities.oscillations import asymptotic

    def error(pt) -> float:
        va, vb = value(a, pt), value(b, pt)
        return abs(va - vb) / max(abs(va), 1e-300)

    return asymptotic(ctx, error).ok


def _only_component(ctx: Context, path: tuple) -> bool:
    """Is the leaf at `path` the only nonzero entry of the mapping that holds it?"""
    parent = ctx.part.data
    for p in path[:-1]:
        parent = parent[p]
    if not isinstance(parent, dict):
        return False
    sub = path[:-1]
    for k, v in parent.items():
        if k == path[-1]:
            continue
        e = ctx.parse(v, sub + (k,))
        if not vanishes(e, ctx.sampler, symbolic=False).ok:
            return False
    return True
