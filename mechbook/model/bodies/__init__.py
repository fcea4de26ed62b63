"""Rigid bodies in the engine's own kinematics: the table of standard shapes' inertia,
bodies made of parts, and the kinetic energy of a moving body.

    shapes     inertia of the uniform standard shapes about their centre of mass
    composite  a body of parts (shapes, rods, point masses) placed and turned in its axes:
               mass, centre of mass, inertia about any point, moment about a line
    kinetic    T = M v²/2 + ω·I·ω/2, body rates from the attitude (Euler angles, or a
               chain of rotations: mechbook.model.attitude)

The Newton cross-check never imports this package (mechbook/crosscheck/kinematics.py
computes the same things another way).
"""

from mechbook.model.bodies.composite import CompositeBody, Piece, rotation_matrix
from mechbook.model.bodies.kinetic import body_kinetic, euler_body_rates
from mechbook.model.bodies.shapes import AXISYMMETRIC, SHAPES, apex_offset, shape_inertia

__all__ = ["AXISYMMETRIC", "SHAPES", "CompositeBody", "Piece", "apex_offset", "body_kinetic",
           "euler_body_rates", "rotation_matrix", "shape_inertia"]
