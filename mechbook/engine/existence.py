"""Which equilibria exist at given parameter values: real, and inside the coordinates'
domains (mechbook.model.domains).

SymPy's solve returns every branch of the conditions: a spring pendulum's polar origin
r = 0 with cos(theta) = -k*l0/(g*m), a complex arccosine at the default values, a radius
that is negative unless k*l0 > m*g. A listing for a reader (`mechbook solve`, the report,
the Python API) shows the points that exist at the parameters and says how many it left
out and why; the checker compares a book's answer with the engine's points as they are
(an equilibrium that exists only for other parameter values is still one). The numeric
search looks only inside the domains.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from mechbook.model.domains import outside


def why_not(point: dict, sys, values: dict) -> str | None:
    """Why `point` does not exist at `values` (a coordinate not real there, or outside its
    domain), or None where it does (or cannot be evaluated: kept)."""
    for q, v in point.items():
        if not isinstance(v, sp.Basic):
            continue
        try:
            z = complex(sp.N(v.subs(values), 20))
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            continue
        if not (math.isfinite(z.real) and math.isfinite(z.imag)):
            return f"{q} = {sp.sstr(v)} is not finite at the default values"
        if abs(z.imag) > 1e-9 * max(1.0, abs(z.real)):
            return f"{q} = {sp.sstr(v)} is not real at the default values ({_num(z)})"
    return outside(point, sys.domains, values)


def existing(points: list[dict], sys, values: dict) -> tuple[list[dict], list[str]]:
    """(the points that exist at `values`, a reason for each one left out)."""
    kept, dropped = [], []
    for point in points:
        why = why_not(point, sys, values)
        if why is None:
            kept.append(point)
        else:
            dropped.append(why)
    return kept, dropped


def clip_ranges(sys, qs: list, ranges: list[tuple[float, float]],
                values: dict) -> list[tuple]:
    """Search intervals (one per coordinate of `qs`, in order) narrowed to the domains."""
    domains = sys.domains
    out = []
    for q, (lo, hi) in zip(qs, ranges, strict=True):
        dom = domains.get(q)
        out.append(dom.clip(lo, hi, values) if dom is not None else (lo, hi))
    return out


def inside(sys, qs: list, x: np.ndarray, values: dict) -> bool:
    """Whether the values `x` of the coordinates `qs` lie in their domains at `values`."""
    domains = sys.domains
    return all(domains[q].contains(float(v), values) for q, v in zip(qs, x, strict=False)
               if q in domains)


def _num(z: complex) -> str:
    return f"{z.real:.4g}{z.imag:+.4g}i"
