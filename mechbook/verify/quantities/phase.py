"""Phase-space flows (Liouville): `phase_area` and `phase_region`.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.core.compile import compile_batch
from mechbook.core.words import plural
from mechbook.engine.phase import (
    PhaseFlow,  # scipy's integrator, only when a phase part is checked
    image_area,
    image_bounds,
    in_box,
)
from mechbook.errors import UndecidedError, UnsupportedError
from mechbook.verify import boundary
from mechbook.verify.compare import Sampler, Verdict, value
from mechbook.verify.context import Context, numbers
from mechbook.verify.registration import EXPR, REGION, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

PHASE_RTOL = 1e-8  # agreement required of a phase area
PHASE_POINTS = 3  # parameter points per phase-space check
REGION_SAMPLES = 2000  # phase points per parameter point in a region check
REGION_MARGIN = 1e-6  # points this close (relative) to a boundary are not judged


def _phase_box(ctx: Context):
    """The part's initial box (`region:` {q or p_q: [low, high]}, every coordinate and
    momentum) and its time (`time:`), as parsed expressions, in the order q…, p…."""
    names = list(ctx.system.coord_names) + ["p_" + c for c in ctx.system.coord_names]
    region = ctx.as_map(ctx.part.data.get("region"), ("region",))
    for k in region:
        if k not in names:
            raise ctx.part.error(("region", k), f"{k!r} is neither a coordinate nor a momentum "
                                 f"(have {', '.join(names)})")
    missing = [k for k in names if k not in region]
    if missing:
        raise ctx.part.error(("region",), "the initial box gives every coordinate and "
                             "momentum a range; missing " + ", ".join(missing))
    if "time" not in ctx.part.data:
        raise ctx.part.error(("time",), "a phase-space part names the elapsed time with 'time:'")
    state = set(ctx.system.q + ctx.system.qd + ctx.dyn.p) | {ctx.system.t}
    bounds = []
    for k in names:
        pair = ctx.as_list(region[k], ("region", k))
        if len(pair) != 2:
            raise ctx.part.error(("region", k), "a range is [low, high]")
        bounds.append([ctx.parse(v, ("region", k, i)) for i, v in enumerate(pair)])
    time = ctx.parse(ctx.part.data["time"], ("time",))
    for e, sub in [(time, ("time",))] + [(b, ("region", k)) for k, pair in zip(names, bounds,
                                                                             strict=True)
                                         for b in pair]:
        if e.free_symbols & state:
            raise ctx.part.error(sub, "the initial box and the time are constants (no "
                                 "coordinates, momenta or t)")
    return names, bounds, time


def _phasenumbers(ctx: Context, bounds, time, pt) -> tuple[np.ndarray, np.ndarray, float]:
    lo = np.array(numbers([b[0] for b in bounds], pt))
    hi = np.array(numbers([b[1] for b in bounds], pt))
    tv = numbers([time], pt)[0]
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo < hi)
            and np.isfinite(tv)):
        raise ctx.part.error(("region",), f"the box is empty or not real at {pt}")
    return lo, hi, tv


def _flow(ctx: Context):

    return PhaseFlow(ctx.system, ctx.dyn)


def _fmt_point(pt: dict) -> str:
    return "{" + ", ".join(f"{k}={float(v):.6g}" for k, v in
                           sorted(pt.items(), key=lambda kv: str(kv[0]))) + "}"


@quantity('phase_area',
          book='expression (may use `t`)',
          how=('the area (one degree of freedom) of the image at `time:` of the initial '
               "box `region:` under the engine's flow in (q, p), measured (see below)"),
          keys={"region": REGION,
                "time": EXPR})
def check_phase_area(ctx: Context, val) -> Verdict:
    """Area (one degree of freedom) of the image at `time:` of the `region:` box under the
    engine's flow in (q, p). Valid because the engine's side is a direct computation from
    the equations of motion alone: the box boundary is carried by the integrated flow
    (DOP853, rtol 1e-12, p ↔ q̇ through the engine's momenta) and the enclosed area is the
    shoelace sum, Romberg-extrapolated in the number of boundary points; no Liouville
    theorem is assumed, so a damped system's shrinking area is measured, not presumed.
    Compared at 3 parameter points to rtol 1e-8."""
    if len(ctx.system.q) != 1:
        raise UnsupportedError("phase-space area of more than one degree of freedom")

    book = ctx.parse(val, ("book",))
    _, bounds, time = _phase_box(ctx)
    flow = _flow(ctx)
    worst = 0.0
    for k in range(PHASE_POINTS):
        pt = ctx.sampler.draw()
        lo, hi, tv = _phasenumbers(ctx, bounds, time, pt)
        area, _ = image_area(flow, pt, lo, hi, tv)
        env = dict(pt)
        env[ctx.system.t] = sp.Float(tv, 30)
        b = value(book, env)
        rel = abs(b - area) / max(abs(area), 1e-300)
        if not (np.isfinite(rel) and abs(b.imag) <= 1e-12 * abs(b)) or rel > PHASE_RTOL:
            return Verdict(False, f"numeric({plural(k + 1, 'point')})",
                           f"book area {b.real:.12g}, image of the box {area:.12g} at t = "
                           f"{tv:.6g}, {_fmt_point(pt)}")
        worst = max(worst, rel)
    return Verdict(True, f"numeric({PHASE_POINTS} points, flow DOP853 rtol 1e-12, "
                   f"rtol {PHASE_RTOL:g})", f"worst relative {worst:.2g}",
                   power=f"{PHASE_POINTS} points: the image's area to {PHASE_RTOL:g}")



def _truth(expr, env: dict, n_points: int):
    """Truth of a condition at many points (arrays in env) and whether any of its
    comparisons is within REGION_MARGIN (relative) of equality there."""
    if expr is sp.true or expr is sp.false:
        return np.full(n_points, bool(expr)), np.zeros(n_points, bool)
    if isinstance(expr, (sp.And, sp.Or)):
        parts = [_truth(a, env, n_points) for a in expr.args]
        truth = np.all if isinstance(expr, sp.And) else np.any
        return truth([p[0] for p in parts], axis=0), np.any([p[1] for p in parts], axis=0)
    if isinstance(expr, sp.Not):
        inner, near = _truth(expr.args[0], env, n_points)
        return ~inner, near
    if not isinstance(expr, sp.core.relational.Relational) or isinstance(expr, sp.Eq):
        raise ValueError(f"not an inequality: {expr}")
    X = np.column_stack([np.broadcast_to(np.asarray(v, float), (n_points,))
                         for v in env.values()])
    lhs, rhs = compile_batch(list(env), [expr.lhs, expr.rhs])(X).T
    ops = {"<": np.less, "<=": np.less_equal, ">": np.greater, ">=": np.greater_equal,
           "!=": np.not_equal}
    truth = ops[expr.rel_op](lhs, rhs)
    near = ~np.isfinite(lhs - rhs) | (np.abs(lhs - rhs) <= REGION_MARGIN *
                                      np.maximum(np.abs(lhs), np.abs(rhs)))
    return truth, near


@quantity('phase_region',
          book='list of inequalities in the coordinates, momenta `p_<q>` and `t`',
          how=('a point X satisfies them at `time:` exactly when the flow carried back, '
               'Φ₋ₜ(X), lies in the initial box `region:` (see below)'),
          keys={"region": REGION,
                "time": EXPR})
def check_phase_region(ctx: Context, val) -> Verdict:
    """The region of phase space the `region:` box occupies at `time:`, given as inequalities
    in the coordinates, momenta p_<q> and t. Valid because membership is decided pointwise
    without any formula for the image: a point X is in Φ_t(box) iff the engine's flow
    carried back, Φ_{-t}(X), lies in the box. At 3 parameter points, 2000 points drawn in a
    box covering the initial box and the image's bounding box (enlarged by a quarter on each
    side) must get the same verdict from the book's inequalities and from the flow; points
    within 1e-6 (relative) of either boundary are not judged. Any disagreement fails."""

    items = ctx.as_list(val, ("book",))
    conds = [ctx.parse(v, ("book", i), relation=True) for i, v in enumerate(items)]
    variables = ctx.system.q + ctx.dyn.p
    if not any(c.free_symbols & set(variables) for c in conds):
        raise ctx.part.error(("book",), "a region is given by inequalities in the "
                             "coordinates and momenta")
    names, bounds, time = _phase_box(ctx)
    flow = _flow(ctx)
    n = len(ctx.system.q)
    rng = np.random.default_rng(20261123)
    inside = judged = 0
    for k in range(PHASE_POINTS):
        pt = ctx.sampler.draw()
        lo, hi, tv = _phasenumbers(ctx, bounds, time, pt)
        ilo, ihi = image_bounds(flow, pt, lo, hi, tv)
        clo, chi = np.minimum(lo, ilo), np.maximum(hi, ihi)
        clo, chi = clo - (chi - clo) / 4, chi + (chi - clo) / 4
        X = clo + (chi - clo) * rng.uniform(size=(REGION_SAMPLES, 2 * n))
        X0q, X0p = flow.map(pt, X[:, :n], X[:, n:], 0.0, tv)
        X0 = np.column_stack((X0q, X0p))
        truth, near = in_box(X0, lo, hi, REGION_MARGIN)
        env = {ctx.system.t: sp.Float(tv, 30), **pt}
        env_arrays = {v: X[:, i] for i, v in enumerate(variables)}
        claim = np.ones(REGION_SAMPLES, bool)
        for i, c in enumerate(conds):
            try:
                ok, close = _truth(c.subs(env), env_arrays, REGION_SAMPLES)
            except ValueError as exc:
                raise ctx.part.error(("book", i), str(exc)) from None
            claim &= ok
            near |= close
        judge = ~near
        wrong = np.flatnonzero(judge & (claim != truth))
        if wrong.size:
            j = wrong[0]
            where = ", ".join(f"{nm}={x:.8g}" for nm, x in zip(names, X[j], strict=True))
            back = ", ".join(f"{x:.8g}" for x in X0[j])
            return Verdict(False, f"numeric({plural(k + 1, 'point')})",
                           f"at {where}, t={tv:.6g}: the book puts the point "
                           f"{'inside' if claim[j] else 'outside'} the region, but the flow "
                           f"carries it back to ({back}), {'inside' if truth[j] else 'outside'}"
                           f" the initial box ({wrong.size} of "
                           f"{plural(judge.sum(), 'point')} disagree; "
                           f"{_fmt_point(pt)})")
        inside += int(np.sum(judge & truth))
        judged += int(np.sum(judge))
    if inside == 0 or inside == judged:
        raise UndecidedError(f"the {judged} sampled points never straddle the region's "
                             "boundary (all agreeing): the check cannot discriminate")
    edge = _region_boundary(ctx, conds, variables, bounds, time, flow)
    if not edge.ok:
        return Verdict(False, "boundary", edge.detail)
    return Verdict(True, f"numeric({PHASE_POINTS} points x {REGION_SAMPLES} phase points, "
                   "flow DOP853 rtol 1e-12) and boundary",
                   f"{inside} of {judged} judged points inside; {edge.detail}",
                   power=f"{judged} phase points away from the boundary; "
                         f"{edge.power}")


def _region_boundary(ctx: Context, conds: list, variables: list, bounds, time, flow
                     ) -> Verdict:
    """The book's region decided at its boundary (mechbook.verify.boundary) at one parameter
    point: rays through phase space, in units of the region's size, cross the book's
    inequalities; just inside and just outside each crossing (1e-8 of the size) the flow
    carried back must land inside and outside the initial box. Random points judge only
    away from the boundary (1e-6), so a region moved by less would pass them."""

    pt = ctx.sampler.draw()
    lo, hi, tv = _phasenumbers(ctx, bounds, time, pt)
    ilo, ihi = image_bounds(flow, pt, lo, hi, tv)
    clo, chi = np.minimum(lo, ilo), np.maximum(hi, ihi)
    n = len(ctx.system.q)
    params = {k: v for k, v in pt.items() if k not in variables}
    centre = {v: sp.Float((a + b) / 2, 30) for v, a, b in zip(variables, clo, chi, strict=True)}
    scales = {v: float((b - a) / 2) for v, a, b in zip(variables, clo, chi, strict=True)}
    space = Sampler({**params, **centre}, fixed=list(params))
    rng = np.random.default_rng(20261126)

    def origin() -> dict:
        return {**params, **{v: sp.Float(rng.uniform(a, b), 30)
                             for v, a, b in zip(variables, clo, chi, strict=True)}}

    def inside(point: dict, near: bool) -> bool | None:
        X = np.array([[float(point[v]) for v in variables]])
        try:
            q0, p0 = flow.map(params, X[:, :n], X[:, n:], 0.0, tv)
        except UnsupportedError:
            return None
        got, close = in_box(np.column_stack((q0, p0)), lo, hi,
                            1e-11 if near else REGION_MARGIN)
        return None if close[0] else bool(got[0])

    cond = sp.And(*[c.subs(ctx.system.t, sp.Float(tv, 30)) for c in conds])
    result = boundary.compare(cond, inside, space, ("inside", "outside"), scales=scales,
                              rays=4, grid=24, origins=origin)
    return boundary.verdict(result)
