"""Quantities about the equations of motion: `lagrangian`, `eom`, `conserved`.
"""

from __future__ import annotations

import sympy as sp

from mechbook.engine.lagrange import lagrange_expressions
from mechbook.verify.compare import Verdict, all_vanish
from mechbook.verify.context import Context, linear_accelerations, split_named
from mechbook.verify.manifold_constant import constant_on_manifold
from mechbook.verify.registration import Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity


@quantity('lagrangian',
          book='expression',
          how=("the difference from the engine's L has identically vanishing Lagrange "
               'expressions (equal up to a total time derivative). With `about`, against'
               " the engine's L expanded to second order"),
          equivalent=("gauge",),
          crosschecks=("newton",), display="system_lagrangian")
def check_lagrangian(ctx: Context, val) -> Verdict:
    """Equal up to a total time derivative: the difference has vanishing Lagrange expressions.
    With `about:`, the engine's Lagrangian is first expanded to second order there."""
    book = ctx.parse(val, ("book",))
    engine = ctx.system.lagrangian
    if "about" in ctx.part.data:
        engine = ctx.analysis.equilibria(ctx.part.system).quadratic_lagrangian(ctx.point())
    return all_vanish(lagrange_expressions(ctx.system, book - engine), ctx.sampler)


@quantity('eom',
          book='list of equations',
          how=("each holds once the engine's solved accelerations are substituted "
               '(linearized ones with `about`; with constraints the multipliers '
               '`lambda_<name>` too, on the constraint manifold); so any nonzero multiple of '
               'an equation is accepted, and each must contain an acceleration'),
          crosschecks=("newton",), display="equations_of_motion")
def check_eom(ctx: Context, val) -> Verdict:
    """Each book equation holds once the engine's accelerations are substituted
    (the linearized ones when `about` is given)."""
    eqs = [ctx.parse(v, ("book", i), equation=True)
           for i, v in enumerate(ctx.as_list(val, ("book",)))]
    if "about" in ctx.part.data:
        acc = linear_accelerations(ctx.linear())
    elif ctx.dyn.constrained:  # the multipliers solved with the accelerations
        acc = dict(ctx.dyn.solved)
    else:
        acc = dict(zip(ctx.dyn.qdd, ctx.dyn.accelerations, strict=True))
    out = []
    for i, e in enumerate(eqs):
        if not (e.free_symbols & set(ctx.dyn.qdd)):
            raise ctx.part.error(("book", i), "an equation of motion must contain an "
                                 "acceleration; a first integral is a 'conserved' part")
        out.append(e.xreplace(acc))  # accelerations are symbols: no pattern search
    return all_vanish(out, ctx.sampler)


ENERGY_NAMES = ("energy", "jacobi", "E", "h")  # the energy function (Jacobi's integral)


@quantity('conserved',
          book=('expression or list (`= const` allowed); or `name = expression` where the '
                'book names the quantity: a momentum `p_<q>` (or a sum of them), the energy '
                'function `E`, `h`, `energy` or `jacobi` (Jacobi\'s integral), or a name '
                'the problem defines from the motion (a body\'s `rates:`)'),
          how=('its time derivative vanishes along the motion. A named quantity must also '
               'equal the engine\'s own (a momentum or a defined name exactly, the energy '
               'function up to an additive constant), so a constant factor fails; a bare '
               '"this is conserved" is a claim any function of it satisfies too (so its '
               'multiples pass), and the verdict says so'),
          names=lambda ctx: _with_energy_names(ctx),
          equivalent=("function",),
          crosschecks=("newton", "first_integrals"), display="momenta_and_energy")
