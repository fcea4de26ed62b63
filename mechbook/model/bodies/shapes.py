"""Inertia of the standard uniform shapes about their centre of mass, from the table of
closed forms (the Newton cross-check integrates over the shapes instead:
mechbook/crosscheck/kinematics.py).

Every shape has its own axes: the symmetry axis is body z, the centre of mass at the origin.
A cone's apex lies on its axis at 3h/4 below the centre of mass (the axis points from the
apex to the base); a solid ellipsoid has semi-axes a, b, c along its own x, y, z.
"""

from __future__ import annotations

import sympy as sp

SHAPES = ("point", "rod", "ring", "disk", "solid_cylinder", "solid_sphere", "spherical_shell",
          "rectangular_plate", "block", "cone", "solid_ellipsoid")
# shapes whose inertia tensor is unchanged by a turn about their own z axis: for them a part
# may give only the direction of that axis
AXISYMMETRIC = ("point", "rod", "ring", "disk", "solid_cylinder", "solid_sphere",
                "spherical_shell", "cone")
NEEDS = {"ring": ("radius",), "disk": ("radius",), "solid_cylinder": ("radius",),
         "solid_sphere": ("radius",), "spherical_shell": ("radius",), "rod": ("length",),
         "rectangular_plate": ("sides",), "block": ("sides",), "cone": ("radius", "height"),
         "solid_ellipsoid": ("semi_axes",)}
COUNTS = {"rectangular_plate": ("sides", 2), "block": ("sides", 3),
          "solid_ellipsoid": ("semi_axes", 3)}


def shape_inertia(shape: str, m: sp.Expr, dims: dict) -> sp.Matrix:
    """Principal inertia tensor about the centre of mass (symmetry axis = own z)."""
    for need in NEEDS.get(shape, ()):
        if need not in dims:
            raise ValueError(f"shape {shape!r} needs '{need}'")
    if shape in COUNTS:
        key, count = COUNTS[shape]
        if len(dims[key]) != count:
            words = {2: "two", 3: "three"}
            raise ValueError(f"a {shape.replace('_', ' ')} has {words[count]} "
                             f"{key.replace('_', ' ')}")
    r = dims.get("radius")
    length = dims.get("length", sp.S.Zero)
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
        x, y, z = (list(dims["sides"]) + [sp.S.Zero])[:3]
        a, b, c = m * (y**2 + z**2) / 12, m * (x**2 + z**2) / 12, m * (x**2 + y**2) / 12
    elif shape == "cone":  # solid, base radius r, height h, about its centre of mass
        h = dims["height"]
        a = b = 3 * m * (4 * r**2 + h**2) / 80
        c = 3 * m * r**2 / 10
    elif shape == "solid_ellipsoid":
        x, y, z = dims["semi_axes"]
        a, b, c = m * (y**2 + z**2) / 5, m * (x**2 + z**2) / 5, m * (x**2 + y**2) / 5
    else:  # pragma: no cover - the schema restricts shapes
        raise ValueError(f"unknown shape {shape!r}; known: {', '.join(SHAPES)}")
    return sp.diag(a, b, c)


def apex_offset(shape: str, dims: dict) -> sp.Matrix:
    """Where a cone's apex is, from its centre of mass, in the cone's own axes."""
    if shape != "cone":
        raise ValueError(f"only a cone has an apex, not a {shape}")
    return sp.Matrix([0, 0, -3 * dims["height"] / 4])
