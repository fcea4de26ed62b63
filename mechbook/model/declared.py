"""What a problem declares besides its systems: named vectors, bodies made of parts, and
named tensors, built once per problem (in that order: a body may be placed with the
vectors, a tensor may use both).

    vectors:  {A: [5, -3, 2], n: "cross(A, B)"}          components, or an expression
    bodies:   {cone: {parts: [{shape: cone, mass: m, radius: a, height: h, apex: [0, 0, 0]}]}}
    tensors:  {T: "dyad(A, B) + dyad(B, A)", S: [[1, 0, 0], [0, 2, 0], [0, 0, 3]]}

A problem that declares only these (no coordinates) has no system: its answer parts are
tensor and body quantities (mechbook/verify/quantities/tensors.py, bodies.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from mechbook.core.numeval import is_zero
from mechbook.errors import ExpressionError
from mechbook.model.bodies import AXISYMMETRIC, CompositeBody, Piece, apex_offset
from mechbook.model.bodies.composite import rotation_matrix
from mechbook.model.problem import RESERVED, Problem
from mechbook.model.tensorexpr import kind, parse_tensor

TAKEN = RESERVED


@dataclass
class Declared:
    """The problem's names (parameters, vectors, tensors) and its bodies."""

    names: dict[str, sp.Basic] = field(default_factory=dict)
    bodies: dict[str, CompositeBody] = field(default_factory=dict)
    vectors: list[str] = field(default_factory=list)
    tensors: list[str] = field(default_factory=list)


def declared(problem: Problem) -> Declared:
    """The problem's declared vectors, bodies and tensors, built anew (model.built.Built
    builds them once and keeps them)."""
    data = problem.doc.data
    out = Declared(dict(problem.names()))
    taken = set(out.names) | TAKEN

    def claim(section: str, name: str) -> None:
        if name in taken:
            raise problem.doc.error((section, name), f"name {name!r} is already taken "
                                    "(parameter, reserved word, or another vector, tensor "
                                    "or body)")
        taken.add(name)

    for name, spec in (data.get("vectors") or {}).items():
        claim("vectors", name)
        out.names[name] = _object(problem, spec, ("vectors", name), out, "vector")
        out.vectors.append(name)
    for name, spec in (data.get("bodies") or {}).items():
        claim("bodies", name)
        out.bodies[name] = _body(problem, name, spec, out)
    for name, spec in (data.get("tensors") or {}).items():
        claim("tensors", name)
        out.names[name] = _object(problem, spec, ("tensors", name), out, "tensor")
        out.tensors.append(name)
    return out


def parse_at(problem: Problem, text, path: tuple, names: dict, bodies: dict | None = None):
    """A tensor expression at `path` of the problem file (errors name file and line)."""
    try:
        return parse_tensor(text, names, bodies or {})
    except ExpressionError as exc:
        raise problem.doc.error(path, str(exc)) from None


def _object(problem: Problem, spec, path: tuple, decl: Declared, want: str):
    """A vector or tensor given by its components (a list) or by an expression."""
    if isinstance(spec, list):
        if want == "vector":
            value = sp.ImmutableMatrix([parse_at(problem, x, path + (i,), decl.names)
                                        for i, x in enumerate(spec)])
        else:
            if len(spec) != 3 or any(not isinstance(r, list) or len(r) != 3 for r in spec):
                raise problem.doc.error(path, "a tensor's components are three rows of three")
            value = sp.ImmutableMatrix([[parse_at(problem, x, path + (i, j), decl.names)
                                         for j, x in enumerate(row)]
                                        for i, row in enumerate(spec)])
    else:
        value = parse_at(problem, spec, path, decl.names, decl.bodies)
    if kind(value) != want:
        raise problem.doc.error(path, f"expected a {want}, got a {kind(value)}")
    return value


def _vector(problem: Problem, spec, path: tuple, decl: Declared) -> sp.Matrix:
    return sp.Matrix(_object(problem, spec, path, decl, "vector"))


def _body(problem: Problem, name: str, spec: dict, decl: Declared) -> CompositeBody:
    pieces = []
    for i, part in enumerate(spec["parts"]):
        path = ("bodies", name, "parts", i)
        pieces.append(_piece(problem, part, path, decl))
    body = CompositeBody(name, pieces)
    if body.mass == 0:
        raise problem.doc.error(("bodies", name), "the body has no mass")
    return body


