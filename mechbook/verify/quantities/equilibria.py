"""Quantities about static equilibria: `equilibrium`, `stability_condition`.
"""

from __future__ import annotations

from mechbook.errors import MechbookError
from mechbook.verify import boundary, boundary_limit
from mechbook.verify.compare import Verdict, all_vanish, combine, vanishes
from mechbook.verify.context import Context
from mechbook.verify.periodic import FloquetVerdicts, time_dependent
from mechbook.verify.registration import EXPR, LIMIT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity


def _engine_points(ctx: Context) -> list[dict]:
    return ctx.analysis.equilibria(ctx.part.system).symbolic


@quantity('equilibrium',
          book='`{at: {q: value}}` or `{where: [equations]}`',
          how=('`at`: the equilibrium conditions vanish there; `where`: an engine '
               'equilibrium satisfies the equations. `stable: true/false` also checks '
               'stability'),
          keys={"stable": {"type": "boolean"}},
          display="equilibrium_points")
def check_equilibrium(ctx: Context, val) -> Verdict:
    """`at:` the point satisfies the equilibrium conditions; `where:` some engine equilibrium
    satisfies the book's equations. `stable:` also checks the stability there."""
    val = ctx.as_map(val, ("book",))
    eq = ctx.analysis.equilibria(ctx.part.system)
    if "at" in val:
        at = ctx.as_map(val["at"], ("book", "at"))
        point = {ctx.system.q[ctx.system.coord_names.index(k)]: ctx.parse(v, ("book", "at", k))
                 for k, v in at.items() if k in ctx.system.coord_names}
        if len(point) != len(ctx.system.q):
            raise ctx.part.error(("book", "at"), "give every coordinate of the point")
        verdicts = [all_vanish(eq.residual(point), ctx.sampler)]
        candidates = [point]
    elif "where" in val:
        where = [ctx.parse(w, ("book", "where", i), equation=True)
                 for i, w in enumerate(ctx.as_list(val["where"], ("book", "where")))]
        candidates = []
        for pt in _engine_points(ctx):
            if all(vanishes(w.subs(pt), ctx.sampler, symbolic=False).ok for w in where):
                candidates.append(pt)
        if not candidates:
            return Verdict(False, "numeric", "no equilibrium found by the engine satisfies "
                           f"{val['where']}; engine found {_engine_points(ctx)}")
        # a numeric pass (6 points, 30 digits) is not a proof: proved only with --prove
        proof = all_vanish([w.subs(candidates[0]) for w in where], ctx.sampler)
        verdicts = [Verdict(True, proof.method if proof.method == "symbolic" else "numeric",
                            f"engine equilibrium {candidates[0]}",
                            power="an equilibrium the engine solves for in closed form "
                                  "satisfies the book's equations" +
                                  (" (proved symbolically)" if proof.method == "symbolic"
                                   else " (6 points, 30 digits)"), unproved=proof.unproved)]

    else:
        raise ctx.part.error(("book",), "an equilibrium answer gives 'at:' or 'where:'")
    verdict = combine(verdicts)
    if not verdict.ok:
        return verdict
    if "stable" in ctx.part.data:
        want = ctx.part.data["stable"]
        for pt in candidates:
            lin = ctx.analysis.linear(ctx.part.system, pt, ctx.sampler.derived)
            for _ in range(4):
                got = lin.numeric_stability(ctx.sampler.draw())
                if (got == "stable") != want:
                    return Verdict(False, "numeric", f"engine finds the equilibrium {got}")
    return combine(verdicts)


@quantity('stability_condition',
          book='relation',
          how=('decided at its boundary (mechbook.verify.boundary): along 8 random rays '
               'through parameter space (factors up to e^2.5 each way) the relation holds '
               'exactly where the linearized system is stable at 40 grid points each, and at '
               'every place where the relation changes truth (found to 30 digits) the '
               'engine\'s verdict, in 40-digit arithmetic, agrees a relative 1e-8 inside and '
               'outside; tangencies are judged on both sides. A boundary moved by more than '
               '1e-8 fails. Coefficients periodic in t (a driven coordinate): the verdict is '
               'Floquet\'s, from the monodromy over one period (detected, or `period:`) '
               'integrated in 113-bit arithmetic. With `limit:` the relation holds only in '
               'that limit: the distance from its boundary to the engine\'s, along each other '
               'parameter, must fall at the order claimed'),
          keys={"limit": LIMIT, "period": EXPR},
          crosschecks=("modes",), display="sylvester_criterion", sweeps=("stability",))
def check_stability_condition(ctx: Context, val) -> Verdict:
    """The book's condition holds exactly where the engine finds the point stable, compared
    at the condition's boundary (mechbook.verify.boundary) and widely along rays; with
    `limit:`, its boundary approaches the engine's (mechbook.verify.boundary_limit)."""
    cond = ctx.parse(val, ("book",), relation=True)
    lin = ctx.linear()
    floquet = None
    if time_dependent(lin):
        floquet = FloquetVerdicts(ctx, lin)
        stable = floquet.classify
    else:
        if "period" in ctx.part.data:
            raise ctx.part.error(("period",), "`period:` is for a linearization whose "
                                 "coefficients depend on t; these do not")

        def stable(pt: dict, near: bool) -> bool | None:
            try:
                got = lin.numeric_stability(pt)
                if near or got == "marginal":
                    got = lin.precise_stability(pt)
            except (ZeroDivisionError, ValueError) as exc:  # a singular matrix: no verdict
                raise MechbookError(f"no linear system at this point ({exc})") from None
            return None if got == "marginal" else got == "stable"

    if "limit" in ctx.part.data:
        got = boundary_limit.check(ctx, cond, stable, boundary_limit.FLOOR if floquet is None
                                   else boundary_limit.FLOQUET_FLOOR)
    else:
        got = boundary.verdict(boundary.compare(cond, stable, ctx.sampler,
                                                ("stable", "unstable")))
    if got.ok and floquet is not None:
        got.power = f"{got.power}; {floquet.power()}"
    return got
