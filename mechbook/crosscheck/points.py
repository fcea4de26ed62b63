"""Where a problem's frequency cross-checks are taken: one per distinct point.

Two answer parts about the same point share one simulation: a point is known by its system,
whether it is a steady motion (which momenta are held), its coordinates and the parameter
values, numerically (so `pi - acos(x)` and `acos(-x)` coincide). Besides the points the
answer key names, every stable equilibrium the engine finds at the default values gets a
check of its own.
"""

from __future__ import annotations

import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.engine.linear import LinearSystem
from mechbook.engine.screen import screen, snap
from mechbook.errors import UnsupportedError


def numeric_key(lin: LinearSystem, values: dict, params: set) -> tuple:
    """What makes two cross-checks the same: system, steady or not, the point and the
    parameter values, numerically (so `pi - acos(x)` and `acos(-x)` coincide)."""
    sys_lin = lin.dyn.sys
    steady = tuple(sorted(map(str, sys_lin.held_momenta))) if sys_lin.reduced else ()
    point = []
    for q in lin.q:
        try:
            point.append(round(float(sp.N(sp.S(lin.point.get(q, 0)).subs(values))), 9))
        except (TypeError, ValueError):
            point.append(str(lin.point.get(q, 0)))
    pv = tuple(sorted((str(k), round(float(v), 12)) for k, v in values.items() if k in params))
    rates = []  # a steady motion kept in full: its rates tell two such motions apart
    for q, r in sorted((getattr(lin, "velocity", None) or {}).items(), key=lambda kv: str(kv[0])):
        try:
            rates.append((str(q), round(float(sp.N(sp.S(r).subs(values))), 9)))
        except (TypeError, ValueError):
            rates.append((str(q), str(r)))
    return (steady, tuple(point), pv) + ((tuple(rates),) if rates else ())


def point_label(lin: LinearSystem) -> str:
    """The point as the cross-check's name shows it (`{theta: pi}`, `… steady (p_phi
    fixed)`)."""
    sys_lin = lin.dyn.sys
    pt = ", ".join(f"{q}: {sp.sstr(lin.point.get(q, 0))}" for q in lin.q)
    if sys_lin.reduced:
        cyc = ", ".join(f"p_{c}" for c in sys_lin.held_momenta)
        return f"{{{pt}}} steady ({cyc} fixed)"
    return "{" + pt + "}"


def engine_linear_systems(analysis: Analysis, name: str,
                          checked: dict) -> list[tuple[LinearSystem, str]]:
    """Linear systems about the stable equilibria of `name` at the default values (when the
    system asks for small oscillations) that no check in `checked` (tags as
    `numeric_key` makes them) has linearized yet. Found numerically (mechbook.engine.screen):
    no part asks for a closed form here, and SymPy's search would mostly spend its time
    limit on transcendental conditions and find nothing."""
    sys = analysis.system(name)
    compute = sys.spec.get("compute")
    if compute is not None and "small_oscillations" not in compute:
        return []
    values = analysis.problem.values()
    try:
        found = screen(analysis.equilibria(name), values)
    except UnsupportedError:
        return []
    pv = tuple(sorted((str(k), round(float(v), 12)) for k, v in values.items()))
    done = [tag[2] for tag in checked if len(tag) == 4 and tag[0] == name and tag[1] == ()
            and tag[3] == pv and all(isinstance(x, float) for x in tag[2])]
    out = []
    for f in found.found:
        if not (f.isolated and f.stability == "stable"):
            continue
        if any(found.same(f.point, d) for d in done):
            continue
        point = {q: snap(x) for q, x in zip(sys.q, f.point, strict=True)}
        if not admissible(sys, point, values):
            continue  # outside a coordinate's domain (r > 0): not a state of the problem
        try:
            lin = analysis.linear(name, point)
            if lin.numeric_stability(values) != "stable" and not _marginal_ok(lin, values):
                continue
        except (UnsupportedError, TypeError, ValueError):
            continue
        done.append(tuple(f.point))
        out.append((lin, point_label(lin)))
    return out


def admissible(system, point: dict, values: dict) -> bool:
    """Is `point` (coordinates) inside every coordinate's declared domain and sign (a
    positive r stays positive)? A cross-check samples only states the problem admits.
    Example: for a coordinate r declared positive, admissible(sys, {r: -0.62}, {}) is
    False."""
    domains = system.domains
    params = {k: float(v) for k, v in values.items()
              if isinstance(v, int | float) or getattr(v, "is_number", False)}
    for q, x in point.items():
        try:
            x = float(x)
        except (TypeError, ValueError):
            continue
        if q.is_positive and x <= 0 or q.is_nonnegative and x < 0:
            return False
        if q in domains and not domains[q].contains(x, params):
            return False
    return True


def _marginal_ok(lin: LinearSystem, values: dict) -> bool:
    """A marginal point (zero modes, e.g. a free translation) with the rest oscillating."""
    try:
        return lin.numeric_stability(values) == "marginal"
    except (TypeError, ValueError):
        return False
