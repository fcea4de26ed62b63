"""Steady motions, in general: where they are, how many, and whether they are stable.

A steady motion turns some coordinates at constant rates while the others stay put
(Symon §12-6); with no rates it is an equilibrium. Three questions, for any system:

    steady_residuals  the equations of motion along q*(t) = point + rates·t (q̈ = 0): all
                      zero, at two times, exactly when the motion is steady
    count             the distinct steady motions in a region of the non-turning
                      coordinates, at fixed rates or at fixed momenta of cyclic coordinates
                      (Routh's reduction), found by multistart root finding
    classify          stable / unstable / marginal from the linearized equations (Routh
                      reduced or kept in full), with the size of the largest Jordan block
                      (secular t^k growth at a multiple root) for the marginal cases

Chapter 11's tops (steady precession) and chapter 12's orbits and three bodies use the same
functions; nothing here knows a particular system.
"""

from __future__ import annotations

import numpy as np
import scipy.optimize
import sympy as sp

from mechbook.core.compile import compile_exprs
from mechbook.engine.equilibria import Equilibria
from mechbook.engine.lagrange import Dynamics
from mechbook.engine.linear import LinearSystem, classify_matrices
from mechbook.engine.routh import ReducedSystem
from mechbook.errors import UnsupportedError

TIMES = (sp.Rational(7, 5), sp.Rational(-3, 7))  # a steady motion's residual vanishes at all t


def steady_residuals(dyn: Dynamics, rates: dict, point: dict) -> list[sp.Expr]:
    """E_i along q*(t) = point + rates·t, q̇ = rates, q̈ = 0 (small parameters off), at two
    times: every one vanishes exactly when that uniform motion solves the equations."""
    sys = dyn.sys
    sub = {}
    for q, v, a in zip(dyn.q, dyn.qd, dyn.qdd, strict=True):
        sub[q] = sp.S(point.get(q, 0)) + sp.S(rates.get(q, 0)) * sys.t
        sub[v] = sp.S(rates.get(q, 0))
        sub[a] = sp.S.Zero
    sub.update({s: sp.S.Zero for s in sys.small_params})
    out = []
    for e in dyn.residuals:
        e = e.subs(sub, simultaneous=True)
        out += [e.subs(sys.t, tv) for tv in TIMES] if e.has(sys.t) else [e]
    return out


def reduced_at(sys, momenta: dict) -> ReducedSystem:
    """The system left when the cyclic coordinates `momenta` names keep those momenta."""
    return ReducedSystem(sys, {c: sp.S.Zero for c in momenta}, {}, momenta=momenta)


def steady_conditions(sys, rates: dict | None = None, momenta: dict | None = None
                      ) -> tuple[list[sp.Expr], list[sp.Symbol], Equilibria]:
    """The conditions on the non-turning coordinates for a steady motion, those
    coordinates, and the Equilibria object that linearizes about one: at fixed `rates`
    (E_i with q̇ = rates), at fixed cyclic `momenta` (the equilibrium conditions of Routh's
    reduced system), or neither (static equilibria)."""
    if momenta:
        reduced = reduced_at(sys, momenta)
        eq = Equilibria(Dynamics(reduced))
        return eq.conditions, list(reduced.q), eq
    dyn = Dynamics(sys)
    rates = rates or {}
    free = [q for q in dyn.q if q not in rates]
    conds = []
    for e in steady_residuals(dyn, rates, {q: q for q in free}):
        if e.has(sys.t):
            raise UnsupportedError("steady motions of a non-autonomous system")
        if e != 0:
            conds.append(e)
    return conds, free, Equilibria(dyn)


