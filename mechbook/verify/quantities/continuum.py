"""A continuous field's quantities (`field:`): `field_equation`, `field_frequencies`,
`field_mode`, `field_current`.

The book's expressions use the field's jet names (u, u_t, u_tt, u_x, u_xxxx, u_r, u_theta,
…; mechbook.model.continuum), the coordinates and the parameters.
"""

from __future__ import annotations

import mpmath as mp
import sympy as sp

from mechbook.engine.continuum import (
    edge_conditions,
    field_equation,
    squared_frequencies,
    total_derivative,
)
from mechbook.errors import UnsupportedError
from mechbook.model.continuum import FieldModel
from mechbook.verify.compare import EXACT_RTOL, RTOL, Verdict, equal, vanishes
from mechbook.verify.context import Context
from mechbook.verify.registration import ESTIMATE, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

POINTS = 3  # parameter points at which the frequencies are compared
DIGITS = 30


def _field(ctx: Context) -> FieldModel:
    model = ctx.analysis.built.field()
    if model is None:
        raise ctx.part.error(("quantity",), f"{ctx.part.quantity!r} needs a `field:` "
                             "(a Lagrangian density); this problem has none")
    return model


def field_names(ctx: Context) -> dict:
    """The part's names with the field's: its jet, the coordinates and t."""
    names = dict(ctx.names)
    names.update(_field(ctx).names)
    return names


def _jet_point(model: FieldModel, rng, extra: set) -> dict:
    return {s: sp.Float(rng.uniform(-1, 1), DIGITS) for s in extra}


@quantity('field_equation',
          book='equation in the jet names (`rho*u_tt = tau*u_xx`)',
          how=("Euler–Lagrange's equation of the density (Σ(−D)^α ∂ℒ/∂u_α, of ℒ·r in polar "
               "coordinates): the book's E_b and the engine's E are proportional, "
               "E_b = c·E with c fixed (by the parameters only) at one random jet point and "
               "the identity E_b = c·E then holding at 6 random points of parameters, jet "
               "and coordinates in 30 digits (a nonzero c required)"),
          names=field_names, needs_system=False)
def check_field_equation(ctx: Context, val) -> Verdict:
    """The book's PDE is the engine's Euler–Lagrange equation times a constant factor."""
    model = _field(ctx)
    book = ctx.parse(val, ("book",), equation=True, names=field_names(ctx))
    if ctx.validate_only:
        return Verdict(True, "validated")
    engine = field_equation(model)
    params = set(ctx.sampler.base)
    extra = (book.free_symbols | engine.free_symbols) - params
    pt = ctx.sampler.draw()
    for _ in range(5):  # a reference point where the engine's E is not zero
        ref = _jet_point(model, ctx.sampler.rng, extra)
        if sp.N(engine.xreplace(ref).xreplace(pt), DIGITS) != 0:
            break
    else:
        raise UnsupportedError("a field equation that vanishes identically")
    factor = book.xreplace(ref) / engine.xreplace(ref)
    if sp.N(factor.xreplace(pt), DIGITS) == 0:
        return Verdict(False, "numeric", f"the book's equation vanishes where the engine's "
                       f"{sp.sstr(engine)} = 0 does not")
    got = equal(book, factor * engine, ctx.sampler)
    if not got.ok:
        got.detail = f"not proportional to the engine's {sp.sstr(engine)} = 0: {got.detail}"
    return got


def _book_values(ctx: Context, val) -> list:
    return [ctx.parse(v, ("book", i)) for i, v in enumerate(ctx.as_list(val, ("book",)))]


@quantity('field_frequencies',
          book='list of ω: the lowest ones in order, a degenerate one repeated '
               '(`partial: true`: each among the lowest 2N + 8)',
          how=('by separation at 3 random parameter points, in 30 digits: a segment\'s '
               'roots of the boundary determinant on the mode ODE\'s transfer matrix '
               '(mpmath findroot, bracketed by the Chebyshev discretization), a '
               'rectangle\'s sums of the two segments\' λ, a disk\'s zeros of J_n or J_n′, '
               'an annulus\'s of the cross product of J_n and Y_n (n ≥ 1 twice: cos, sin); '
               'each book value within 1e-20 relative (numbers below 30 digits in the key: '
               '1e-10; `estimate:` its rtol); the spectral cross-check vouches'),
          keys={"partial": {"type": "boolean"}, "estimate": ESTIMATE},
          names=field_names, needs_system=False, crosschecks=("spectral",))
