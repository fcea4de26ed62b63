"""Steady motions as answers: `steady_rates`, `steady_exists`, `stability`,
`effective_potential` (mechbook.engine.steady; Routh's reduction for stability).

A part names the steady motion by `about:` (the coordinates at rest, e.g. theta: theta0),
`unknown:` (the cyclic coordinate whose rate the book gives) and `hold:` (relations that fix
the other cyclic rates, e.g. "psidot + phidot*cos(theta) = omega3").
"""

from __future__ import annotations

import sympy as sp

from mechbook.core.numeval import holds
from mechbook.engine.steady import SteadyFamily, effective_potential, polynomial_roots
from mechbook.verify.compare import Sampler, Verdict, all_vanish, combine
from mechbook.verify.context import Context, numbers
from mechbook.verify.quantities.oscillations import asymptotic
from mechbook.verify.registry import ESTIMATE, LIMIT, NAME, quantity

HOLD = {"type": "array", "items": {"type": "string"}}
ROOT_RTOL = 1e-9
STEADY_KEYS = {"hold": HOLD, "unknown": NAME}


def family(ctx: Context) -> SteadyFamily:
    """The steady motions a part names: `about:`, `unknown:`, `hold:`."""
    data = ctx.part.data
    if "about" not in data:
        raise ctx.part.error((), "a steady motion needs `about:` (the coordinates at rest)")
    name = data.get("unknown")
    if name not in ctx.system.coord_names:
        raise ctx.part.error(("unknown",), f"`unknown:` must name a coordinate, not {name!r}")
    unknown = ctx.system.q[ctx.system.coord_names.index(name)]
    hold = [ctx.parse(h, ("hold", i), equation=True)
            for i, h in enumerate(data.get("hold") or [])]
    key = ("steady-family", ctx.part.system, repr(sorted(data["about"].items())), name,
           tuple(data.get("hold") or []))
    cache = ctx.analysis.__dict__.setdefault("_steady_families", {})
    if key not in cache:
        cache[key] = SteadyFamily.build(ctx.dyn, ctx.point(), unknown, hold)
    return cache[key]


def _rate_symbol(ctx: Context, fam: SteadyFamily) -> sp.Symbol:
    return ctx.system.qd[ctx.system.q.index(fam.unknown)]


@quantity('steady_rates',
          book=('equation in the unknown rate (e.g. `phidot`), or a list of rates'),
          how=('an equation: at random parameter points its real roots in the rate are '
               'exactly the rates at which the generalized forces on the `about:` '
               'coordinates vanish (polynomial roots, 30 digits). A list: each rate makes '
               'them vanish and, unless `partial: true`, there are no other real ones; '
               'with `limit:` each book rate approaches an engine rate (decades, as for '
               'frequencies). `hold:` fixes the other cyclic rates; `estimate:` compares '
               'at the book\'s numbers to its precision'),
          keys={**STEADY_KEYS, "partial": {"type": "boolean"}, "limit": LIMIT,
                "estimate": ESTIMATE})
def check_steady_rates(ctx: Context, val) -> Verdict:
    fam = family(ctx)
    xdot = _rate_symbol(ctx, fam)
    if isinstance(val, str) and "=" in val and "<" not in val and ">" not in val:
        eq = ctx.parse(val, ("book",), equation=True)
        if not eq.has(xdot):
            raise ctx.part.error(("book",), f"the equation must contain the rate {xdot}")
        # at the steady state: coordinates at `about:`, the other rates by `hold:`
        return _same_roots(ctx, fam, eq.subs(xdot, fam.x).subs(fam.state))
    book = [ctx.parse(v, ("book", i)) for i, v in
            enumerate(val if isinstance(val, list) else [val])]
    if "limit" in ctx.part.data:
        def error(pt) -> float:
            engine = fam.real_rates(pt)
            worst = 0.0
            for b in numbers(book, pt):
                if not engine:
                    return float("inf")
                worst = max(worst, min(abs(e - b) for e in engine) / max(abs(b), 1e-300))
            return worst
        return asymptotic(ctx, error)
    if "estimate" in ctx.part.data:  # the book's numbers: each near an engine rate
        pt = ctx.sampler.draw()
        engine = fam.real_rates(pt)
        rtol = ctx.sampler.rtol
        for b in numbers(book, pt):
            if not any(abs(e - b) <= rtol * abs(b) for e in engine):
                return Verdict(False, f"estimate(rtol {rtol:g})", f"book rate {b:.6g} is not "
                               f"within {rtol:g} of an engine rate {[f'{e:.6g}' for e in engine]}")
        if not ctx.part.data.get("partial") and len(engine) != len(book):
            return Verdict(False, f"estimate(rtol {rtol:g})", f"the engine finds "
                           f"{len(engine)} steady rates, the book lists {len(book)}")
        return Verdict(True, f"estimate(rtol {rtol:g})",
                       f"engine's steady rates {[f'{e:.6g}' for e in engine]}")
    verdicts = [all_vanish(fam.residuals_at(b), ctx.sampler) for b in book]
    verdict = combine(verdicts)
    if not verdict.ok or ctx.part.data.get("partial"):
        return verdict
    for _ in range(4):
        pt = ctx.sampler.draw()
        engine = fam.real_rates(pt)
        if len(engine) != len(book):
            return Verdict(False, "numeric", f"the engine finds {len(engine)} steady rates "
                           f"{[f'{e:.8g}' for e in engine]}, the book lists {len(book)}")
    return verdict


