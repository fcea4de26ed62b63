"""Cross-check on the constraint manifold: Newton–Euler with the constraint forces.

The off-shell Newton check (mechbook.crosscheck.newton) compares the engine's Lagrange
expressions with Newton's and Euler's as functions, constraint forces aside. Here the
constraints are judged: at states on the constraint manifold the engine's equations are
solved numerically for the accelerations and multipliers (its KKT system), and Newton's
and Euler's residual there must equal the forces of the constraints built here from those
multipliers — λ·∂g/∂q of a holonomic constraint, λ·∂c/∂q̇ of a velocity constraint read
from the file again, and for a rolling contact the friction Σ λ_k t_k acting at the contact
point, through this module's own contact velocity v_G + ω × (P − r_G) (ω and R from the
Newton check's own kinematics, the contact point from the shape by the rule docs/schema.md
states). Each rolling contact's own tangential velocity is compared with the engine's
constraint rows too.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np
import symengine as se
import sympy as sp

from mechbook.core.backends import FEW_CALLS_BACKEND
from mechbook.core.compile import compile_exprs
from mechbook.core.secalc import either, same
from mechbook.engine.analysis import Analysis
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.model.manifold import manifold_of


def _tangents(n: sp.Matrix) -> list[sp.Matrix]:
    """The tangent basis of a contact's plane, by the convention docs/schema.md states (in
    space: t1 the first coordinate axis not along n made orthogonal to it, t2 = n × t1; in
    a plane: n turned by −90°), built here from that statement."""
    if n.rows == 2:
        return [sp.Matrix([n[1], -n[0]])]
    for k in range(3):
        e = sp.Matrix([1 if i == k else 0 for i in range(3)])
        w = e - e.dot(n) * n
        if sp.N(w.dot(w)) > 1e-6:
            t1 = w / sp.sqrt(w.dot(w))
            return [t1, n.cross(t1)]
    raise UnsupportedError("Newton cross-check: a contact's normal is zero")


def _contact_point(spec: dict, c: dict, sub: tuple, r: sp.Matrix, frame, n: sp.Matrix,
                   parse) -> sp.Matrix:
    """Where a rolling body touches the plane: its `point`, or from its shape with this
    module's own attitude R (a sphere at r − ρn; a disk, ring or cylinder at r − ρu, u the
    unit part of n normal to its own z axis Rẑ; a planar body at r − ρn)."""
    if "point" in c:
        return sp.Matrix([parse(x, sub + ("point", j)) for j, x in enumerate(c["point"])])
    body = c["body"]
    inertia = spec["rigid_bodies"][body]["inertia"]
    rho = parse(inertia["radius"], ("rigid_bodies", body, "inertia", "radius"))
    R = frame[2] if frame is not None else None
    if inertia["shape"] in ("solid_sphere", "spherical_shell") or R is None:
        return r - rho * n
    e = R * sp.Matrix([0, 0, 1])
    w = n - n.dot(e) * e
    return r - rho * w / sp.sqrt(w.dot(w))


def _constraint_forces(sys, spec: dict, positions: dict, frames: dict, parse,
                       multipliers: list) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """(generalized forces of the constraints, rolling rows) given their multipliers, from
    the file here: λ·∂g/∂q of a holonomic constraint, λ·∂c/∂q̇ of a velocity constraint, and
    for a rolling contact the friction Σ λ_k t_k acting at the contact point, Q = F·∂v/∂q̇
    with this module's own contact velocity v = v_G + ω × (P − r_G) (less the surface's),
    whose tangential components are returned too (the rows rolling adds)."""
    n = len(sys.q)
    out = [sp.S.Zero] * n
    lam = iter(multipliers)
    for i, c in enumerate(spec.get("constraints") or []):
        g = parse(c["expr"], ("constraints", i, "expr"))
        mu = next(lam)
        out = [o + mu * sp.diff(g, q) for o, q in zip(out, sys.q, strict=True)]
    for i, c in enumerate(spec.get("velocity_constraints") or []):
        k = parse(c["expr"], ("velocity_constraints", i, "expr"))
        mu = next(lam)
        out = [o + mu * sp.diff(k, v) for o, v in zip(out, sys.qd, strict=True)]
    rows: list = []
    contacts = []  # (contact velocity, its tangents, their multipliers), SymPy objects
    for i, c in enumerate(spec.get("rolling") or []):
        sub = ("rolling", i)
        body = c["body"]
        r = positions[body]
        surface = c.get("surface") or {}
        nv = (sp.Matrix([parse(x, sub + ("surface", "normal", j))
                         for j, x in enumerate(surface["normal"])]) if "normal" in surface
              else sp.Matrix([0] * (r.rows - 1) + [1]))
        nv = nv / sp.sqrt(nv.dot(nv))
        frame = frames.get(body)
        p = _contact_point(spec, c, sub, r, frame, nv, parse)
        v = sys.dt(r)
        _, omega, R = frame
        d = p - r
        if R is None and omega.rows == 1:  # planar
            v = v + sp.Matrix([-omega[0] * d[1], omega[0] * d[0]])
        else:
            v = v + (R * omega if R is not None else omega).cross(d)
        if "velocity" in surface:
            v = v - sp.Matrix([parse(x, sub + ("surface", "velocity", j))
                               for j, x in enumerate(surface["velocity"])])
        tangents = _tangents(nv)
        contacts.append((list(v), [list(t) for t in tangents], [next(lam) for _ in tangents]))
    if contacts:
        # the friction's generalized forces and the tangential rows, in SymEngine's algebra
        # where it can do the calculus (SymPy's otherwise): ∂v/∂q̇ and the dot products in
        # SymPy were most of this cross-check's time (the compile layer takes either)
        gen, rows = either(partial(_friction_terms, contacts, list(sys.qd)))
        conv = se.sympify if isinstance(next(iter(gen), None), se.Basic) else same
        out = [conv(o) + g for o, g in zip(out, gen, strict=True)]
    return out, rows


def _friction_terms(contacts: list, qd: list, conv) -> tuple[list, list]:
    """(Σ F·∂v/∂q̇_i over the contacts, each contact's tangential rows v·t), F = Σ λ_k t_k
    the friction at the contact, in the algebra `conv` converts to (core.secalc.either)."""
    gen = [conv(sp.S.Zero)] * len(qd)
    rows = []
    rates = [conv(x) for x in qd]
    for v, tangents, lams in contacts:
        vel = [conv(x) for x in v]
        ts = [[conv(x) for x in t] for t in tangents]
        force = [sum((conv(lam) * t[j] for lam, t in zip(lams, ts, strict=True)), conv(0))
                 for j in range(len(vel))]
        rows += [sum((a * b for a, b in zip(vel, t, strict=True)), conv(0)) for t in ts]
        gen = [g + sum((f * e.diff(rate) for f, e in zip(force, vel, strict=True)), conv(0))
               for g, rate in zip(gen, rates, strict=True)]
    return gen, rows


def on_manifold(analysis: Analysis, sys, newton: list, frames: dict,
                samples: int) -> tuple[float, float, int]:
    """(worst relative difference of the rolling rows, worst relative force imbalance,
    states) on the constraint manifold: each rolling contact's own tangential velocity
    against the engine's constraint rows, and Newton–Euler with the contact forces: at
    the engine's accelerations and multipliers (its equations solved numerically there),
    Σ J·(m r̈ − F) + Euler terms equals the constraints' forces built here from the
    multipliers."""
    dyn = analysis.dynamics(sys.name)
    lam = list(dyn.multipliers)
    names = list(sys.spec.get("particles") or {}) + list(sys.spec.get("rigid_bodies") or {})
    positions = {name: sys.positions[name] for name in names}
    forces, rows = _constraint_forces(sys, sys.spec, positions, frames, sys.parse, lam)
    engine_rows = [c for _, c in sys.velocity_constraints][
        len(sys.spec.get("velocity_constraints") or []):]
    params = [p.symbol for p in sys.params.values()]
    args = [sys.t, *sys.q, *sys.qd, *sys.qdd, *lam, *params]
    exprs = (list(dyn.residuals) + newton + forces + list(dyn.velocity_jacobian)
             + list(dyn.constraint_bias) + rows + engine_rows)
    fn, _ = compile_exprs(args, exprs, FEW_CALLS_BACKEND)
    layout = _Layout(len(sys.q), len(lam), len(rows))
    manifold = manifold_of(sys)
    rng = np.random.default_rng(20261129)
    base = np.array([p.value for p in sys.params.values()])
    positive = np.array([p.positive for p in sys.params.values()])
    worst_rows = worst_force = 0.0
    used = 0
    for _ in range(10 * samples):
        if used >= samples:
            break
        pv = np.where(positive, base * np.exp(rng.uniform(-0.3, 0.3, len(base))),
                      base + rng.uniform(-0.3, 0.3, len(base)))
        t0 = float(rng.uniform(0, 1))
        n = layout.n
        settled = manifold.settle(dict(zip(params, pv, strict=True)), rng.uniform(0.05, 0.6, n),
                                  rng.uniform(-1, 1, n), t0)
        if settled is None:
            continue
        state = np.concatenate(([t0], settled[0], settled[1]))
        judged = _judge(partial(_evaluate, fn, state, pv), layout, np.array(settled[1]))
        if judged is None:
            continue
        worst_force = max(worst_force, judged[0])
        worst_rows = max(worst_rows, judged[1])
        used += 1
    if used < 3:
        raise MechbookError("Newton cross-check: no states on the constraint manifold "
                            "evaluate")
    return worst_rows, worst_force, used


@dataclass(frozen=True)
class _Layout:
    """Where each piece sits in the compiled function's output: E (n), Newton's residual
    (n), the constraint forces (n), A (m×n), the bias (m), own rolling rows (r), the
    engine's (r)."""

    n: int
    m: int
    r: int

    @property
    def a(self) -> int:
        return 3 * self.n

    @property
    def rows(self) -> int:
        return self.a + self.m * self.n + self.m


def _judge(at, layout: _Layout, qd: np.ndarray) -> tuple[float, float] | None:
    """(relative force imbalance, relative difference of the rolling rows) at one state:
    the engine's M from E at unit accelerations, its KKT system solved, Newton's residual
    against the constraint forces there. None where something does not evaluate."""
    n, m, k = layout.n, layout.m, layout.a
    zero = at(np.zeros(n), np.zeros(m))
    e0 = zero[:n]
    M = np.column_stack([at(np.eye(n)[j], np.zeros(m))[:n] - e0 for j in range(n)])
    A = zero[k: k + m * n].reshape(m, n)
    bias = zero[k + m * n: layout.rows]
    kkt = np.block([[M, -A.T], [A, np.zeros((m, m))]])
    if not (np.all(np.isfinite(kkt)) and np.all(np.isfinite(zero))):
        return None
    sol = np.linalg.solve(kkt, np.concatenate((-e0, -bias)))
    val = at(sol[:n], sol[n:])
    newton, forces = val[n: 2 * n], val[2 * n: 3 * n]
    scale = max(float(np.max(np.abs(newton))), float(np.max(np.abs(forces))),
                float(np.max(np.abs(M @ sol[:n]))), 1e-300)
    imbalance = float(np.max(np.abs(newton - forces))) / scale
    if not layout.r:
        return imbalance, 0.0
    own = val[layout.rows: layout.rows + layout.r]
    eng = val[layout.rows + layout.r:]
    size = max(float(np.max(np.abs(own))), float(np.max(np.abs(eng))),
               float(np.max(np.abs(qd))), 1e-300)
    return imbalance, float(np.max(np.abs(own - eng))) / size


def _evaluate(fn, state: np.ndarray, params: np.ndarray, qdd: np.ndarray,
              multipliers: np.ndarray) -> np.ndarray:
    with np.errstate(all="ignore"):
        return fn(np.concatenate((state, qdd, multipliers, params)))