def check_field_frequencies(ctx: Context, val) -> Verdict:
    """The book's frequencies are the field's lowest normal frequencies (with multiplicity)."""
    model = _field(ctx)
    book = _book_values(ctx, val)
    if ctx.validate_only:
        return Verdict(True, "validated")
    partial = bool(ctx.part.data.get("partial"))
    count = 2 * len(book) + 8 if partial else len(book)
    numbers = any(f._prec < 90 for b in book for f in b.atoms(sp.Float))
    rtol = ctx.sampler.rtol if (ctx.sampler.rtol > RTOL or numbers) else EXACT_RTOL
    fixed = "estimate" in ctx.part.data
    worst = 0.0
    for k in range(1 if fixed else POINTS):
        pt = ctx.sampler.default() if k == 0 else ctx.sampler.draw()
        with mp.workdps(DIGITS):
            engine = [mp.sqrt(x) for x in squared_frequencies(model, pt, count)]
            if len(engine) < count:
                raise UnsupportedError(f"only {len(engine)} of the {count} lowest "
                                       "frequencies found")
            values = [mp.mpf(str(sp.N(b.xreplace(pt), DIGITS + 5))) for b in book]
            free = list(engine)
            scale0 = max(abs(e) for e in engine) * mp.mpf("1e-3")
            for i, b in enumerate(values if partial else sorted(values)):
                j = (min(range(len(free)), key=lambda j: abs(free[j] - b)) if partial
                     else i)
                rel = abs(free[j] - b) / max(abs(b), scale0)
                if rel > rtol:
                    shown = ", ".join(mp.nstr(e, 12) for e in engine)
                    return Verdict(False, f"numeric({k + 1} points)",
                                   f"book value {mp.nstr(b, 15)} is not "
                                   f"{'among' if partial else f'#{i + 1} of'} the field's "
                                   f"lowest frequencies [{shown}] (relative "
                                   f"{mp.nstr(rel, 3)})")
                worst = max(worst, float(rel))
                if partial:
                    free.pop(j)
    return Verdict(True, f"numeric({1 if fixed else POINTS} points, rtol {rtol:g})",
                   f"worst relative {worst:.2g}",
                   power=f"each frequency within {rtol:g} at {1 if fixed else POINTS} "
                         "parameter points, 30 digits")


def on_shell(model: FieldModel, expr: sp.Expr) -> sp.Expr:
    """u_tt and its space derivatives replaced by the field equation's (E linear in u_tt)."""
    eq = field_equation(model)
    dims = len(model.coords)
    utt = model.jet(tuple([2] + [0] * dims))
    coeff = sp.expand(eq).coeff(utt)
    if coeff == 0 or coeff.has(utt):
        raise UnsupportedError("a current of a field equation that does not give u_tt")
    solution = sp.expand(-(eq - coeff * utt) / coeff)
    sub = {}
    for orders, sym in list(model.jets.items()):
        if orders[0] >= 2 and expr.has(sym):
            if orders[0] > 2:
                raise UnsupportedError("a current whose time derivative needs u_ttt (a "
                                       "density with u_tt)")
            val = solution
            for axis, k in enumerate(orders[1:]):
                for _ in range(k):
                    val = total_derivative(model, val, axis + 1)
            sub[sym] = val
    return expr.xreplace(sub)


@quantity('field_current',
          book='`{density: ρ, flux: [j_1, j_2]}`: a conserved current of the field',
          how=('∂_t ρ + ∇·j (total derivatives; in polar coordinates (1/r)∂_r(r·j_r) + '
               '(1/r)∂_θ j_θ) with u_tt and its derivatives from the field equation '
               'vanishes at 6 random points of parameters, jet and coordinates in 30 digits '
               '(1e-20 of the terms that cancel); ρ = 0 is refused. `noether: t` (or a '
               'coordinate) also requires ρ = ±(the canonical density of that '
               'translation: u_t·∂ℒ/∂u_t − ℒ for t, u_s·∂ℒ/∂u_t for a coordinate s)'),
          keys={"noether": {"type": "string"}}, names=field_names, needs_system=False)