def check_conserved(ctx: Context, val) -> Verdict:
    """d/dt of each book expression vanishes along the motion ('= const' may be written);
    a named one (`p_psi = ...`) is also compared with the engine's quantity of that name."""
    vals = val if isinstance(val, list) else [val]
    out = []
    named = []
    if "about" in ctx.part.data:
        acc = linear_accelerations(ctx.linear())
    else:
        acc = dict(zip(ctx.dyn.qdd, ctx.dyn.accelerations, strict=True))
    for i, v in enumerate(vals):
        sub = ("book", i) if isinstance(val, list) else ("book",)
        name, text = split_named(v)
        if name is not None:
            engine, up_to_constant, what = _named(ctx, name, sub)
            e = ctx.parse(text, sub)
            diff = e - engine
            manifold = ctx.sampler.manifold
            if up_to_constant and manifold is not None and not manifold.empty:
                # constrained: equal up to a constant on the manifold, where the motion is
                same = constant_on_manifold(e, engine, ctx.system, ctx.sampler)
            elif up_to_constant:  # the energy: V (so h) is defined up to a constant
                motion = list(ctx.system.q) + list(ctx.system.qd) + [ctx.system.t]
                checks = [sp.diff(diff, x) for x in motion if diff.has(x)]
                same = all_vanish(checks, ctx.sampler) if checks else None
            else:
                same = all_vanish([diff], ctx.sampler)
            if same is not None and not same.ok:
                return Verdict(False, same.method, f"{name} is {what}: the book's "
                               f"expression differs from the engine's ({same.detail})")
            named.append(f"{name} ({what})")
        else:
            e = ctx.parse(text, sub)
        if not (e.free_symbols & set(ctx.dyn.q + ctx.dyn.qd)):
            raise ctx.part.error(sub, "a conserved quantity must depend on the motion")
        out.append(ctx.system.dt(e).xreplace(acc))
    verdict = all_vanish(out, ctx.sampler)
    if verdict.ok:
        bare = len(vals) - len(named)
        notes = [f"identified: {'; '.join(named)}"] if named else []
        if bare:
            notes.append(f"{bare} bare first integral{'s' if bare > 1 else ''}: any function "
                         "of one (a multiple, say) is conserved too and passes")
        verdict.detail = "; ".join(notes + ([verdict.detail] if verdict.detail else []))
    return verdict


def _with_energy_names(ctx: Context) -> dict:
    """The part's names and the energy function's (E, h, energy, jacobi) where the problem
    does not use them: a book value may name the quantity it gives."""
    out = dict(ctx.names)
    for n in ENERGY_NAMES:
        out.setdefault(n, sp.Symbol(n, real=True))
    return out


def _named(ctx: Context, text: str, sub: tuple) -> tuple[sp.Expr, bool, str]:
    """The engine's value of a named quantity (the left side of `name = expression`): an
    expression in momenta p_<q>, the energy function or names the problem derives from the
    motion; (value, up to a constant?, what it is)."""
    name = text.strip()
    sys, dyn = ctx.system, ctx.dyn
    if name in ENERGY_NAMES and name not in ctx.names:
        return dyn.energy_function, True, "the energy function, up to a constant"
    momenta = {sp.Symbol("p_" + q.name, real=True): p
               for q, p in zip(sys.q, dyn.momenta, strict=True)}
    derived = {k for k, v in sys.names.items()
               if not isinstance(v, sp.Symbol) and k not in ctx.part.key.symbols}
    idents = _identifiers(name)
    used = [k for k in idents if k in derived]
    if not used and not any(sp.Symbol(k, real=True) in momenta for k in idents):
        known = ", ".join(["p_<coordinate>", *ENERGY_NAMES, *sorted(derived)])
        raise ctx.part.error(sub, f"{name!r} names no quantity the engine computes; the "
                             f"left side may use {known}")
    lhs = ctx.parse(name, sub)
    motion = set(sys.q) | set(sys.qd)
    if not used and lhs.free_symbols & motion:
        raise ctx.part.error(sub, "the left side names the quantity (momenta, the energy, "
                             "defined names); the coordinates belong on the right")
    used_p = lhs.free_symbols & set(momenta)
    what = ("as the problem defines it from the motion" if not used_p else
            "the engine's momentum" if len(used_p) == 1 else "the engine's momenta")
    return lhs.xreplace(momenta), False, what


def _identifiers(text: str) -> list[str]:
    import ast

    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        return []
    return [n.id for n in ast.walk(tree) if isinstance(n, ast.Name)]
