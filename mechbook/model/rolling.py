"""Velocity constraints and rolling without slipping: the system keys `velocity_constraints:`
and `rolling:`.

    velocity_constraints:
      - {name: blade, expr: "-xdot*sin(phi) + ydot*cos(phi)"}   # A(q, t)·q̇ + b(q, t) = 0
    rolling:
      - name: contact
        body: coin                  # a rigid body
        point: [x, y, 0]            # optional: the contact point in space (functions of q)
        surface: {normal: [0, 0, 1], velocity: ["-Omega*y", "Omega*x", 0]}  # optional

A velocity constraint is linear in the velocities, c(q, q̇, t) = A(q, t)·q̇ + b(q, t) = 0,
and kept with a multiplier `lambda_<name>`: the generalized force it exerts is Aᵀλ, as a
holonomic constraint's is (mechbook.engine.lagrange). It need not come from a constraint
on the positions: a skate's blade, a wheel that does not slip.

Rolling without slipping says that the body's material point at the contact moves with the
surface there: v_G + ω × (P − r_G) = v_surface(P) (mechbook.model.friction.point_velocity
computes the left side, as it does for sliding friction). Its components along the surface
are velocity constraints — two on a surface in space (along t1, t2: t1 the first coordinate
axis not along the normal, made orthogonal to it, t2 = n × t1), one in a plane (t = the
normal turned by −90°) — whose multipliers `lambda_<name>_1`, `lambda_<name>_2` (in a
plane: `lambda_<name>`) are the friction force that rolling needs, in those directions.
The component along the normal is not a constraint of its own: the coordinates must keep
the body on the surface (the disk's height a function of its tilt), which is checked on
random states of the constraint manifold.

The contact point comes from `point:`, or from the body's shape: a sphere (`solid_sphere`,
`spherical_shell`) touches a plane at r_G − R·n; a disk, ring or cylinder (symmetry axis e,
its own z) at r_G − R·u, u the unit vector of n − (n·e)e (the rim's lowest point); a planar
body of radius R at r_G − R·n. A body with neither (its inertia given as numbers, or no
attitude to find its axis by) is refused with the fix.
"""

from __future__ import annotations

import sympy as sp

from mechbook.core.expansion import trig_canonical
from mechbook.core.numeval import is_zero
from mechbook.model.attitude import rotation_matrix
from mechbook.model.friction import point_velocity

ROUND = ("solid_sphere", "spherical_shell")  # touch a plane below their centre
RIMMED = ("disk", "ring", "solid_cylinder")  # touch it at the lowest point of the rim


def velocity_constraints(sys) -> list[tuple[str, sp.Expr]]:
    """The system's velocity constraints, from `velocity_constraints:` and `rolling:`, as
    (name of the multiplier's constraint, c(q, q̇, t)); each refused at its line when it is
    not linear in the velocities, holds no velocity, or names a taken multiplier."""
    out: list[tuple[str, sp.Expr, tuple]] = []
    for i, spec in enumerate(sys.spec.get("velocity_constraints") or []):
        sub = ("velocity_constraints", i)
        out.append((spec["name"], sys.parse(spec["expr"], sub + ("expr",)), sub + ("expr",)))
    for i, spec in enumerate(sys.spec.get("rolling") or []):
        sub = ("rolling", i)
        out += [(name, c, sub) for name, c in _rolling(sys, spec, sub)]
    taken = {name for name, _ in sys.constraints}
    for name, c, sub in out:
        _linear_in_velocities(sys, name, c, sub)
        if name in taken:
            raise sys.error(sub, f"a constraint named {name!r} is already declared: each "
                             "constraint (and its multiplier lambda_<name>) needs its own name")
        taken.add(name)
        if f"lambda_{name}" in sys.names:
            raise sys.error(sub, f"constraint {name!r} has the multiplier lambda_{name}, which "
                             f"is already a name here: rename the constraint or lambda_{name}")
    return [(name, c) for name, c, _ in out]