def check_field_current(ctx: Context, val) -> Verdict:
    """The book's (ρ, j) satisfies the continuity equation on the field's solutions."""
    model = _field(ctx)
    names = field_names(ctx)
    val = ctx.as_map(val, ("book",))
    if "density" not in val or "flux" not in val:
        raise ctx.part.error(("book",), "a current gives `density:` and `flux:`")
    rho = ctx.parse(val["density"], ("book", "density"), names=names)
    flux = [ctx.parse(f, ("book", "flux", i), names=names)
            for i, f in enumerate(ctx.as_list(val["flux"], ("book", "flux")))]
    if len(flux) != len(model.coords):
        raise ctx.part.error(("book", "flux"), f"give {len(model.coords)} flux components "
                             f"(along {', '.join(model.coord_names)})")
    which = ctx.part.data.get("noether")
    if which is not None and which not in ("t", *model.coord_names):
        raise ctx.part.error(("noether",), f"a translation in t or "
                             f"{' or '.join(model.coord_names)}")
    if ctx.validate_only:
        return Verdict(True, "validated")
    if rho == 0:
        return Verdict(False, "symbolic", "a zero density conserves nothing")
    if model.polar:
        r = model.coords[0]
        div = (total_derivative(model, r * flux[0], 1) + total_derivative(model, flux[1], 2)) / r
    else:
        div = sum((total_derivative(model, j, i + 1) for i, j in enumerate(flux)), sp.S.Zero)
    residual = on_shell(model, total_derivative(model, rho, 0) + div)
    got = vanishes(sp.expand(residual), ctx.sampler)
    if not got.ok:
        got.detail = f"∂_t ρ + ∇·j ≠ 0 on the field's solutions: {got.detail}"
        return got
    if which is None:
        return got
    dims = len(model.coords)
    ut = model.jet(tuple([1] + [0] * dims))
    p = sp.diff(model.density, ut)
    if which == "t":
        canonical = ut * p - model.density
    else:
        axis = model.coord_names.index(which)
        canonical = model.jet(tuple([0] + [1 if i == axis else 0 for i in range(dims)])) * p
    plus = equal(rho, canonical, ctx.sampler)
    if plus.ok:
        return plus
    minus = equal(rho, -canonical, ctx.sampler)
    if minus.ok:
        return minus
    return Verdict(False, plus.method, f"ρ is not ±{sp.sstr(canonical)}, the canonical "
                   f"density of the translation in {which}: {plus.detail}")


def mode_jets(model: FieldModel, shape: sp.Expr, omega: sp.Expr) -> dict:
    """The jet of u = φ·cos(ωt) at t = 0: ∂_t^a ∂^β u = (−ω²)^(a/2)·∂^β φ for even a, 0
    for odd a."""
    sub = {}
    for orders, sym in list(model.jets.items()):
        if orders[0] % 2:
            sub[sym] = sp.S.Zero
            continue
        d = shape
        for c, k in zip(model.coords, orders[1:], strict=True):
            if k:
                d = sp.diff(d, c, k)
        sub[sym] = (-omega**2) ** (orders[0] // 2) * d
    return sub


@quantity('field_mode',
          book='`{frequency: ω, shape: φ}`: a normal mode u = φ(coordinates)·cos ωt',
          how=('the field equation with u = φ·cos ωt vanishes identically in the coordinates '
               '(6 random points of coordinates and parameters, 30 digits, 1e-20 of what '
               'cancels), each edge\'s conditions vanish on the edge (6 points each), φ is '
               'not zero and ω ≥ 0 (3 points); a shape the coordinates\' functions cannot '
               'write (a Bessel function on main) is not checkable this way'),
          names=field_names, needs_system=False)
def check_field_mode(ctx: Context, val) -> Verdict:
    """The book's (ω, φ) solves the field equation and the boundary conditions."""
    model = _field(ctx)
    names = field_names(ctx)
    val = ctx.as_map(val, ("book",))
    if "frequency" not in val or "shape" not in val:
        raise ctx.part.error(("book",), "a mode gives `frequency:` and `shape:`")
    omega = ctx.parse(val["frequency"], ("book", "frequency"), names=names)
    shape = ctx.parse(val["shape"], ("book", "shape"), names=names)
    jets = set(model.jets.values()) | {model.names["t"]}
    for key, expr in (("frequency", omega), ("shape", shape)):
        if expr.free_symbols & jets or (key == "frequency" and expr.free_symbols
                                        & set(model.coords)):
            raise ctx.part.error(("book", key), "a mode's frequency is a constant and its "
                                 "shape a function of the coordinates, without the field's "
                                 "derivatives or t")
    if ctx.validate_only:
        return Verdict(True, "validated")
    if shape == 0 or vanishes(shape, ctx.sampler, symbolic=False).ok:
        return Verdict(False, "numeric", "the shape is zero: no mode")
    for _ in range(3):  # ω² alone enters the equations: the sign is the book's claim
        pt = ctx.sampler.draw()
        w = sp.N(omega.xreplace(pt), DIGITS)
        if not w.is_real or w < 0:
            return Verdict(False, "numeric", f"the frequency {sp.sstr(omega)} is {w}, not a "
                           "nonnegative number, here")
    sub = mode_jets(model, shape, omega)
    got = vanishes(sp.expand(field_equation(model).xreplace(sub)), ctx.sampler)
    if not got.ok:
        got.detail = f"φ·cos ωt does not solve the field equation: {got.detail}"
        return got
    for edge in model.edges:
        for cond in edge_conditions(model, edge):
            on_edge = cond.xreplace(sub).xreplace({model.coords[edge.axis]: edge.at})
            edge_got = vanishes(sp.expand(on_edge), ctx.sampler)
            if not edge_got.ok:
                edge_got.detail = (f"the condition {sp.sstr(cond)} = 0 fails on the edge "
                                   f"{edge.name}: {edge_got.detail}")
                return edge_got
    return got