def _same_roots(ctx: Context, fam: SteadyFamily, eq: sp.Expr) -> Verdict:
    """The book's equation has exactly the engine's real steady rates as real roots."""
    sys = ctx.system
    free = eq.free_symbols & set(sys.q + sys.qd + sys.qdd)
    if free:  # e.g. a cyclic coordinate's value, which a steady motion leaves arbitrary
        return Verdict(False, "exact", "the equation depends on " + ", ".join(
            sorted(map(str, free))) + ", which the steady motion does not fix")
    n = seen = 0
    for _ in range(6):
        pt = ctx.sampler.draw()
        engine = fam.real_rates(pt)
        book = polynomial_roots(eq, fam.x, pt)
        n += 1
        seen += bool(engine)
        ok = len(engine) == len(book) and all(
            abs(a - b) <= ROOT_RTOL * max(1.0, abs(a)) for a, b in zip(engine, book,
                                                                       strict=True))
        if not ok:
            return Verdict(False, f"numeric({n} points)",
                           f"book's roots {[f'{b:.10g}' for b in book]}, engine's steady rates "
                           f"{[f'{e:.10g}' for e in engine]}")
    if not seen:  # two equations without real roots agree without saying anything
        return Verdict(False, f"numeric({n} points)", "no steady motion exists at any sampled "
                       "point: the check cannot discriminate (`assume:` a region where one does)")
    return Verdict(True, f"numeric({n} points, polynomial roots)")


@quantity('steady_exists',
          book='relation',
          how=('at ≥ 60 parameter points drawn widely (both outcomes must occur), the '
               'relation holds exactly where a real steady rate exists (the minimum spin '
               'of a top)'),
          keys=STEADY_KEYS)
def check_steady_exists(ctx: Context, val) -> Verdict:
    fam = family(ctx)
    cond = ctx.parse(val, ("book",), relation=True)
    wide = Sampler(ctx.sampler.base, ctx.sampler.conditions, spread=2.0, policy=ctx.policy)
    seen = {True: 0, False: 0}
    n = 0
    for _ in range(400):
        pt = wide.draw()
        exists = bool(fam.real_rates(pt))
        claim = holds(cond, pt)
        if claim != exists:
            return Verdict(False, f"numeric({n + 1} points)",
                           f"book says {'a' if claim else 'no'} steady motion, the engine "
                           f"finds {'some' if exists else 'none'} at "
                           f"{{{', '.join(f'{k}={float(v):.4g}' for k, v in pt.items())}}}")
        seen[claim] += 1
        n += 1
        if n >= 60 and min(seen.values()) >= 10:
            break
    if min(seen.values()) == 0:
        return Verdict(False, "numeric", "sampling never crossed the existence boundary; the "
                       "check cannot discriminate")
    return Verdict(True, f"numeric({n} points: {seen[True]} exist, {seen[False]} do not)")


VERDICTS = ("stable", "unstable")


@quantity('stability',
          book='`stable` or `unstable`',
          how=('the linearized motion about the equilibrium or steady motion (`about:`, '
               '`steady:`) is so at every one of 12 parameter points drawn widely (factors '
               'up to e² about the defaults; `assume:` bounds the region); no boundary '
               'crossing is needed. Points where the linearization is marginal are not '
               'counted (8 decided points needed)'),
          keys={})
def check_stability(ctx: Context, val) -> Verdict:
    if val not in VERDICTS:
        raise ctx.part.error(("book",), f"book must be one of {VERDICTS}")
    lin = ctx.linear()
    wide = Sampler(ctx.sampler.base, ctx.sampler.conditions, spread=2.0, policy=ctx.policy)
    decided = 0
    for i in range(40):
        if decided >= 12:
            break
        pt = wide.draw()
        got = lin.numeric_stability(pt)
        if got == "marginal":
            continue
        decided += 1
        if got != val:
            return Verdict(False, f"numeric({i + 1} points)",
                           f"engine finds {got} at "
                           f"{{{', '.join(f'{k}={float(v):.4g}' for k, v in pt.items())}}}")
    if decided < 8:
        return Verdict(False, "numeric", f"only {decided} points were not marginal")
    return Verdict(True, f"numeric({decided} points)")


@quantity('effective_potential',
          book="expression in the other coordinates and the held momenta `p_<q>`",
          how=("Routh's reduction: with the momenta of the `cyclic:` coordinates held, V_eff"
               " = [Σ p φ̇ − L] at rest in the other coordinates; equal to the book's up to "
               "a function of the momenta (its gradient in the coordinates agrees)"),
          keys={"cyclic": {"type": "array", "minItems": 1, "items": NAME}})
def check_effective_potential(ctx: Context, val) -> Verdict:
    names = ctx.part.data.get("cyclic") or []
    coords = []
    for i, c in enumerate(names):
        if c not in ctx.system.coord_names:
            raise ctx.part.error(("cyclic", i), f"{c!r} is not a coordinate")
        coords.append(ctx.system.q[ctx.system.coord_names.index(c)])
    momenta = [ctx.names["p_" + c] for c in names]
    engine = effective_potential(ctx.dyn, coords, momenta)
    book = ctx.parse(val, ("book",))
    rest = [q for q in ctx.system.q if q not in coords]
    stray = book.free_symbols & set(coords + ctx.system.qd)
    if stray:
        raise ctx.part.error(("book",), "an effective potential depends on the other "
                             "coordinates and the momenta only, not on "
                             + ", ".join(sorted(map(str, stray))))
    return all_vanish([sp.diff(book - engine, q) for q in rest], ctx.sampler)