def _linear_in_velocities(sys, name: str, c: sp.Expr, sub: tuple) -> None:
    if c.free_symbols & set(sys.qdd):
        raise sys.error(sub, f"velocity constraint {name!r} holds an acceleration: it is "
                         "A(q, t)·q̇ + b(q, t) = 0")
    if not c.free_symbols & set(sys.qd):
        raise sys.error(sub, f"velocity constraint {name!r} holds no velocity: a relation "
                         "among the coordinates is a holonomic constraint (`constraints:`)")
    # linear means a polynomial of degree one in the velocities: a velocity inside a
    # function or a non-integer power (Abs(xdot), sign(xdot)*xdot, sqrt(xdot**2)) is not,
    # though its second derivatives vanish wherever they are defined
    inside = _velocity_inside(c, set(sys.qd))
    poly = None if inside is not None else _poly(c, sys.qd)
    if poly is None:
        where = f" ({sp.sstr(inside)[:80]})" if inside is not None else ""
        raise sys.error(sub, f"velocity constraint {name!r} is not linear in the velocities: "
                         f"a velocity appears inside a function or a power{where}; it must "
                         "read A(q, t)·q̇ + b(q, t) = 0")
    for powers, coeff in poly.terms():
        if sum(powers) > 1 and not _vanishes(coeff):  # Poly.terms(): SymPy coefficients
            term = sp.Mul(*[v**k for v, k in zip(sys.qd, powers, strict=True)])
            raise sys.error(sub, f"velocity constraint {name!r} is not linear in the "
                             f"velocities (it holds {sp.sstr(term)} times "
                             f"{sp.sstr(coeff)[:80]}): it must read A(q, t)·q̇ + b(q, t) = 0")


_NOT_SMOOTH = (sp.Abs, sp.sign, sp.Piecewise, sp.Heaviside, sp.Min, sp.Max, sp.floor,
               sp.ceiling, sp.re, sp.im, sp.DiracDelta)


def _velocity_inside(c: sp.Expr, velocities: set) -> sp.Expr | None:
    """The first node of `c` that holds a velocity inside something no linear expression
    has: a function (Abs, sign, sin, ...) or a power other than a positive integer."""
    for node in sp.preorder_traversal(c):
        if not (isinstance(node, sp.Basic) and node.free_symbols & velocities):
            continue
        if isinstance(node, sp.Pow) and not (node.exp.is_Integer and node.exp > 0):
            return node
        if isinstance(node, (sp.Function, *_NOT_SMOOTH)):
            return node
    return None


def _poly(c: sp.Expr, velocities: list):
    try:
        return sp.Poly(sp.expand(c), *velocities)
    except (sp.PolynomialError, sp.GeneratorsNeeded, ValueError, TypeError):
        return None


def _vanishes(expr: sp.Expr) -> bool:
    try:
        return is_zero(expr)
    except Exception:  # noqa: BLE001 - an expression that does not evaluate is not zero
        return False


def _vector(sys, texts: list, sub: tuple) -> sp.Matrix:
    return sp.Matrix([sys.parse(x, sub + (j,)) for j, x in enumerate(texts)])


def _rolling(sys, spec: dict, sub: tuple) -> list[tuple[str, sp.Expr]]:
    """The tangential components of the contact point's velocity relative to the surface."""
    v, n = relative_velocity(sys, spec, sub)
    rows = [trig_canonical(sp.expand(v.dot(t)), list(sys.qd)) for t in _tangents(n)]
    name = spec["name"]
    if len(rows) == 1:
        return [(name, rows[0])]
    return [(f"{name}_{k + 1}", r) for k, r in enumerate(rows)]


