"""Where steady motions are, as answers: `steady_motion`, `steady_rates`, `steady_exists`,
`effective_potential` (mechbook.engine.steady). Their stability and counts are
mechbook.verify.quantities.stability.

A part names a family of steady motions by `about:` (the coordinates at rest, e.g. theta:
theta0), `unknown:` (the cyclic coordinate whose rate the book gives or whose existence it
states) and `hold:` (relations that fix the other cyclic rates, e.g. "psidot +
phidot*cos(theta) = omega3").
"""

from __future__ import annotations

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.identity import decide_zero
from mechbook.core.numeval import NotNumeric, evaluate_resolved
from mechbook.core.secalc import expand
from mechbook.core.words import plural
from mechbook.engine import steady
from mechbook.engine.steady import SteadyFamily, effective_potential, polynomial_roots
from mechbook.errors import UndecidedError, UnsupportedError
from mechbook.verify import boundary
from mechbook.verify.asymptotic import asymptotic
from mechbook.verify.compare import (
    DIGITS,
    Verdict,
    all_vanish,
    combine,
    symbolic_or,
    value_and_scale,
)
from mechbook.verify.context import Context, numbers
from mechbook.verify.proof import NO_PATH, Proof
from mechbook.verify.registration import ESTIMATE, LIMIT, NAME, Family
from mechbook.verify.response_proof import prove_proportional

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

HOLD = {"type": "array", "items": {"type": "string"}}
ROOT_RTOL = 1e-9
STEADY_KEYS = {"hold": HOLD, "unknown": NAME}


def coordinate_map(ctx: Context, mapping, sub) -> dict:
    mapping = ctx.as_map(mapping, sub)
    out = {}
    for k, v in mapping.items():
        if k not in ctx.system.coord_names:
            raise ctx.part.error(sub + (k,), f"{k!r} is not a coordinate")
        out[ctx.system.q[ctx.system.coord_names.index(k)]] = ctx.parse(v, sub + (k,))
    return out


@quantity('steady_motion',
          book='`{at: {q: value}, rates: {q: rate}}`',
          how=('the uniform motion q = at + rates·t (every coordinate in `at:` or `rates:`) '
               'solves the equations of motion: each residual vanishes identically (at two '
               'times, at random points; answer symbols such as an orbit radius are '
               'sampled too); with constraints, each constraint holds along it and the '
               'residual is one the constraint forces Aᵀλ can supply'))
def check_steady_motion(ctx: Context, val) -> Verdict:
    val = ctx.as_map(val, ("book",))
    point = coordinate_map(ctx, val.get("at") or {}, ("book", "at"))
    rates = coordinate_map(ctx, val.get("rates") or {}, ("book", "rates"))
    missing = [c for c, q in zip(ctx.system.coord_names, ctx.system.q, strict=True)
               if q not in point and q not in rates]
    if missing:
        raise ctx.part.error(("book",), f"give every coordinate a value (`at:`) or a rate "
                             f"(`rates:`): {', '.join(missing)} missing")
    residuals = (steady.constrained_steady_residuals if ctx.dyn.constrained
                 else steady.steady_residuals)
    return all_vanish(residuals(ctx.dyn, rates, point), ctx.sampler)


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
    return ctx.analysis.reuse(key, lambda: SteadyFamily.build(ctx.dyn, ctx.point(), unknown,
                                                               hold))


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
               'at the book\'s numbers to its precision; with `--prove`, an equation is '
               '`symbolic` where it is polynomial in the rate and proved proportional to '
               'the one condition not identically 0 (lc(B)·E = lc(E)·B, the same degree: '
               'the same roots wherever the leading coefficients do not vanish, as sin θ0 '
               'for a top)'),
          keys={**STEADY_KEYS, "partial": {"type": "boolean"}, "limit": LIMIT,
                "estimate": ESTIMATE},
          crosschecks=("steady",))
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
        return asymptotic(ctx, error, floor=1e-13)
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
                       f"engine's steady rates {[f'{e:.6g}' for e in engine]}",
                       power=f"within the stated {rtol:g}")
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
        try:
            book = polynomial_roots(eq, fam.x, pt)
        except UnsupportedError:  # not polynomial in the rate: its roots cannot be counted
            return _vanishes_at_rates(ctx, fam, eq)
        n += 1
        seen += bool(engine)
        ok = len(engine) == len(book) and all(
            abs(a - b) <= ROOT_RTOL * max(abs(a), abs(b), 1e-30) for a, b in zip(engine, book,
                                                                       strict=True))
        if not ok:
            return Verdict(False, f"numeric({plural(n, 'point')})",
                           f"book's roots {[f'{b:.10g}' for b in book]}, engine's steady rates "
                           f"{[f'{e:.10g}' for e in engine]}")
    if not seen:  # two equations without real roots agree without saying anything
        raise UndecidedError(f"no steady motion exists at any of {n} sampled points: the "
                             "check cannot discriminate (`assume:` a region where one does)")
    numeric = Verdict(True, f"numeric({plural(n, 'point')}, polynomial roots)",
                      power=f"{plural(n, 'point')}: the real roots, all of them, to "
                            f"{ROOT_RTOL:g}")
    if not ctx.policy.prove:
        return numeric
    return symbolic_or(numeric, _proved_same_roots(fam, eq, ctx.sampler),
                       "proved symbolically: the book's polynomial and the engine's condition "
                       "proportional in the rate (the same roots wherever their leading "
                       "coefficients do not vanish)")


