"""The field frequencies by a spectral discretization that does not separate: the check
of a `field_frequencies` part by other means (never reading the book's values).

A segment by Chebyshev collocation at 48 points (the separated roots were bracketed at
64), a rectangle by a 2-D tensor-product collocation of the whole operator (no
separation), a disk or an annulus by collocation of Bessel's radial equation for each n.
At the part's default parameters the separated frequencies (engine.continuum) and these
agree within 1e-8 relative, or the check fails.
"""

from __future__ import annotations

import mpmath as mp

from mechbook.crosscheck.guard import guarded
from mechbook.crosscheck.partview import PartView
from mechbook.engine.analysis import Analysis
from mechbook.engine.continuum import (
    as_number,
    edge_conditions,
    field_equation,
    isotropic_membrane,
    linear_coefficients,
    modal_coefficients,
    segment_problem,
    squared_frequencies,
)
from mechbook.engine.spectral import radial_eigenvalues, rectangle_eigenvalues, segment_eigenvalues
from mechbook.records import CrossCheck, Status
from mechbook.verify.answers import Part

RTOL = 1e-8
SEGMENT_POINTS = 48


def spectral_part(analysis: Analysis, part: Part, models: dict) -> CrossCheck | None:
    """The spectral cross-check of a `field_frequencies` part (None without a field)."""
    model = analysis.built.field()
    if model is None:
        return None
    x = CrossCheck(f"spectral:{part.name}", "frequencies", "", Status.ERROR, parts=[part.name])
    with guarded(x):
        point = PartView(analysis, part).values()
        book = part.data.get("book")
        count = len(book) if isinstance(book, list) else 1
        if part.data.get("partial"):
            count = 2 * count + 8
        separated = [float(v) for v in squared_frequencies(model, point, count)]
        spectral = discretized(model, point, count)
        worst = max(abs(a - b) / max(abs(a), 1e-3 * max(separated))
                    for a, b in zip(separated, spectral, strict=False))
        x.error = worst
        shown = ", ".join(f"{float(mp.sqrt(max(v, 0))):.10g}" for v in spectral[:6])
        x.status = Status.PASS if worst <= RTOL and len(spectral) >= count else Status.FAIL
        x.detail = (f"ω² by collocation within {worst:.2g} of the separated values "
                    f"(ω: {shown}{', …' if len(spectral) > 6 else ''})")
    return x


def discretized(model, point: dict, count: int) -> list[float]:
    """The lowest `count` ω² by collocation, at the parameter point."""
    weight, coeffs = modal_coefficients(model, field_equation(model))
    if model.domain == "segment":
        ode, w, length, left, right = segment_problem(model, coeffs, weight, 0, model.edges,
                                                      point, True)
        return segment_eigenvalues([float(c) for c in ode], float(w), float(length),
                                   [([float(v) for v in r], float(m)) for r, m in left],
                                   [([float(v) for v in r], float(m)) for r, m in right],
                                   count, SEGMENT_POINTS)
    if model.domain == "rectangle":
        ops = {o[1:]: float(as_number(c, point)) for o, c in coeffs.items()}
        edges = {}
        for e in model.edges:
            cond, = edge_conditions(model, e)
            lin = linear_coefficients(model, cond)
            normal = tuple([0] + [1 if i == e.axis else 0 for i in range(2)])
            edges[e.name] = [float(as_number(lin.get((0, 0, 0), 0), point)),
                             float(as_number(lin.get(normal, 0), point))]
        return rectangle_eigenvalues(ops, float(as_number(weight, point)),
                                     tuple(float(as_number(s, point)) for s in model.size),
                                     edges, count)
    tau, c0, w = (float(v) for v in isotropic_membrane(model, weight, dict(coeffs), point))
    kinds = tuple(0 if e.kind == "fixed" else 1 for e in model.edges)
    if model.domain == "disk":
        inner, outer, kinds = 0.0, float(as_number(model.size[0], point)), (None, kinds[0])
    else:
        inner, outer = (float(as_number(s, point)) for s in model.size)
    out: list[float] = []
    for n in range(count + 1):
        ks = radial_eigenvalues(n, inner, outer, kinds, count)
        lams = [(tau * max(k, 0.0) - c0) / w for k in ks]
        if n and len(out) >= count and min(lams) > sorted(out)[count - 1]:
            break
        out += lams * (2 if n else 1)
    return sorted(out)[:count]