def classify_at(eq: Equilibria, root: dict, values: dict, rates: dict | None = None) -> str:
    """The stability of the steady motion found numerically at `root` ({q: float}), at
    fixed `rates` of the turning coordinates (or at rest in a reduced system): M, C, K are
    the derivatives of the equations of motion there, taken symbolically once and
    evaluated at the numbers (a numeric root is no exact equilibrium for `linearize`)."""
    dyn = eq.dyn
    held = getattr(dyn.sys, "held", {})
    rates = rates or {}
    sub = {v: sp.S(rates.get(q, 0)) for q, v in zip(dyn.q, dyn.qd, strict=True)}
    sub.update({a: 0 for a in dyn.qdd})
    sub.update({s: 0 for s in dyn.sys.small_params})
    key = ("jacobians", tuple(sorted(map(str, rates))))
    cache = eq.__dict__.setdefault("_jacobians", {})
    if key not in cache:
        res = [e.xreplace(held) for e in dyn.residuals]
        cache[key] = [sp.Matrix([[sp.diff(e, v) for v in vs] for e in res]).subs(sub)
                      for vs in (dyn.qdd, dyn.qd, dyn.q)]
    at = dict(values)
    at.update({q: sp.Float(x, 30) for q, x in root.items()})
    M, C, K = (np.array(A.subs(at).evalf(30).tolist(), dtype=complex).real.astype(float)
               for A in cache[key])
    return classify_matrices(M, C, K)


def roots_in(conds: list[sp.Expr], unknowns: list[sp.Symbol], values: dict,
             boxes: list[dict], starts: int = 7, tol: float = 1e-10) -> list[np.ndarray]:
    """The distinct solutions of conds = 0 inside any of `boxes` ({q: (lo, hi)}; a missing
    coordinate ranges over (−π, π)), by Newton-type root finding from a grid of starting
    points in each box (`starts` per coordinate, at most 3000 per box). Solutions on a box's
    edge (within 1e-9 of its width) are not counted: a count is about the interior."""
    F = [sp.N(c.subs(values), 30) for c in conds]
    J = sp.Matrix(F).jacobian(unknowns)
    f_num, _ = compile_exprs(unknowns, F)
    j_num, _ = compile_exprs(unknowns, list(J))
    n, m = len(unknowns), len(F)
    found: list[np.ndarray] = []
    rng = np.random.default_rng(11)
    for box in boxes:
        ranges = [box.get(q, (-np.pi, np.pi)) for q in unknowns]
        # a positive range over decades (a distance) is searched on a geometric grid
        grids = [np.geomspace(lo, hi, starts + 2)[1:-1] if lo > 0 and hi > 100 * lo
                 else np.linspace(lo, hi, starts + 2)[1:-1] for lo, hi in ranges]
        mesh = np.array(np.meshgrid(*grids, indexing="ij")).reshape(n, -1).T
        if len(mesh) > 3000:
            mesh = mesh[rng.choice(len(mesh), 3000, replace=False)]
        width = np.array([hi - lo for lo, hi in ranges], dtype=float)
        for x0 in mesh:
            with np.errstate(all="ignore"):
                sol = scipy.optimize.root(
                    lambda x: np.asarray(f_num(x), float), x0, method="lm",
                    jac=lambda x: np.asarray(j_num(x), float).reshape(m, n))
            x = sol.x
            with np.errstate(all="ignore"):
                resid = np.asarray(f_num(x), float)
                jac = np.asarray(j_num(x), float).reshape(m, n)
            if not (np.all(np.isfinite(x)) and np.all(np.isfinite(resid))
                    and np.all(np.isfinite(jac))):
                continue
            # a root, not a place where the conditions are merely small (a potential that
            # decays far away): the Newton step from it must be negligible
            step = np.linalg.lstsq(jac, resid, rcond=None)[0]
            if not np.linalg.norm(step) <= tol * max(1.0, float(np.max(width))):
                continue
            inside = all(lo + 1e-9 * w < xi < hi - 1e-9 * w
                         for xi, (lo, hi), w in zip(x, ranges, width, strict=True))
            if inside and not any(np.allclose(x, f, rtol=1e-6, atol=1e-7 * np.max(width))
                                  for f in found):
                found.append(x)
    return found


def classify(lin: LinearSystem, values: dict) -> str:
    """'stable', 'unstable' or 'marginal' (the linearized system's own verdict)."""
    return lin.numeric_stability(values)
