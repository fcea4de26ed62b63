"""Stability and counts of equilibria and steady motions as answers: `stability`,
`equilibrium_count`, `secular_growth` (mechbook.engine.steady_search, .response).
`stability_condition` (a relation) is in mechbook.verify.quantities.equilibria.
"""

from __future__ import annotations

import numpy as np

from mechbook.core.words import plural
from mechbook.engine import response, steady
from mechbook.engine.certified_count import certified_count
from mechbook.engine.steady_search import classify, classify_at, roots_in
from mechbook.verify.compare import Verdict, value
from mechbook.verify.context import Context
from mechbook.verify.periodic import FloquetVerdicts, time_dependent
from mechbook.verify.quantities.equilibria import check_stability_condition
from mechbook.verify.quantities.steady import coordinate_map
from mechbook.verify.registration import EXPR, LIMIT, POINT, REGION, Family
from mechbook.verify.stability_proof import prove_stability

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity


@quantity('stability',
          book='stable, unstable or marginal (or a relation: stable exactly where it holds)',
          how=('the linearized system about the part\'s equilibrium or steady motion '
               '(`about:`, `steady:`) has that verdict at every one of 60 parameter points '
               'drawn widely (factors up to e² about the defaults; `assume:` bounds the '
               'region): "always stable / always unstable" claims, no boundary crossing '
               'needed. A marginal point (a zero frequency without gyroscopic terms) counts '
               'against `stable` and `unstable`; zero exponents of a symmetry are neutral. '
               'Coefficients periodic in t: Floquet multipliers (as `stability_condition`). A '
               'relation is checked as `stability_condition`. With `--prove`, `symbolic` '
               'where the verdict follows from signs proved at every admissible point: '
               'unstable from det M > 0 > det K; stable from M, K positive definite (C '
               'gyroscopic or none) or, under gyroscopic terms, from the even characteristic '
               'polynomial in s = λ² (degree ≤ 3) with positive coefficients and '
               'discriminant'),
          literals=("stable", "unstable", "marginal"),
          keys={"limit": LIMIT, "period": EXPR},
          crosschecks=("modes",))
def check_stability(ctx: Context, val) -> Verdict:
    if isinstance(val, str) and ("<" in val or ">" in val):  # a condition after all
        return check_stability_condition(ctx, val)
    if val not in ("stable", "unstable", "marginal"):
        raise ctx.part.error(("book",), "expected stable, unstable or marginal (or a "
                             "relation: where it is stable)")
    if "limit" in ctx.part.data:
        raise ctx.part.error(("limit",), "`limit:` applies to a relation (where it is stable "
                             "in the limit), not to a verdict")
    lin = ctx.linear()
    floquet = FloquetVerdicts(ctx, lin) if time_dependent(lin) else None
    if floquet is None and "period" in ctx.part.data:
        raise ctx.part.error(("period",), "`period:` is for a linearization whose "
                             "coefficients depend on t; these do not")
    wide = ctx.sampler.widened(2.0)
    seen: dict[str, int] = {}
    for n in range(60):
        pt = wide.draw()
        got = classify(lin, pt) if floquet is None else floquet.stability(pt)
        seen[got] = seen.get(got, 0) + 1
        if got != val:
            shown = ", ".join(f"{k}={float(v):.4g}" for k, v in sorted(
                pt.items(), key=lambda kv: kv[0].name)[:8])
            return Verdict(False, f"numeric({plural(n + 1, 'point')})",
                           f"engine finds it {got} at {{{shown}}}")
    power = (f"60 points drawn widely (factors to e²), all {val}: a claim of no boundary, "
             "checked away from one")
    numeric = Verdict(True, f"numeric(60 points, all {val})",
                      power=power if floquet is None else f"{power}; {floquet.power()}")
    if not ctx.policy.prove or floquet is not None:
        return numeric
    proof = prove_stability(lin, val, ctx.sampler)
    if proof.ok:
        return Verdict(True, "symbolic", power=f"proved {val} at every admissible point (the "
                       "signs of the linearization's determinants and minors; "
                       "mechbook.verify.stability_proof)")
    numeric.unproved = proof.why
    return numeric


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
               'multistart root finding at 3 points; where the conditions are polynomial (after '
               'factors that never vanish are removed) the count is certified exactly by a '
               'Gröbner basis and real-root isolation at a rational point, otherwise it is a '
               'lower bound and the outcome says so; `stable: true/false` also checks each '
               'one\'s stability'),
          keys={"search": {"oneOf": [REGION, {"type": "array", "minItems": 1,
                                               "items": REGION}]},
                "rates": POINT, "momenta": POINT, "stable": {"type": "boolean"}})