def relative_velocity(sys, spec: dict, sub: tuple) -> tuple[sp.Matrix, sp.Matrix]:
    """(v, n): the velocity of the body's material point at the contact relative to the
    surface there, and the surface's unit normal. v·n vanishes along every motion when the
    coordinates keep the body on the surface (checked where the system is validated)."""
    body = spec["body"]
    bodies = sys.spec.get("rigid_bodies") or {}
    if body not in sys.positions:
        raise sys.error(sub + ("body",), f"no rigid body {body!r} to roll")
    if body not in bodies:
        raise sys.error(sub + ("body",), f"{body!r} is a particle: a particle has no surface "
                         "to roll on (rolling needs a rigid body; a particle that does not "
                         "slide is a velocity constraint on its own)")
    dim = sys.positions[body].rows
    surface = spec.get("surface") or {}
    if "normal" in surface:
        n = _vector(sys, surface["normal"], sub + ("surface", "normal"))
    else:
        n = sp.Matrix([0] * (dim - 1) + [1])
    if n.rows != dim or any(x.free_symbols & set(sys.q + sys.qd + [sys.t]) for x in n):
        raise sys.error(sub + ("surface", "normal"), f"the surface's normal is a constant "
                         f"vector with {dim} components (as many as the body's position)")
    size = sp.sqrt(n.dot(n))
    if size == 0:
        raise sys.error(sub + ("surface", "normal"), "the surface's normal is zero")
    n = n / size
    point = (_vector(sys, spec["point"], sub + ("point",)) if "point" in spec
             else _contact_from_shape(sys, body, bodies[body], n, sub))
    if point.rows != dim:
        raise sys.error(sub + ("point",), f"the contact point has {point.rows} components, "
                         f"the body's position {dim}")
    v = point_velocity(sys, body, point, sub)
    if "velocity" in surface:
        moving = _vector(sys, surface["velocity"], sub + ("surface", "velocity"))
        if moving.rows != dim:
            raise sys.error(sub + ("surface", "velocity"), f"the surface's velocity has "
                             f"{moving.rows} components, the body's position {dim}")
        v = v - moving
    return v, n


def _tangents(n: sp.Matrix) -> list[sp.Matrix]:
    """An orthonormal basis of the plane normal to the unit vector n (constant)."""
    if n.rows == 2:
        return [sp.Matrix([n[1], -n[0]])]
    axes = [sp.Matrix([1 if i == k else 0 for i in range(3)]) for k in range(3)]
    for e in axes:
        w = e - e.dot(n) * n
        size = sp.sqrt(sp.nsimplify(w.dot(w)))
        if size != 0 and sp.N(size) > 1e-3:
            t1 = (w / size).applyfunc(sp.nsimplify)
            t2 = n.cross(t1).applyfunc(sp.nsimplify)
            return [t1, t2]
    raise ValueError("no tangent to a zero normal")  # pragma: no cover - n is a unit vector


def _contact_from_shape(sys, body: str, spec: dict, n: sp.Matrix, sub: tuple) -> sp.Matrix:
    """The contact point with a plane of normal n, from the body's declared shape."""
    inertia = spec.get("inertia")
    shape = inertia.get("shape") if isinstance(inertia, dict) else None
    fix = ("give the contact `point:` (where the body touches, in space), or declare the "
           "body's shape (inertia: {shape: disk, ring, solid_cylinder, solid_sphere or "
           "spherical_shell, radius: ...})")
    if shape not in ROUND + RIMMED or "radius" not in inertia:
        what = f"a {shape}" if shape else "its inertia as numbers"
        raise sys.error(sub + ("body",), f"rolling body {body!r} declares no surface to roll "
                         f"on ({what}): {fix}")
    radius = sys.parse(inertia["radius"], ("rigid_bodies", body, "inertia", "radius"))
    r = sys.positions[body]
    if shape in ROUND or r.rows == 2:
        return r - radius * n
    if body not in sys.attitudes:
        raise sys.error(sub + ("body",), f"rolling body {body!r} has no attitude (euler_angles "
                         f"or rotation) to find its rim by: {fix}")
    e = rotation_matrix(sys.attitudes[body]) * sp.Matrix([0, 0, 1])
    w = n - n.dot(e) * e
    return r - radius * w / sp.sqrt(w.dot(w))
