"""Attitude kinematics: a body's orientation as a chain of elementary rotations.

A chart is a list of rotations [(axis, angle), ...] about the body's own x, y or z axis,
applied in order (intrinsic): R = R_axis1(angle1) · R_axis2(angle2) · …, which carries
body components into space components. Symon's z-x-z Euler angles (phi, theta, psi) are
the chain [(z, phi), (x, theta), (z, psi)]; a chain such as [(x, a), (y, b), (z, c)]
(Cardan / Tait–Bryan angles) is regular where z-x-z is singular (the body's 3-axis along
space z: a sleeping top), and constant or time-dependent angles describe moving mounts
(a gyrocompass on the rotating earth).

The angular velocity is the sum of the elementary rotations' rates (angular velocities
add, Symon §11-4): ω = Σ_k q̇_k (R_{k+1}·…·R_n)ᵀ e_{axis_k} in body components. The
cross-check derives the same from Rᵀ·dR/dt instead (mechbook.crosscheck.kinematics).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import sympy as sp

AXES = ("x", "y", "z")
EULER_ZXZ = ("z", "x", "z")


def elementary(axis: str, angle: sp.Expr) -> sp.Matrix:
    """The rotation by `angle` about the x, y or z axis (active, right-handed)."""
    c, s = sp.cos(angle), sp.sin(angle)
    if axis == "x":
        return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "y":
        return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    if axis == "z":
        return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    raise ValueError(f"unknown rotation axis {axis!r}; use x, y or z")


def unit(axis: str) -> sp.Matrix:
    return sp.Matrix([1 if a == axis else 0 for a in AXES])


def rotation_matrix(chain: Sequence[tuple[str, sp.Expr]]) -> sp.Matrix:
    """R (body components -> space components) of a chain of rotations."""
    R = sp.eye(3)
    for axis, angle in chain:
        R = R * elementary(axis, angle)
    return R


def body_rates(chain: Sequence[tuple[str, sp.Expr]], dt: Callable) -> sp.Matrix:
    """Body-axis components of ω: Σ_k (d angle_k/dt) (R_{k+1}…R_n)ᵀ e_{axis_k}."""
    omega = sp.zeros(3, 1)
    tail = sp.eye(3)  # R_{k+1}…R_n, built from the last rotation backwards
    for axis, angle in reversed(list(chain)):
        rate = dt(angle)
        if rate != 0:
            omega += rate * (tail.T * unit(axis))
        tail = elementary(axis, angle) * tail
    return omega.applyfunc(sp.expand)


def euler_chain(angles: Sequence[sp.Expr]) -> list[tuple[str, sp.Expr]]:
    """Symon's z-x-z Euler angles (phi, theta, psi) as a chain."""
    return list(zip(EULER_ZXZ, angles, strict=True))
