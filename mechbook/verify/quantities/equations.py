"""Quantities about the equations of motion: `lagrangian`, `eom`, `conserved`.
"""

from __future__ import annotations

import sympy as sp

from mechbook.verify.compare import Verdict, all_vanish
from mechbook.verify.context import Context, linear_accelerations, strip_const
from mechbook.verify.registry import quantity


@quantity('lagrangian',
          book='expression',
          how=("the difference from the engine's L has identically vanishing Lagrange "
               'expressions (equal up to a total time derivative). With `about`, against'
               " the engine's L expanded to second order"))
def check_lagrangian(ctx: Context, val) -> Verdict:
    """Equal up to a total time derivative: the difference has vanishing Lagrange expressions.
    With `about:`, the engine's Lagrangian is first expanded to second order there."""
    book = ctx.parse(val, ("book",))
    engine = ctx.system.lagrangian
    if "about" in ctx.part.data:
        engine = ctx.analysis.equilibria(ctx.part.system).quadratic_lagrangian(ctx.point())
    diff = book - engine
    sys = ctx.system
    exprs = [sys.dt(sp.diff(diff, qd)) - sp.diff(diff, q) for q, qd in zip(sys.q, sys.qd,
                                                                           strict=True)]
    return all_vanish(exprs, ctx.sampler)


@quantity('eom',
          book='list of equations',
          how=("each holds once the engine's solved accelerations are substituted "
               '(linearized ones with `about`); so any nonzero multiple of an equation '
               'is accepted, and each must contain an acceleration'))
def check_eom(ctx: Context, val) -> Verdict:
    """Each book equation holds once the engine's accelerations are substituted
    (the linearized ones when `about` is given)."""
    eqs = [ctx.parse(v, ("book", i), equation=True)
           for i, v in enumerate(ctx.as_list(val, ("book",)))]
    if "about" in ctx.part.data:
        acc = linear_accelerations(ctx.linear())
    else:
        acc = dict(zip(ctx.dyn.qdd, ctx.dyn.accelerations, strict=True))
    out = []
    for i, e in enumerate(eqs):
        if not (e.free_symbols & set(ctx.dyn.qdd)):
            raise ctx.part.error(("book", i), "an equation of motion must contain an "
                                 "acceleration; a first integral is a 'conserved' part")
        out.append(e.subs(acc))
    return all_vanish(out, ctx.sampler)


@quantity('conserved',
          book='expression or list (`= const` allowed)',
          how='its time derivative vanishes along the motion')
def check_conserved(ctx: Context, val) -> Verdict:
    """d/dt of each book expression vanishes along the motion ('= const' may be written)."""
    vals = val if isinstance(val, list) else [val]
    out = []
    if "about" in ctx.part.data:
        acc = linear_accelerations(ctx.linear())
    else:
        acc = dict(zip(ctx.dyn.qdd, ctx.dyn.accelerations, strict=True))
    for i, v in enumerate(vals):
        sub = ("book", i) if isinstance(val, list) else ("book",)
        e = ctx.parse(strip_const(v), sub)
        if not (e.free_symbols & set(ctx.dyn.q + ctx.dyn.qd)):
            raise ctx.part.error(sub, "a conserved quantity must depend on the motion")
        out.append(ctx.system.dt(e).subs(acc))
    return all_vanish(out, ctx.sampler)
