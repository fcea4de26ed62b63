"""The outline of each rigid body in the page's animation, turned as the body turns.

A body's shape (`inertia: {shape: ..., radius: ..., length: ...}`, its symmetry axis its own
z) gives its outline in its own axes: a rod its segment, a disk or ring its rim and axis,
a sphere its equator and a meridian, a block or plate its edges, a cone its base and apex,
an ellipsoid two principal sections. A 3-D body with an attitude (Euler angles or a chain of
rotations) is drawn through its rotation matrix R(q, t), body → space, at every frame; a
body with no shape given (an inertia tensor, a body made of parts) shows its three axes
instead. A planar body turns by the angle its `angular_velocity` is the rate of: where
that is a sum of coordinates' rates with constant coefficients (θ̇, or θ̇₁ + θ̇₂), the
angle is the same sum of the coordinates, and its outline (a plate's edges, a rod) turns
with it in the plane of the positions; otherwise (and for a body with no attitude in 3-D)
only an outline that does not depend on the angle is drawn (the rim of a disk, ring,
cylinder or sphere). The outlines are numbers in the body's axes; the script turns
them with R's two rows for the drawing plane.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.model.attitude import rotation_matrix

ROUND = ("disk", "ring", "solid_cylinder", "solid_sphere", "spherical_shell")
N = 24  # points of a circle


def _circle(a: float, b: float, plane: str = "xy", z: float = 0.0) -> list[list[float]]:
    t = np.linspace(0, 2 * np.pi, N + 1)
    pts = {"xy": lambda c, s: [a * c, b * s, z], "xz": lambda c, s: [a * c, z, b * s]}[plane]
    return [[float(v) for v in pts(c, s)] for c, s in zip(np.cos(t), np.sin(t), strict=True)]


def shape_lines(shape: str, dims: dict) -> list[list[list[float]]]:
    """Polylines of a shape's outline in its own axes (symmetry axis z), or [] for a
    point."""
    r, length = dims.get("radius", 0.0), dims.get("length", 0.0)
    if shape == "rod":
        return [[[0, 0, -length / 2], [0, 0, length / 2]]]
    if shape in ("disk", "ring", "solid_cylinder"):
        half = max(length / 2, r / 2)
        return [_circle(r, r), [[0, 0, -half], [0, 0, half]]]
    if shape in ("solid_sphere", "spherical_shell"):
        return [_circle(r, r), _circle(r, r, "xz")]
    if shape in ("rectangular_plate", "block"):
        x, y, z = ([*dims.get("sides", []), 0.0, 0.0, 0.0])[:3]
        return _box(x / 2, y / 2, z / 2)
    if shape == "cone":
        h = dims.get("height", 0.0)
        base = _circle(r, r, z=-h / 4)
        apex = [0.0, 0.0, 3 * h / 4]
        return [base] + [[base[k], apex] for k in range(0, N, N // 4)]
    if shape == "solid_ellipsoid":
        a, b, c = dims.get("semi_axes", [0.0, 0.0, 0.0])
        return [_circle(a, b), _circle(a, c, "xz")]
    return []


def _box(a: float, b: float, c: float) -> list[list[list[float]]]:
    square = [[-a, -b], [a, -b], [a, b], [-a, b], [-a, -b]]
    out = [[[x, y, -c] for x, y in square]]
    if c:
        out += [[[x, y, c] for x, y in square]]
        out += [[[x, y, -c], [x, y, c]] for x, y in square[:4]]
    return out


def _dims(sys, name: str, spec: dict, values: dict) -> tuple[str, dict] | None:
    """(shape, {dimension: number}) of a body declared with a shape, else None."""
    inertia = spec.get("inertia")
    if not isinstance(inertia, dict) or "shape" not in inertia:
        return None
    sub = ("rigid_bodies", name, "inertia")
    try:
        dims = {}
        for key, v in inertia.items():
            if key in ("radius", "length", "height"):
                dims[key] = float(sys.parse(v, sub + (key,)).xreplace(values))
            elif key in ("sides", "semi_axes"):
                dims[key] = [float(sys.parse(x, sub + (key, i)).xreplace(values))
                             for i, x in enumerate(v)]
    except (TypeError, ValueError, AttributeError):
        return None  # a dimension that is no number at the default values
    return str(inertia["shape"]), dims


def outline_specs(sys, names: list[str], values: dict) -> list[dict]:
    """For each body that can be drawn with an outline: {body index, lines (its own axes),
    turns (R to be compiled per frame, or None), triad (axes instead of a shape)}."""
    out = []
    bodies = sys.spec.get("rigid_bodies") or {}
    for name, spec in bodies.items():
        if name not in names or not isinstance(spec, dict):
            continue
        found = _dims(sys, name, spec, values)
        attitude = getattr(sys, "attitudes", {}).get(name)
        if attitude is not None:
            lines = shape_lines(*found) if found else []
            R = rotation_matrix(attitude).xreplace(values)
            out.append({"body": names.index(name), "lines": lines, "R": R,
                        "triad": not lines})
        elif found and (angle := planar_angle(sys, name, spec)) is not None:
            out.append({"body": names.index(name), "lines": shape_lines(*found),
                        "R": _about_z(angle).xreplace(values), "triad": False})
        elif found and found[0] in ROUND:  # its rim, whatever its angle
            r = found[1].get("radius", 0.0)
            out.append({"body": names.index(name), "lines": [_circle(r, r)], "R": None,
                        "triad": False})
    return out


def planar_angle(sys, name: str, spec: dict) -> sp.Expr | None:
    """The angle φ(q) whose rate is the planar body's `angular_velocity` (a scalar), where
    that rate is Σ cᵢ q̇ᵢ with constant cᵢ; None otherwise (or for a 3-D body)."""
    w = spec.get("angular_velocity")
    if w is None or isinstance(w, list):
        return None
    try:
        omega = sp.expand(sys.parse(w, ("rigid_bodies", name, "angular_velocity")))
    except Exception:  # noqa: BLE001 - the system was built from it; a drawing is optional
        return None
    coeffs = [omega.diff(v) for v in sys.qd]
    moving = set(sys.q) | set(sys.qd) | {sys.t}
    if any(c.free_symbols & moving for c in coeffs):
        return None
    if sp.expand(omega - sum(c * v for c, v in zip(coeffs, sys.qd, strict=True))) != 0:
        return None
    angle = sum((c * q for c, q in zip(coeffs, sys.q, strict=True)), sp.S.Zero)
    return angle if angle != 0 else None


def _about_z(angle: sp.Expr) -> sp.Matrix:
    """The rotation by `angle` in the x-y plane (a planar body's own axes → space)."""
    c, s = sp.cos(angle), sp.sin(angle)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def projected(R_frames: np.ndarray, axes: list[int]) -> list[list[float]]:
    """Per frame, R's rows for the drawing plane's two axes, flattened (6 numbers)."""
    return np.round(R_frames[:, axes, :].reshape(len(R_frames), 6), 5).tolist()


def triad(size: float) -> list[list[list[float]]]:
    """A body's own axes x, y, z from its centre."""
    return [[[0.0, 0.0, 0.0], [size, 0.0, 0.0]], [[0.0, 0.0, 0.0], [0.0, size, 0.0]],
            [[0.0, 0.0, 0.0], [0.0, 0.0, 1.5 * size]]]


def entries(sys_R) -> list[sp.Expr]:
    """R's nine entries, row by row, for the compiler."""
    return [sys_R[i, j] for i in range(3) for j in range(3)]