def check_equilibrium_count(ctx: Context, val) -> Verdict:
    if not isinstance(val, int) or isinstance(val, bool):
        raise ctx.part.error(("book",), "expected an integer")
    if "search" not in ctx.part.data:
        raise ctx.part.error((), "a count needs `search:` (the region to count in)")
    rates = coordinate_map(ctx, ctx.part.data.get("rates") or {}, ("rates",))
    momenta = coordinate_map(ctx, ctx.part.data.get("momenta") or {}, ("momenta",))
    if rates and momenta:
        raise ctx.part.error(("momenta",), "fix either rates or momenta")
    conds, unknowns, eq = steady.steady_conditions(ctx.system, rates, momenta)
    want = ctx.part.data.get("stable")
    counts = []
    certified = 0
    for _ in range(3):
        pt = ctx.sampler.draw()
        boxes = _boxes(ctx, pt, unknowns)
        roots = roots_in(conds, unknowns, pt, boxes)
        counts.append(len(roots))
        where = "; ".join("(" + ", ".join(f"{x:.5g}" for x in r) + ")" for r in roots[:6])
        exact = certified_count(conds, unknowns, pt, boxes)
        if exact is not None:
            certified += 1
            if exact[0] != val:
                return Verdict(False, "exact(real-root isolation)",
                               f"exactly {exact[0]} in the region at the rational point "
                               f"{_fmt(exact[1])} (the search found {len(roots)}: {where})")
        if len(roots) != val:
            return Verdict(False, "numeric(root search)",
                           f"found {len(roots)} in the region: {where}")
        if want is not None:
            for r in roots:
                got = classify_at(eq, dict(zip(unknowns, r, strict=True)), pt, rates)
                if (got == "stable") != want:
                    at = ", ".join(f"{x:.5g}" for x in r)
                    return Verdict(False, "numeric(root search)", f"the one at ({at}) is {got}")
    how = "" if want is None else f", each {'stable' if want else 'unstable'}"
    if certified:
        power = (f"exactly {val} (real-root isolation of the polynomial conditions at "
                 f"{certified} rational points)")
    else:
        power = (f"at least {val} (multistart search at 3 points; the conditions are not "
                 "polynomial, so others could hide: a lower bound)")
    return Verdict(True, f"numeric(root search, 3 points{how})", f"counts {counts}",
                   power=power + how)


def _fmt(pt: dict) -> str:
    return "{" + ", ".join(f"{k}={v}" for k, v in sorted(pt.items(), key=lambda kv: str(kv[0]))
                           [:8]) + "}"


@quantity('secular_growth',
          book='integer k (solutions grow like t^k·e^{pt})',
          how=('the largest Jordan block of the state matrix (at `exponent:`, or over all '
               'exponents) has size k + 1: k = 0 no secular terms, k = 1 t·cos growth at a '
               'double root with one mode; ranks of (A − pI)^j in mpmath at 40 digits, 3 '
               'points'),
          keys={"exponent": EXPR},
          complex_values=True,
          crosschecks=("modes",))
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
    return Verdict(True, "numeric(Jordan blocks, 40 digits, 3 points)",
                   power="exact sizes of Jordan blocks (ranks at 40 digits), 3 points")



def _clusters(lam: np.ndarray) -> list[complex]:
    """One representative per group of (nearly) equal exponents."""
    scale = max(1e-300, float(np.max(np.abs(lam))))
    out: list[complex] = []
    for x in lam:
        if not any(abs(x - y) <= 1e-6 * scale for y in out):
            out.append(complex(x))
    return out



