"""Steady motions and their stability: `steady_motion`, `stability`, `equilibrium_count`,
`secular_growth` (the engine's side is mechbook.engine.steady and .response).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.core.numeval import holds
from mechbook.engine import response, steady
from mechbook.verify.compare import Verdict, all_vanish, value, value_and_scale
from mechbook.verify.context import Context
from mechbook.verify.quantities.equilibria import check_stability_condition
from mechbook.verify.registry import EXPR, POINT, REGION, quantity


def _coordinate_map(ctx: Context, mapping, sub) -> dict:
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
               'sampled too)'))
def check_steady_motion(ctx: Context, val) -> Verdict:
    val = ctx.as_map(val, ("book",))
    point = _coordinate_map(ctx, val.get("at") or {}, ("book", "at"))
    rates = _coordinate_map(ctx, val.get("rates") or {}, ("book", "rates"))
    missing = [c for c, q in zip(ctx.system.coord_names, ctx.system.q, strict=True)
               if q not in point and q not in rates]
    if missing:
        raise ctx.part.error(("book",), f"give every coordinate a value (`at:`) or a rate "
                             f"(`rates:`): {', '.join(missing)} missing")
    return all_vanish(steady.steady_residuals(ctx.dyn, rates, point), ctx.sampler)


@quantity('stability',
          book='stable, unstable or marginal (or a relation: stable exactly where it holds)',
          how=('the linearized system about the part\'s point or steady motion has that '
               'verdict at every one of ≥ 60 parameter points drawn widely (spread x4, '
               '`assume:` honoured): "always stable / always unstable" claims'),
          literals=("stable", "unstable", "marginal"))
def check_stability(ctx: Context, val) -> Verdict:
    if isinstance(val, str) and ("<" in val or ">" in val):  # a condition after all
        return check_stability_condition(ctx, val)
    if val not in ("stable", "unstable", "marginal"):
        raise ctx.part.error(("book",), "expected stable, unstable or marginal (or a "
                             "relation: where it is stable)")
    lin = ctx.linear()
    wide = ctx.sampler.widened(2.0)
    seen: dict[str, int] = {}
    for n in range(60):
        pt = wide.draw()
        got = steady.classify(lin, pt)
        seen[got] = seen.get(got, 0) + 1
        if got != val:
            shown = ", ".join(f"{k}={float(v):.4g}" for k, v in sorted(
                pt.items(), key=lambda kv: kv[0].name)[:8])
            return Verdict(False, f"numeric({n + 1} points)",
                           f"engine finds it {got} at {{{shown}}}")
    return Verdict(True, f"numeric(60 points, all {val})")


def _boxes(ctx: Context, pt: dict, unknowns: list) -> list[dict]:
    region = ctx.part.data.get("search")
    boxes = region if isinstance(region, list) else [region]
    out = []
    for i, box in enumerate(boxes):
        sub = ("search", i) if isinstance(region, list) else ("search",)
        box = ctx.as_map(box, sub)
        parsed = {}
        for k, (lo, hi) in box.items():
            if k not in ctx.system.coord_names:
                raise ctx.part.error(sub + (k,), f"{k!r} is not a coordinate")
            q = ctx.system.q[ctx.system.coord_names.index(k)]
            if q not in unknowns:
                raise ctx.part.error(sub + (k,), f"{k!r} turns at a fixed rate or momentum "
                                     "here; the region is over the other coordinates")
            parsed[q] = tuple(value(ctx.parse(x, sub + (k, j)), pt).real
                              for j, x in enumerate((lo, hi)))
        out.append(parsed)
    return out


@quantity('equilibrium_count',
          book='integer',
          how=('the number of distinct equilibria, or steady motions at fixed `rates:` or at '
               'fixed cyclic `momenta:` (equilibria of Routh\'s reduced system), inside '
               '`search:` (a box or a list of boxes over the other coordinates), found by '
               'multistart root finding at 3 points (a count the search can miss is a lower '
               'bound: say so in the note); `stable: true/false` also checks each one\'s '
               'stability'),
          keys={"search": {"oneOf": [REGION, {"type": "array", "minItems": 1,
                                               "items": REGION}]},
                "rates": POINT, "momenta": POINT, "stable": {"type": "boolean"}})
def check_equilibrium_count(ctx: Context, val) -> Verdict:
    if not isinstance(val, int) or isinstance(val, bool):
        raise ctx.part.error(("book",), "expected an integer")
    if "search" not in ctx.part.data:
        raise ctx.part.error((), "a count needs `search:` (the region to count in)")
    rates = _coordinate_map(ctx, ctx.part.data.get("rates") or {}, ("rates",))
    momenta = _coordinate_map(ctx, ctx.part.data.get("momenta") or {}, ("momenta",))
    if rates and momenta:
        raise ctx.part.error(("momenta",), "fix either rates or momenta")
    conds, unknowns, eq = steady.steady_conditions(ctx.system, rates, momenta)
    want = ctx.part.data.get("stable")
    counts = []
    for _ in range(3):
        pt = ctx.sampler.draw()
        roots = steady.roots_in(conds, unknowns, pt, _boxes(ctx, pt, unknowns))
        counts.append(len(roots))
        where = "; ".join("(" + ", ".join(f"{x:.5g}" for x in r) + ")" for r in roots[:6])
        if len(roots) != val:
            return Verdict(False, "numeric(root search)",
                           f"found {len(roots)} in the region: {where}")
        if want is not None:
            for r in roots:
                got = steady.classify_at(eq, dict(zip(unknowns, r, strict=True)), pt, rates)
                if (got == "stable") != want:
                    at = ", ".join(f"{x:.5g}" for x in r)
                    return Verdict(False, "numeric(root search)", f"the one at ({at}) is {got}")
    how = "" if want is None else f", each {'stable' if want else 'unstable'}"
    return Verdict(True, f"numeric(root search, 3 points{how})", f"counts {counts}")


@quantity('secular_growth',
          book='integer k (solutions grow like t^k·e^{pt})',
          how=('the largest Jordan block of the state matrix (at `exponent:`, or over all '
               'exponents) has size k + 1: k = 0 no secular terms, k = 1 t·cos growth at a '
               'double root with one mode; ranks of (A − pI)^j in mpmath at 40 digits, 3 '
               'points'),
          keys={"exponent": EXPR})
def check_secular_growth(ctx: Context, val) -> Verdict:
    if not isinstance(val, int) or isinstance(val, bool) or val < 0:
        raise ctx.part.error(("book",), "expected a non-negative integer")
    lin = ctx.linear()
    sizes = []
    for _ in range(3):
        pt = ctx.sampler.draw()
        if "exponent" in ctx.part.data:
            targets = [value(ctx.parse(ctx.part.data["exponent"], ("exponent",)), pt)]
        else:
            targets = _clusters(response.exponents(lin, pt, precise=True))
        size = max(response.jordan_size(lin, pt, p) for p in targets)
        sizes.append(size)
        if size != val + 1:
            return Verdict(False, "numeric(Jordan blocks, 40 digits)",
                           f"largest Jordan block {size}: solutions grow like t^{size - 1}")
    return Verdict(True, "numeric(Jordan blocks, 40 digits, 3 points)")


def _clusters(lam: np.ndarray) -> list[complex]:
    """One representative per group of (nearly) equal exponents."""
    scale = max(1e-300, float(np.max(np.abs(lam))))
    out: list[complex] = []
    for x in lam:
        if not any(abs(x - y) <= 1e-6 * scale for y in out):
            out.append(complex(x))
    return out



@quantity('steady_exists',
          book='relation (where a steady motion exists)',
          how=('at ≥ 60 parameter points drawn widely, the relation holds exactly where some '
               'real rate of the coordinate `turning:` makes the configuration `at:` (every '
               'other coordinate) a steady motion: the residuals, polynomials in the rate, '
               'have a common real root (numpy roots, checked on every residual)'),
          keys={"turning": {"type": "string"}, "at": POINT})
def check_steady_exists(ctx: Context, val) -> Verdict:
    cond = ctx.parse(val, ("book",), relation=True)
    name = ctx.part.data.get("turning")
    if name not in ctx.system.coord_names:
        raise ctx.part.error(("turning",), "name the coordinate that turns at a steady rate")
    q = ctx.system.q[ctx.system.coord_names.index(name)]
    point = _coordinate_map(ctx, ctx.part.data.get("at") or {}, ("at",))
    if set(point) | {q} != set(ctx.system.q):
        raise ctx.part.error(("at",), "give every coordinate but the turning one")
    w = sp.Symbol("w_rate", real=True)
    coefficients = []  # each residual as a polynomial in the rate: its coefficients
    for e in steady.steady_residuals(ctx.dyn, {q: w}, point):
        if e != 0:
            coefficients.append(sp.Poly(sp.expand(e), w).all_coeffs())
    wide = ctx.sampler.widened(2.0)
    seen = {True: 0, False: 0}
    n = 0
    for _ in range(400):
        pt = wide.draw()
        exists = _common_real_root(coefficients, pt)
        claim = holds(cond, pt)
        if claim != exists:
            shown = ", ".join(f"{k}={float(v):.4g}" for k, v in sorted(
                pt.items(), key=lambda kv: kv[0].name)[:8])
            return Verdict(False, f"numeric({n + 1} points)",
                           f"book says {'a' if claim else 'no'} steady motion, engine finds "
                           f"{'one' if exists else 'none'} at {{{shown}}}")
        seen[claim] += 1
        n += 1
        if n >= 60 and min(seen.values()) >= 10:
            break
    if min(seen.values()) == 0:
        return Verdict(False, "numeric", "sampling never crossed the boundary; the check "
                       "cannot discriminate")
    return Verdict(True, f"numeric({n} points: {seen[True]} with, {seen[False]} without)")


def _common_real_root(coefficients: list[list], pt: dict) -> bool:
    """Do the polynomials (coefficient lists, highest first) have a common real root at
    `pt`? A coefficient counts as zero when it cancels to 1e-20 of its terms."""
    polys = []
    for coeffs in coefficients:
        vals = []
        for c in coeffs:
            v, size = value_and_scale(c, pt)
            vals.append(0.0 if abs(v) <= 1e-20 * max(size, 1e-300) else v.real)
        while vals and vals[0] == 0.0:
            vals.pop(0)
        if not vals:
            continue  # vanishes identically here
        if len(vals) == 1:
            return False  # a nonzero constant: no rate makes this residual vanish
        polys.append(np.array(vals))
    if not polys:
        return True
    roots = [r.real for r in np.roots(polys[0]) if abs(r.imag) <= 1e-9 * max(1, abs(r))]
    for r in roots:
        if all(abs(np.polyval(c, r)) <= 1e-9 * np.polyval(np.abs(c), abs(r)) for c in polys):
            return True
    return False