def _proved_same_roots(fam: SteadyFamily, eq: sp.Expr, sampler) -> Proof:
    """The one condition of the family not identically 0 proved proportional to the
    book's polynomial in the rate; refused where there are several (common roots)."""
    live = [c for c in fam.conditions if not (c == 0 or decide_zero(c).zero is True)]
    if len(live) != 1:
        return Proof(False, NO_PATH + " (several conditions: their common roots)")
    num, den = sp.together(live[0]).as_numer_denom()
    if den.has(fam.x):
        return Proof(False, NO_PATH + " (the condition is not polynomial in the rate)")
    bnum, bden = sp.together(eq).as_numer_denom()
    if bden.has(fam.x):
        return Proof(False, NO_PATH + " (the equation is not polynomial in the rate)")
    return prove_proportional(bnum, num, fam.x, sampler)



def _vanishes_at_rates(ctx: Context, fam: SteadyFamily, eq: sp.Expr) -> Verdict:
    """A book equation that is not polynomial in the rate (a root, a power that is not an
    integer): it must vanish at every one of the engine's real steady rates, at 6 points.
    Its own roots cannot be counted, so a pass says it may have others."""
    n = seen = 0
    for _ in range(6):
        pt = ctx.sampler.draw()
        engine = fam.real_rates(pt)
        n += 1
        seen += bool(engine)
        for r in engine:
            v, scale = value_and_scale(eq, {**pt, fam.x: sp.Float(r, DIGITS)})
            if not abs(v) <= ROOT_RTOL * max(scale, 1e-300):
                return Verdict(False, f"numeric({plural(n, 'point')})",
                               f"the book's equation does not vanish at the engine's steady "
                               f"rate {r:.10g} (residual {abs(v):.3g} of {scale:.3g})")
    if not seen:
        raise UndecidedError(f"no steady motion exists at any of {n} sampled points: the "
                             "check cannot discriminate (`assume:` a region where one does)")
    return Verdict(True, f"numeric({plural(n, 'point')}, at the engine's rates)",
                   "the equation is not polynomial in the rate: it holds at every steady rate, "
                   "but its other roots are not counted",
                   power=f"residual ≤ {ROOT_RTOL:g} at the engine's rates "
                         f"({plural(n, 'point')}); other "
                         "roots of the book's equation not counted")


@quantity('steady_exists',
          book='relation (where a steady motion exists)',
          how=('decided at its boundary like `stability_condition` (8 random rays, 40 '
               'points each, every crossing of the relation found to 30 digits and judged '
               'a relative 1e-8 on either side): the relation holds exactly where some real '
               'rate of the `unknown:` coordinate makes the configuration `about:` (with the '
               'other cyclic rates fixed by `hold:`) a steady motion: the conditions, '
               'polynomials in the rate, have a common real root (a coefficient that cancels '
               'to 1e-20 of its terms counts as zero; the roots are checked on every '
               'condition). The minimum spin of a top, the region where circular orbits '
               'exist'),
          keys=STEADY_KEYS,
          crosschecks=("steady",))
def check_steady_exists(ctx: Context, val) -> Verdict:
    fam = family(ctx)
    cond = ctx.parse(val, ("book",), relation=True)
    # the family kept beside its coefficients: its id is not reused while the analysis lives
    coefficients = ctx.analysis.reuse(("steady-coefficients", id(fam)),
                                      lambda: (fam, _coefficients(ctx, fam)))[1]
    result = boundary.compare(cond, lambda pt, near: _common_real_root(coefficients, pt, near),
                              ctx.sampler, ("a steady motion", "none"))
    return boundary.verdict(result)


