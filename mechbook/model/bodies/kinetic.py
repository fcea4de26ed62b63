"""The kinetic energy of a moving rigid body: translation of the centre of mass plus
rotation, with the angular velocity in body axes, or from the body's attitude: z-x-z Euler
angles (phi, theta, psi) or any chain of elementary rotations (mechbook.model.attitude)."""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp

from mechbook.model.attitude import body_rates, euler_chain


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
