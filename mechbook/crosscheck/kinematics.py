"""Rigid-body kinematics for the Newton cross-check, computed independently of the engine.

The engine (mechbook.model.bodies) writes a body's angular velocity with the closed formula
for z-x-z Euler angles and takes inertia tensors from a table of standard shapes. Here both
are obtained another way, so that an error in either cannot pass the cross-check:

* the angular velocity from the rotation itself: R = Rz(φ)·Rx(θ)·Rz(ψ) (or the product of
  a body's chain of elementary rotations) carries body axes into space axes, and the body
  components of ω are read off the antisymmetric matrix Rᵀ·dR/dt;
* an inertia tensor by integrating ρ(|r|²·1 − r rᵀ) over the shape with uniform density
  (line, surface or volume integrals in the shape's own parametrization).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache

import sympy as sp

from mechbook.core.integrals import box_integral

# generic dimensions, substituted by the body's own after integration
_M, _R, _L = sp.symbols("M_ R_ L_", positive=True)
_A, _B, _C = sp.symbols("A_ B_ C_", positive=True)


def _rz(a: sp.Expr) -> sp.Matrix:
    return sp.Matrix([[sp.cos(a), -sp.sin(a), 0], [sp.sin(a), sp.cos(a), 0], [0, 0, 1]])


def _rx(a: sp.Expr) -> sp.Matrix:
    return sp.Matrix([[1, 0, 0], [0, sp.cos(a), -sp.sin(a)], [0, sp.sin(a), sp.cos(a)]])


def _ry(a: sp.Expr) -> sp.Matrix:
    return sp.Matrix([[sp.cos(a), 0, sp.sin(a)], [0, 1, 0], [-sp.sin(a), 0, sp.cos(a)]])


_ELEMENTARY = {"x": _rx, "y": _ry, "z": _rz}


def chain_matrix(chain: list[tuple[str, sp.Expr]]) -> sp.Matrix:
    """R = R_1·R_2·… of a chain of (axis, angle) rotations about body axes."""
    R = sp.eye(3)
    for axis, angle in chain:
        R = R * _ELEMENTARY[axis](angle)
    return R


def chain_angular_velocity(chain: list[tuple[str, sp.Expr]], dt: Callable) -> sp.Matrix:
    """Body-axis components of ω for a chain of rotations: vee(Rᵀ Ṙ)."""
    R = chain_matrix(chain)
    W = R.T * R.applyfunc(dt)
    return sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])


def body_angular_velocity(angles: list[sp.Expr], dt: Callable) -> sp.Matrix:
    """Body-axis components of ω for z-x-z Euler angles (φ, θ, ψ): vee(Rᵀ Ṙ)."""
    phi, theta, psi = angles
    R = _rz(phi) * _rx(theta) * _rz(psi)
    W = R.T * R.applyfunc(dt)
    return sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])


def _tensor(r: sp.Matrix) -> sp.Matrix:
    return r.dot(r) * sp.eye(3) - r * r.T


def _integrate(density: sp.Expr, r: sp.Matrix, *ranges) -> sp.Matrix:
    known: dict = {}  # the entries share most of their one-variable integrals
    return (density * _tensor(r)).applyfunc(lambda e: box_integral(e, ranges, known))



def _moments(density: sp.Expr, r: sp.Matrix, *ranges) -> tuple[sp.Expr, sp.Matrix, sp.Matrix]:
    """Mass, first moment ∫ρ r and second moment ∫ρ r rᵀ over a parametrized shape."""
    def integral(e):
        return sp.integrate(sp.expand(e), *ranges)

    return integral(density), (density * r).applyfunc(integral), \
        (density * r * r.T).applyfunc(integral)


@cache
def _generic(shape: str) -> sp.Matrix:
    """Inertia about the centre of mass, symmetry axis z, in the generic dimensions."""
    u, v, w = sp.symbols("u v w", real=True)
    if shape == "point":
        return sp.zeros(3, 3)
    if shape == "rod":  # a line of length L along z
        return _integrate(_M / _L, sp.Matrix([0, 0, u]), (u, -_L / 2, _L / 2))
    if shape == "ring":  # a circle of radius R in the xy-plane
        r = sp.Matrix([_R * sp.cos(u), _R * sp.sin(u), 0])
        return _integrate(_M / (2 * sp.pi), r, (u, 0, 2 * sp.pi))
    if shape == "cylinder":  # solid, radius R, length L along z; area element s ds dφ dz
        r = sp.Matrix([u * sp.cos(v), u * sp.sin(v), w])
        rho = _M / (sp.pi * _R**2 * _L)
        return _integrate(rho * u, r, (u, 0, _R), (v, 0, 2 * sp.pi), (w, -_L / 2, _L / 2))
    if shape == "disk_thin":  # radius R in the xy-plane
        r = sp.Matrix([u * sp.cos(v), u * sp.sin(v), 0])
        return _integrate(_M / (sp.pi * _R**2) * u, r, (u, 0, _R), (v, 0, 2 * sp.pi))
    if shape in ("solid_sphere", "spherical_shell"):  # polar angle v, azimuth w
        if shape == "solid_sphere":
            r = sp.Matrix([u * sp.sin(v) * sp.cos(w), u * sp.sin(v) * sp.sin(w),
                           u * sp.cos(v)])
            rho = _M / (sp.Rational(4, 3) * sp.pi * _R**3) * u**2 * sp.sin(v)
            return _integrate(rho, r, (u, 0, _R), (v, 0, sp.pi), (w, 0, 2 * sp.pi))
        r = sp.Matrix([_R * sp.sin(v) * sp.cos(w), _R * sp.sin(v) * sp.sin(w),
                       _R * sp.cos(v)])
        return _integrate(_M / (4 * sp.pi) * sp.sin(v), r, (v, 0, sp.pi), (w, 0, 2 * sp.pi))
    if shape == "rectangular_plate":  # sides A (x) and B (y)
        r = sp.Matrix([u, v, 0])
        return _integrate(_M / (_A * _B), r, (u, -_A / 2, _A / 2), (v, -_B / 2, _B / 2))
    if shape == "block":  # sides A, B, C
        r = sp.Matrix([u, v, w])
        return _integrate(_M / (_A * _B * _C), r, (u, -_A / 2, _A / 2), (v, -_B / 2, _B / 2),
                          (w, -_C / 2, _C / 2))
    if shape == "cone":  # apex at the origin, axis z, base radius R at height L
        mass, first, second = _cone_moments()
        c = first / mass  # the centre of mass, found by the integral too
        second_cm = second - mass * c * c.T
        return second_cm.trace() * sp.eye(3) - second_cm
    if shape == "solid_ellipsoid":  # semi-axes A, B, C; u radial, v polar, w azimuth
        r = sp.Matrix([_A * u * sp.sin(v) * sp.cos(w), _B * u * sp.sin(v) * sp.sin(w),
                       _C * u * sp.cos(v)])
        rho = 3 * _M / (4 * sp.pi) * u**2 * sp.sin(v)  # density times the Jacobian ABC u² sin v
        return _integrate(rho, r, (u, 0, 1), (v, 0, sp.pi), (w, 0, 2 * sp.pi))
    raise ValueError(f"no integral for the shape {shape!r}")


@cache
def _cone_moments() -> tuple[sp.Expr, sp.Matrix, sp.Matrix]:
    """A uniform solid cone, apex at the origin, axis z, height L, base radius R."""
    s, phi, z = sp.symbols("s phi z", nonnegative=True)
    r = sp.Matrix([s * sp.cos(phi), s * sp.sin(phi), z])
    rho = _M / (sp.pi * _R**2 * _L / 3) * s
    return _moments(rho, r, (s, 0, _R * z / _L), (phi, 0, 2 * sp.pi), (z, 0, _L))


def cone_apex_to_centre(height: sp.Expr) -> sp.Expr:
    """How far a uniform cone's centre of mass lies from its apex, along the axis (by
    integration)."""
    mass, first, _ = _cone_moments()
    return (first[2] / mass).xreplace({_L: height})


def inertia_of_shape(shape: str, m: sp.Expr, dims: dict) -> sp.Matrix:
    """Inertia tensor of a uniform standard shape about its centre, symmetry axis z, by
    integration. `dims`: radius, length, or sides, as the problem file gives them."""
    sub = {_M: m}
    if shape in ("disk", "solid_cylinder"):
        length = dims.get("length", sp.S.Zero)
        sub.update({_R: dims["radius"]})
        if length == 0:
            return _generic("disk_thin").xreplace(sub)
        sub[_L] = length
        return _generic("cylinder").xreplace(sub)
    if "radius" in dims:
        sub[_R] = dims["radius"]
    if "length" in dims:
        sub[_L] = dims["length"]
    if "height" in dims:
        sub[_L] = dims["height"]
    if "sides" in dims:
        sub.update(dict(zip((_A, _B, _C), dims["sides"], strict=False)))
    if "semi_axes" in dims:
        sub.update(dict(zip((_A, _B, _C), dims["semi_axes"], strict=True)))
    return _generic(shape).xreplace(sub)