def _coefficients(ctx: Context, fam: SteadyFamily) -> list[list]:
    """Each condition of the family as a polynomial in its rate x: the coefficient lists
    (highest first) of the numerators."""
    out = []
    for c in fam.conditions:
        if c == 0:
            continue
        try:
            poly = _poly(c, fam.x)
        except sp.PolynomialError:
            poly = None
        if poly is None or any(a.has(fam.x) for a in poly.all_coeffs()):
            num = sp.together(c).as_numer_denom()[0]
            try:
                poly = _poly(num, fam.x)
            except sp.PolynomialError:
                raise ctx.part.error(("unknown",), "the steady conditions are not "
                                     "polynomial in the rate") from None
        out.append(poly.all_coeffs())
    return out


def _poly(e: sp.Expr, x: sp.Symbol) -> sp.Poly:
    """e as a polynomial in x alone: expanded by SymEngine (SymPy where it cannot), its
    terms collected by powers of x over SymPy's expression domain. Why: building the
    polynomial ring of the coefficients' many symbols, as Poly does by default, was most of
    the time (symon-12-22: 0.82 -> 0.13 s, the same coefficients)."""
    return sp.Poly(expand(e), x, domain=sp.EX)


def _common_real_root(coefficients: list[list], pt: dict, precise: bool = False) -> bool:
    """Do the polynomials (coefficient lists, highest first) have a common real root at
    `pt`? A coefficient counts as zero when it cancels to 1e-20 of its terms. A root is real
    when its imaginary part is below 1e-9 of its own size (not of 1: near an existence
    boundary at infinity the rates themselves are tiny, and ±1e-16i is not real). `precise`
    (close to a boundary): each coefficient evaluated with its precision raised until it
    stands clear of what cancels in it, the roots in mpmath, real below 1e-20 of their
    size."""
    polys = []
    for coeffs in coefficients:
        vals = []
        for c in coeffs:
            if precise:  # precision raised until the coefficient stands clear of rounding
                try:
                    vals.append(mpmath.re(evaluate_resolved(c, pt, DIGITS)))
                    continue
                except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError):
                    pass
                v, size = value_and_scale(c, pt)
                vals.append(mpmath.mpf(0) if abs(v) <= 1e-20 * max(size, 1e-300)
                            else mpmath.mpf(v.real))
            else:
                v, size = value_and_scale(c, pt)
                vals.append(0.0 if abs(v) <= 1e-20 * max(size, 1e-300) else v.real)
        while vals and vals[0] == 0:
            vals.pop(0)
        if not vals:
            continue  # vanishes identically here
        if len(vals) == 1:
            return False  # a nonzero constant: no rate makes this residual vanish
        polys.append(vals)
    if not polys:
        return True
    if precise:
        return _common_real_root_mp(polys)
    polys = [np.array([float(v) for v in c]) for c in polys]
    roots = [r.real for r in np.roots(polys[0]) if abs(r.imag) <= 1e-9 * abs(r)]
    for r in roots:
        if all(abs(np.polyval(c, r)) <= 1e-9 * np.polyval(np.abs(c), abs(r)) for c in polys):
            return True
    return False


def _common_real_root_mp(polys: list[list]) -> bool:
    with mpmath.workdps(DIGITS + 10):
        first = list(polys[0])
        zeros = 0
        while first and first[-1] == 0:  # x = 0 is an exact root
            first.pop()
            zeros += 1
        roots = [mpmath.mpf(0)] if zeros else []
        if len(first) > 1:
            try:
                found = mpmath.polyroots(first, maxsteps=200, extraprec=2 * DIGITS)
            except mpmath.libmp.NoConvergence:
                found = mpmath.polyroots(first, maxsteps=2000, extraprec=4 * DIGITS,
                                         error=False)
            roots += [mpmath.re(r) for r in (found if isinstance(found, list) else [found])
                      if abs(mpmath.im(r)) <= mpmath.mpf(10) ** -20 * abs(r)]
        for r in roots:
            if all(abs(mpmath.polyval(c, r)) <= mpmath.mpf(10) ** -20 *
                   mpmath.polyval([abs(x) for x in c], abs(r)) for c in polys):
                return True
    return False


@quantity('effective_potential',
          book="expression in the other coordinates and the held momenta `p_<q>`",
          how=("Routh's reduction: with the momenta of the `cyclic:` coordinates held, V_eff"
               " = [Σ p φ̇ − L] at rest in the other coordinates; equal to the book's up to "
               "a function of the momenta (its gradient in the coordinates agrees)"),
          keys={"cyclic": {"type": "array", "minItems": 1, "items": NAME}},
          equivalent=("shift",))
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
