"""Sliding (Coulomb) friction at a contact: the system key `friction:`.

    friction:
      - body: top                      # the particle or rigid body that touches
        point: [xp, yp, 0]             # where it touches, in space (functions of q)
        normal: [0, 0, 1]              # the surface's normal (default: the last axis)
        mu: mu                         # the coefficient of friction
        normal_force: M*g              # N ≥ 0, a function of the state (no accelerations)

The material point of the body at `point` moves with v = v_G + ω × (point − r_G) (a particle:
its own velocity); its part along the surface, v_t = v − (v·n)n, is the sliding velocity.
While it slides the contact feels F = −μN·v_t/|v_t| there, whose generalized forces
Q_k = F·∂v/∂q̇_k are added to the system's forces, so every part of the engine (equations of
motion, simulations, trajectory quantities) sees the sliding law. At |v_t| = 0 the law is
not smooth: a contact may stick, with a tangential force up to μN keeping v_t = 0. The
switch between the two is the business of the integrator (mechbook.numerics.friction),
which reads what a contact needs from `Contact`: v_t, its Jacobian ∂v_t/∂q̇ and the rest of
its time derivative, μ and N.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from mechbook.core.expansion import trig_canonical
from mechbook.model.attitude import rotation_matrix


@dataclass
class Contact:
    """One frictional contact of a system."""

    name: str
    normal: sp.Matrix  # the surface's unit normal (constant)
    mu: sp.Expr
    normal_force: sp.Expr
    tangential: sp.Matrix  # v_t (space components), linear in q̇
    jacobian: sp.Matrix  # ∂v_t/∂q̇ (rows: components, columns: coordinates)
    bias: sp.Matrix  # a_t − jacobian·q̈: the rest of dv_t/dt
    force: list  # the sliding law's generalized forces Q_k


def point_velocity(sys, body: str, point: sp.Matrix, sub: tuple) -> sp.Matrix:
    """The velocity of the body's material point now at `point`."""
    if body not in sys.positions:
        raise sys.error(sub + ("body",), f"no particle or rigid body {body!r}")
    r = sys.positions[body]
    if point.rows != r.rows:
        raise sys.error(sub + ("point",), f"the point has {point.rows} components, the "
                         f"body's position {r.rows}")
    v = sys.dt(r)
    bodies = sys.spec.get("rigid_bodies") or {}
    if body not in bodies:
        return v  # a particle: the point is the particle itself
    d = point - r
    if r.rows == 3:
        if sys.body_rates.get(body) is None:
            raise sys.error(sub + ("body",), f"{body!r} has no angular velocity")
        omega = sys.body_rates[body]
        if body in sys.attitudes:
            omega = rotation_matrix(sys.attitudes[body]) * omega  # space components
        return v + omega.cross(d)
    spec = bodies[body]
    if "angular_velocity" not in spec:
        raise sys.error(sub + ("body",), f"planar body {body!r} has no angular_velocity")
    w = sys.parse(spec["angular_velocity"], ("rigid_bodies", body, "angular_velocity"))
    return v + sp.Matrix([-w * d[1], w * d[0]])


def contacts(sys, specs: list) -> list[Contact]:
    """The frictional contacts of `friction:` (each one's sliding law as forces)."""
    out = []
    qdd = list(sys.qdd)
    for i, spec in enumerate(specs):
        sub = ("friction", i)
        point = sp.Matrix([sys.parse(x, sub + ("point", j)) for j, x in
                           enumerate(spec["point"])])
        v = point_velocity(sys, spec["body"], point, sub)
        if "normal" in spec:
            n = sp.Matrix([sys.parse(x, sub + ("normal", j))
                           for j, x in enumerate(spec["normal"])])
        else:
            n = sp.Matrix([0] * (v.rows - 1) + [1])
        if n.rows != v.rows or any(x.free_symbols & set(sys.q + sys.qd) for x in n):
            raise sys.error(sub + ("normal",), "the normal is a constant vector with as many "
                             "components as the position")
        n = n / sp.sqrt(n.dot(n))
        vt = (v - v.dot(n) * n).applyfunc(lambda e: trig_canonical(e, list(sys.qd)))
        mu = sys.parse(spec["mu"], sub + ("mu",))
        N = sys.parse(spec["normal_force"], sub + ("normal_force",))
        if N.has(*qdd) or mu.has(*qdd):
            raise sys.error(sub + ("normal_force",), "the normal force is a function of the "
                             "state (no accelerations)")
        J = vt.jacobian(sys.qd)
        acc = sys.dt(vt)
        bias = acc.subs({a: 0 for a in qdd})
        speed = sp.sqrt(vt.dot(vt))
        F = -mu * N * vt / speed
        force = [F.dot(J[:, k]) for k in range(len(sys.q))]
        out.append(Contact(spec.get("name", f"contact{i + 1}"), n, mu, N, vt, J, bias,
                           force))
    return out
