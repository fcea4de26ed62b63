"""A body made of parts: standard shapes, rods between two points, point masses, each with
its position and orientation in the body's axes; its mass, centre of mass and inertia.

The inertia tensor about a point P is the sum over the parts of each part's tensor about its
own centre of mass, turned into the body's axes (R·I·Rᵀ, or I⊥(1 − nn) + I∥ nn for a part
that gives only the direction n of its symmetry axis), plus the parallel-axis term
m(d²1 − dd) with d from P to the part's centre of mass (Symon Eq. 10-147). Everything stays
symbolic: the parts' masses, sizes and positions are expressions in the problem's parameters.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from mechbook.model.bodies.shapes import AXISYMMETRIC, shape_inertia


def rotation_matrix(axis: sp.Matrix, angle: sp.Expr) -> sp.Matrix:
    """The orthogonal tensor that turns vectors through `angle` about `axis` (right-hand
    sense), by Rodrigues' formula: cos a 1 + sin a [n]x + (1 - cos a) n n."""
    norm = sp.sqrt(axis.dot(axis))
    if norm == 0:
        raise ValueError("a rotation axis must not be the zero vector")
    n = axis / norm
    cross = sp.Matrix([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    return sp.cos(angle) * sp.eye(3) + sp.sin(angle) * cross + (1 - sp.cos(angle)) * n * n.T


def parallel_axis(m: sp.Expr, d: sp.Matrix) -> sp.Matrix:
    """m(d²1 − dd): the inertia of a point mass m at d about the origin."""
    return m * (d.dot(d) * sp.eye(3) - d * d.T)


@dataclass(frozen=True)
class Piece:
    """One part of a body: a standard shape of mass `mass` whose centre of mass is at
    `position` (body axes), its own axes turned by `rotation` (columns: its own x, y, z in
    body components) or, for an axisymmetric shape, its own z along `axis`."""

    label: str
    shape: str
    mass: sp.Expr
    dims: dict
    position: sp.Matrix
    rotation: sp.Matrix | None = None
    axis: sp.Matrix | None = None

    def own_inertia(self) -> sp.Matrix:
        return shape_inertia(self.shape, self.mass, self.dims)

    def inertia(self) -> sp.Matrix:
        """About the part's own centre of mass, in the body's axes."""
        own = self.own_inertia()
        if self.axis is not None:
            if self.shape not in AXISYMMETRIC:
                raise ValueError(f"a {self.shape} is not symmetric about an axis: give its "
                                 "orientation as a rotation")
            n = self.axis / sp.sqrt(self.axis.dot(self.axis))
            return own[0, 0] * (sp.eye(3) - n * n.T) + own[2, 2] * n * n.T
        if self.rotation is not None:
            return self.rotation * own * self.rotation.T
        return own


class CompositeBody:
    """A rigid body as a list of parts, in the body's own axes."""

    def __init__(self, name: str, pieces: list[Piece]):
        if not pieces:
            raise ValueError(f"body {name!r} has no parts")
        self.name = name
        self.pieces = list(pieces)

    @property
    def mass(self) -> sp.Expr:
        return sp.Add(*[p.mass for p in self.pieces])

    @property
    def center_of_mass(self) -> sp.Matrix:
        first = sp.zeros(3, 1)
        for p in self.pieces:
            first += p.mass * p.position
        return first / self.mass

    def inertia(self, point: sp.Matrix | None = None) -> sp.Matrix:
        """The inertia tensor about `point` (default: the centre of mass), body axes."""
        origin = self.center_of_mass if point is None else point
        total = sp.zeros(3, 3)
        for p in self.pieces:
            total += p.inertia() + parallel_axis(p.mass, p.position - origin)
        return total

    def moment(self, point: sp.Matrix, direction: sp.Matrix) -> sp.Expr:
        """The moment of inertia about the line through `point` along `direction`
        (Symon Eq. 10-143: n·I·n with n the unit vector of the line)."""
        norm2 = direction.dot(direction)
        if norm2 == 0:
            raise ValueError("a line's direction must not be the zero vector")
        return (direction.T * self.inertia(point) * direction)[0, 0] / norm2