def _piece(problem: Problem, part: dict, path: tuple, decl: Declared) -> Piece:
    shape = part["shape"]
    label = f"{path[1]}.parts[{path[3]}] ({shape})"

    def scalar(key):
        return parse_at(problem, part[key], path + (key,), decl.names)

    mass = scalar("mass")
    dims = {k: scalar(k) for k in ("radius", "length", "height") if k in part}
    for key in ("sides", "semi_axes"):
        if key in part:
            dims[key] = [parse_at(problem, x, path + (key, i), decl.names)
                         for i, x in enumerate(part[key])]
    places = [k for k in ("position", "apex", "from") if k in part]
    if len(places) != 1:
        raise problem.doc.error(path, "place the part by one of 'position' (its centre of "
                                "mass), 'apex' (a cone) or 'from'/'to' (a rod)")
    axis = _vector(problem, part["axis"], path + ("axis",), decl) if "axis" in part else None
    rotation = None
    if "rotation" in part:
        if axis is not None:
            raise problem.doc.error(path + ("rotation",), "give either 'axis' or 'rotation'")
        rotation = _rotation(problem, part["rotation"], path + ("rotation",), decl)
    if "from" in part:
        if shape != "rod" or "to" not in part or "length" in part or axis is not None \
                or rotation is not None:
            raise problem.doc.error(path, "'from'/'to' place a rod (its length and axis "
                                    "follow from the two ends)")
        a = _vector(problem, part["from"], path + ("from",), decl)
        b = _vector(problem, part["to"], path + ("to",), decl)
        d = b - a
        if d == sp.zeros(3, 1):
            raise problem.doc.error(path + ("to",), "a rod's ends must differ")
        dims["length"] = sp.sqrt(d.dot(d))
        return _checked(problem, Piece(label, shape, mass, dims, (a + b) / 2, axis=d), path)
    if "to" in part:
        raise problem.doc.error(path + ("to",), "'to' goes with 'from'")
    if axis is not None and shape not in AXISYMMETRIC:
        raise problem.doc.error(path + ("axis",), f"a {shape} is not symmetric about an "
                                "axis: give its orientation as 'rotation'")
    if "apex" in part:
        if shape != "cone":
            raise problem.doc.error(path + ("apex",), "only a cone has an apex")
        apex = _vector(problem, part["apex"], path + ("apex",), decl)
        try:
            offset = apex_offset(shape, dims)
        except (ValueError, KeyError):
            raise problem.doc.error(path, "a cone needs 'radius' and 'height'") from None
        if rotation is not None:
            position = apex - rotation * offset
        elif axis is not None:  # the offset lies along the cone's own z axis
            position = apex - offset[2] * axis / sp.sqrt(axis.dot(axis))
        else:
            position = apex - offset
    else:
        position = _vector(problem, part["position"], path + ("position",), decl)
    return _checked(problem, Piece(label, shape, mass, dims, position, rotation, axis), path)


def _checked(problem: Problem, piece: Piece, path: tuple) -> Piece:
    try:
        piece.inertia()
    except ValueError as exc:
        raise problem.doc.error(path, str(exc)) from None
    return piece


def _rotation(problem: Problem, spec, path: tuple, decl: Declared) -> sp.Matrix:
    """{axis: [..], angle: expr} (Rodrigues), or an orthogonal tensor expression."""
    if isinstance(spec, dict):
        if set(spec) != {"axis", "angle"}:
            raise problem.doc.error(path, "a rotation is {axis: [x, y, z], angle: expr}")
        axis = _vector(problem, spec["axis"], path + ("axis",), decl)
        angle = parse_at(problem, spec["angle"], path + ("angle",), decl.names)
        try:
            return rotation_matrix(axis, angle)
        except ValueError as exc:
            raise problem.doc.error(path + ("axis",), str(exc)) from None
    value = sp.Matrix(_object(problem, spec, path, decl, "tensor"))

    if not all(is_zero(e) for e in value * value.T - sp.eye(3)) or not is_zero(value.det() - 1):
        raise problem.doc.error(path, "a part's rotation must be a proper orthogonal tensor "
                                "(R·Rᵀ = 1, det R = 1)")
    return value
