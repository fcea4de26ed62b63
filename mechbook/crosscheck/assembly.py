"""A body made of parts, assembled independently of the engine's mechbook.model.bodies.

The engine adds each part's tabulated inertia, turned by Rodrigues' formula (or written
I⊥(1 − nn) + I∥ nn for a part given by its symmetry axis), and shifted by the
parallel-axis theorem. Here the problem file's `bodies:` entry is read again and each part
contributes its second moment ∫ρ r rᵀ, integrated over the shape in its own
parametrization (mechbook.crosscheck.kinematics), turned by a rotation built another way (a
unit quaternion for an axis and angle; an orthonormal frame by Gram–Schmidt for a symmetry
axis), and moved by m p pᵀ; the body's second moment S about its centre of mass gives
I = tr(S)·1 − S. A cone placed by its apex finds its centre of mass by integration too.
"""

from __future__ import annotations

import sympy as sp

from mechbook.crosscheck.kinematics import cone_apex_to_centre, inertia_of_shape
from mechbook.errors import NotFoundError
from mechbook.model.problem import Problem
from mechbook.model.tensorexpr import parse_tensor


def _names(problem: Problem) -> dict:
    """Parameters and declared vectors (read again from the file)."""
    names = dict(problem.names())
    for name, spec in (problem.doc.data.get("vectors") or {}).items():
        names[name] = _vec(problem, spec, ("vectors", name), names)
    return names


def _vec(problem: Problem, spec, path: tuple, names: dict) -> sp.Matrix:
    if isinstance(spec, list):
        return sp.Matrix([problem.parse(x, path + (i,), names) for i, x in enumerate(spec)])
    return sp.Matrix(parse_tensor(spec, names))


def _quaternion_rotation(axis: sp.Matrix, angle: sp.Expr) -> sp.Matrix:
    """The rotation of the unit quaternion (cos a/2, n sin a/2)."""
    n = axis / sp.sqrt(axis.dot(axis))
    w, x, y, z = sp.cos(angle / 2), *(n * sp.sin(angle / 2))
    return sp.Matrix([
        [1 - 2 * (y**2 + z**2), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x**2 + z**2), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x**2 + y**2)]])


def _frame_along(axis: sp.Matrix, values: dict) -> sp.Matrix:
    """Columns e1, e2, e3 with e3 along `axis`: Gram–Schmidt from the coordinate axis least
    aligned with it (judged at the default parameter values)."""
    e3 = axis / sp.sqrt(axis.dot(axis))
    sizes = [abs(complex(sp.N(c.subs(values)))) for c in e3]
    helper = sp.Matrix([1 if k == sizes.index(min(sizes)) else 0 for k in range(3)])
    e1 = helper - helper.dot(e3) * e3
    e1 = e1 / sp.sqrt(e1.dot(e1))
    e2 = e3.cross(e1)
    return sp.Matrix.hstack(e1, e2, e3)


def composite_inertia(problem: Problem, body: str) -> tuple[sp.Expr, sp.Matrix, sp.Matrix]:
    """(mass, centre of mass, inertia tensor about it) of a declared body, in its axes."""
    spec = (problem.doc.data.get("bodies") or {}).get(body)
    if spec is None:
        raise NotFoundError(f"no body {body!r} declared (declared: "
                            f"{', '.join(problem.doc.data.get('bodies') or {}) or 'none'})")
    names = _names(problem)
    values = problem.values()
    total_m, first, second = sp.S.Zero, sp.zeros(3, 1), sp.zeros(3, 3)
    for i, part in enumerate(spec["parts"]):
        path = ("bodies", body, "parts", i)

        def scalar(key, path=path, part=part):
            return problem.parse(part[key], path + (key,), names)

        m = scalar("mass")
        dims = {k: scalar(k) for k in ("radius", "length", "height") if k in part}
        for key in ("sides", "semi_axes"):
            if key in part:
                dims[key] = [problem.parse(x, path + (key, j), names)
                             for j, x in enumerate(part[key])]
        frame = sp.eye(3)
        if "from" in part:
            a = _vec(problem, part["from"], path + ("from",), names)
            b = _vec(problem, part["to"], path + ("to",), names)
            dims["length"] = sp.sqrt((b - a).dot(b - a))
            frame = _frame_along(b - a, values)
            centre = (a + b) / 2
        else:
            if "axis" in part:
                frame = _frame_along(_vec(problem, part["axis"], path + ("axis",), names),
                                     values)
            elif isinstance(part.get("rotation"), dict):
                rot = part["rotation"]
                frame = _quaternion_rotation(
                    _vec(problem, rot["axis"], path + ("rotation", "axis"), names),
                    problem.parse(rot["angle"], path + ("rotation", "angle"), names))
            elif "rotation" in part:
                rot = part["rotation"]
                frame = (sp.Matrix(parse_tensor(rot, names)) if isinstance(rot, str) else
                         sp.Matrix([[problem.parse(x, path + ("rotation", r, c), names)
                                     for c, x in enumerate(row)] for r, row in enumerate(rot)]))
            if "apex" in part:
                along = frame[:, 2] * cone_apex_to_centre(dims["height"])
                centre = _vec(problem, part["apex"], path + ("apex",), names) + along
            else:
                centre = _vec(problem, part["position"], path + ("position",), names)
        own = inertia_of_shape(part["shape"], m, dims)
        own_second = own.trace() / 2 * sp.eye(3) - own  # S = tr(I)/2·1 − I
        total_m += m
        first += m * centre
        second += frame * own_second * frame.T + m * centre * centre.T
    com = first / total_m
    second_cm = second - total_m * com * com.T
    return total_m, com, second_cm.trace() * sp.eye(3) - second_cm
