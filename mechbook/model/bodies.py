"""Rigid bodies: inertia of standard shapes and the kinetic energy of a moving body.

Shapes have their symmetry axis along the body z axis. A planar body (2-D position) uses the
moment about the axis normal to the plane; a 3-D body uses the full tensor in body axes with
its angular velocity given in body axes or through its attitude: z-x-z Euler angles (phi,
theta, psi) or any chain of elementary rotations (mechbook.model.attitude).
"""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp

from mechbook.model.attitude import body_rates, euler_chain

SHAPES = ("point", "rod", "ring", "disk", "solid_cylinder", "solid_sphere", "spherical_shell",
          "rectangular_plate", "block")


def shape_inertia(shape: str, m: sp.Expr, dims: dict) -> sp.Matrix:
    """Principal inertia tensor about the centre of mass (symmetry axis = body z)."""
    r = dims.get("radius")
    length = dims.get("length", sp.S.Zero)
    need = {"ring": "radius", "disk": "radius", "solid_cylinder": "radius",
            "solid_sphere": "radius", "spherical_shell": "radius", "rod": "length",
            "rectangular_plate": "sides", "block": "sides"}
    if shape in need and need[shape] not in dims:
        raise ValueError(f"shape {shape!r} needs '{need[shape]}'")
    if shape == "point":
        a = b = c = sp.S.Zero
    elif shape == "rod":
        a = b = m * length**2 / 12
        c = sp.S.Zero
    elif shape == "ring":
        a = b = m * r**2 / 2
        c = m * r**2
    elif shape in ("disk", "solid_cylinder"):
        a = b = m * (3 * r**2 + length**2) / 12
        c = m * r**2 / 2
    elif shape == "solid_sphere":
        a = b = c = 2 * m * r**2 / 5
    elif shape == "spherical_shell":
        a = b = c = 2 * m * r**2 / 3
    elif shape in ("rectangular_plate", "block"):
        sides = list(dims["sides"]) + [sp.S.Zero] * 3
        x, y, z = sides[:3]
        if shape == "rectangular_plate" and len(dims["sides"]) != 2:
            raise ValueError("a rectangular plate has two sides")
        if shape == "block" and len(dims["sides"]) != 3:
            raise ValueError("a block has three sides")
        a, b, c = m * (y**2 + z**2) / 12, m * (x**2 + z**2) / 12, m * (x**2 + y**2) / 12
    else:  # pragma: no cover - the schema restricts shapes
        raise ValueError(f"unknown shape {shape!r}; known: {', '.join(SHAPES)}")
    return sp.diag(a, b, c)


def euler_body_rates(angles: list[sp.Expr], dt: Callable) -> sp.Matrix:
    """Body-axis angular velocity for z-x-z Euler angles (phi, theta, psi)."""
    return body_rates(euler_chain(angles), dt)


def body_kinetic(m: sp.Expr, v: sp.Matrix, inertia, omega, chain, dt: Callable) -> sp.Expr:
    """T = m v²/2 + ω·I·ω/2 (centre-of-mass velocity v; ω in body axes, given or from the
    attitude `chain` of elementary rotations)."""
    translational = m * v.dot(v) / 2
    planar = v.rows == 2
    if isinstance(inertia, sp.MatrixBase):
        if planar:
            inertia = inertia[2, 2]  # moment about the axis normal to the plane
    elif not planar:
        raise ValueError("a 3-D body needs a 3x3 inertia tensor or a shape")
    if planar:
        if chain is not None:
            raise ValueError("a planar body takes a scalar angular_velocity, not an attitude")
        if omega is None or isinstance(omega, sp.MatrixBase):
            raise ValueError("a planar body needs a scalar 'angular_velocity'")
        return translational + inertia * omega**2 / 2
    if chain is not None and omega is not None:
        raise ValueError("give either 'angular_velocity' or an attitude ('euler_angles' or "
                         "'rotation'), not both")
    if chain is not None:
        omega = body_rates(chain, dt)
    if omega is None or not isinstance(omega, sp.MatrixBase) or omega.rows != 3:
        raise ValueError("a 3-D body needs a 3-vector 'angular_velocity', 'euler_angles' or "
                         "'rotation'")
    return translational + (omega.T * inertia * omega)[0, 0] / 2
