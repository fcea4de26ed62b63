"""Tensors and vectors, with or without a system: components (in other axes too),
eigenvalues, principal axes, identities, and the ellipsoid of a symmetric tensor.

A part names its object with `tensor:`, a tensor expression (mechbook/model/tensorexpr.py)
in the problem's declared vectors, tensors and bodies (`inertia(frame)`, `moment(cone, p,
n)`), and may quantify over generic objects with `for_all:` (mechbook/verify/instances.py):
then every check below holds for every instance, and a `define:` may name expressions of
them (e.g. the angle of a rotation). Agreement is decided at random admissible points in
30-digit arithmetic, or exactly where the statement is rational (see `identity`).
"""

from __future__ import annotations

import re

import numpy as np
import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.tensorexpr import kind, parse_tensor, parse_tensor_equation
from mechbook.verify.compare import Verdict, all_vanish, value
from mechbook.verify.context import Context
from mechbook.verify.instances import KINDS, branches, vanish_on_instances
from mechbook.verify.registry import quantity

TENSOR = {"type": "string"}
FOR_ALL = {"type": "object", "minProperties": 1,
           "propertyNames": {"pattern": "^[A-Za-z][A-Za-z0-9_]*$"},
           "additionalProperties": {"enum": list(KINDS)}}
AXES = {"oneOf": [{"type": "string"},
                  {"type": "array", "minItems": 3, "maxItems": 3,
                   "items": {"oneOf": [{"type": "string"},
                                       {"type": "array", "minItems": 3, "maxItems": 3,
                                        "items": {"$ref": "#/$defs/expr"}}]}}]}
INDEX = {"1": 0, "2": 1, "3": 2, "x": 0, "y": 1, "z": 2}


# ---- names, objects, parsing -------------------------------------------------------------
def instances(ctx: Context) -> list[dict]:
    """The names of each branch of `for_all` (one branch without it), `define:` included."""
    spec = ctx.part.data.get("for_all") or {}
    for name in spec:
        if name in ctx.names:
            raise ctx.part.error(("for_all", name), f"{name!r} is already a name")
    out = []
    for branch in branches(spec):
        names = dict(ctx.names)
        names.update(branch)
        for k, v in (ctx.part.data.get("define") or {}).items():
            if k in names:
                raise ctx.part.error(("define", k), f"{k!r} is already a name")
            names[k] = tparse(ctx, v, ("define", k), names)
        out.append(names)
    return out


def tparse(ctx: Context, text, sub: tuple, names: dict):
    try:
        return parse_tensor(text, names, ctx.bodies)
    except ExpressionError as exc:
        raise ctx.part.error(sub, str(exc)) from None


def tequation(ctx: Context, text, sub: tuple, names: dict):
    try:
        return parse_tensor_equation(text, names, ctx.bodies)
    except ExpressionError as exc:
        raise ctx.part.error(sub, str(exc)) from None


def subject(ctx: Context, names: dict):
    """The object the part is about (`tensor:`), in the axes `axes:` names if any."""
    if "tensor" not in ctx.part.data:
        raise ctx.part.error(("tensor",), f"a {ctx.part.quantity!r} part names its object "
                             "with 'tensor:'")
    obj = tparse(ctx, ctx.part.data["tensor"], ("tensor",), names)
    if "axes" not in ctx.part.data:
        return obj
    a = axes_matrix(ctx, names)
    if kind(obj) == "tensor":
        return a * obj * a.T
    if kind(obj) == "vector":
        return a * obj
    raise ctx.part.error(("axes",), "a scalar has no components in other axes")


def axes_matrix(ctx: Context, names: dict) -> sp.Matrix:
    """The matrix a_ij = e'_i·e_j (Symon Eq. 10-68) of the new axes, given as three vectors
    (rows) or as one tensor expression; it must be orthogonal."""
    spec = ctx.part.data["axes"]
    if isinstance(spec, str):
        a = tparse(ctx, spec, ("axes",), names)
        if kind(a) != "tensor":
            raise ctx.part.error(("axes",), "axes: a tensor whose rows are the new axes")
    else:
        rows = []
        for i, row in enumerate(spec):
            v = tparse(ctx, row, ("axes", i), names) if isinstance(row, str) else \
                sp.Matrix([tparse(ctx, x, ("axes", i, j), names) for j, x in enumerate(row)])
            if kind(v) != "vector":
                raise ctx.part.error(("axes", i), "each axis is a vector")
            rows.append(list(v))
        a = sp.Matrix(rows)
    a = sp.Matrix(a)
    residual = all_vanish(list(a * a.T - sp.eye(3)), ctx.sampler, symbolic=False)
    if not residual.ok:
        raise ctx.part.error(("axes",), "the new axes are not orthonormal (a·aᵀ ≠ 1): "
                             + residual.detail)
    return a


def book_value(ctx: Context, val, sub: tuple, names: dict, like):
    """The book's value shaped like the engine's `like`: a pair of flat lists (book, engine)
    and labels, for the components the book gives."""
    k = kind(like)
    if isinstance(val, dict):
        if k == "scalar":
            raise ctx.part.error(sub, "a scalar's value is an expression")
        pairs = []
        for key, text in val.items():
            idx = [INDEX.get(ch) for ch in str(key)]
            if None in idx or len(idx) != (2 if k == "tensor" else 1):
                raise ctx.part.error(sub + (key,), f"component {key!r}: write "
                                     + ("'11'…'33' or 'xx'…'zz'" if k == "tensor" else
                                        "'1'…'3' or 'x'…'z'"))
            engine = like[idx[0], idx[1]] if k == "tensor" else like[idx[0], 0]
            pairs.append((str(key), tparse(ctx, text, sub + (key,), names), engine))
        return pairs
    if isinstance(val, list):
        if k == "tensor":
            if len(val) != 3 or any(not isinstance(r, list) or len(r) != 3 for r in val):
                raise ctx.part.error(sub, "a tensor's components are three rows of three")
            return [(f"{i + 1}{j + 1}", tparse(ctx, x, sub + (i, j), names), like[i, j])
                    for i, row in enumerate(val) for j, x in enumerate(row)]
        if k == "vector":
            if len(val) != 3:
                raise ctx.part.error(sub, "a vector has three components")
            return [(f"{i + 1}", tparse(ctx, x, sub + (i,), names), like[i, 0])
                    for i, x in enumerate(val)]
        raise ctx.part.error(sub, "a scalar's value is an expression, not a list")
    book = tparse(ctx, val, sub, names)
    if kind(book) != k:
        raise ctx.part.error(sub, f"the book's value is a {kind(book)}, the object a {k}")
    if k == "scalar":
        return [("value", book, like)]
    return [(f"{i + 1}{j + 1}" if k == "tensor" else f"{i + 1}", book[i, j], like[i, j])
            for i in range(like.rows) for j in range(like.cols)]


def combine(verdicts: list[Verdict]) -> Verdict:
    """One verdict for the branches of `for_all`: the first failure, else the weakest
    method (numeric < exact < symbolic), its count of instances kept."""
    for v in verdicts:
        if not v.ok:
            return v
    rank = {"numeric": 0, "exact": 1, "symbolic": 2}
    return min(verdicts, key=lambda v: rank.get(v.method.split("(")[0], 0))


def _vanish(ctx: Context, exprs: list, labels: list[str]) -> Verdict:
    """All vanish: on for_all instances (exact where rational) or at random points."""
    return vanish_on_instances(exprs, ctx.sampler, labels)


# ---- quantities --------------------------------------------------------------------------
@quantity('components',
          book='expression, `[x, y, z]`, `[[..], [..], [..]]`, or `{"12": T12, …}` (some '
               'components)',
          how=('the value of the tensor expression `tensor:` (a scalar, vector or tensor; '
               'declared vectors, tensors and bodies), in the axes `axes:` (three unit '
               'vectors e′ᵢ, or a tensor whose rows they are: T′ = a·T·aᵀ, a_ij = '
               'e′ᵢ·e_j) if given, equals the book\'s component by component, at random '
               'points; with `for_all:`, for every instance'),
          keys={"tensor": TENSOR, "axes": AXES, "for_all": FOR_ALL}, needs_system=False)
def check_components(ctx: Context, val) -> Verdict:
    out = []
    for names in instances(ctx):
        obj = subject(ctx, names)
        pairs = book_value(ctx, val, ("book",), names, obj)
        out.append(_vanish(ctx, [b - e for _, b, e in pairs],
                           [f"component {p[0]}, book − value," for p in pairs]))
    return combine(out)


def _characteristic(t: sp.Matrix) -> tuple:
    """tr T, M(T) (the sum of principal 2×2 minors), det T: the coefficients of
    λ³ − tr λ² + M λ − det (Symon Eqs. 10-136 to 10-139)."""
    m = sum((t[i, i] * t[j, j] - t[i, j] * t[j, i] for i, j in ((0, 1), (1, 2), (0, 2))),
            sp.S.Zero)
    return t.trace(), m, t.det(method="berkowitz")


def _tensor_subject(ctx: Context, names: dict) -> sp.Matrix:
    obj = subject(ctx, names)
    if kind(obj) != "tensor":
        raise ctx.part.error(("tensor",), f"expected a tensor, got a {kind(obj)}")
    return sp.Matrix(obj)


@quantity('eigenvalues',
          book='list of eigenvalues (with repeats)',
          how=('three values: their elementary symmetric functions equal tr T, M(T) and '
               'det T, the coefficients of the secular equation (so the multiset matches, '
               'in any order, complex ones included, without solving it); fewer values '
               'with `partial: true`: each is a root, det(λ1 − T) = 0. `for_all:` '
               'quantifies over generic tensors'),
          keys={"tensor": TENSOR, "for_all": FOR_ALL, "axes": AXES,
                "partial": {"type": "boolean"}}, needs_system=False)
def check_eigenvalues(ctx: Context, val) -> Verdict:
    values = ctx.as_list(val, ("book",))
    partial = bool(ctx.part.data.get("partial"))
    if not partial and len(values) != 3:
        raise ctx.part.error(("book",), "give all three eigenvalues (with repeats), or "
                             "`partial: true`")
    out = []
    for names in instances(ctx):
        t = _tensor_subject(ctx, names)
        lams = [tparse(ctx, v, ("book", i), names) for i, v in enumerate(values)]
        if partial:
            exprs = [(lam * sp.eye(3) - t).det(method="berkowitz") for lam in lams]
            labels = [f"det(λ1 − T) at λ = {v}" for v in values]
        else:
            a, b, c = lams
            exprs = [x - y for x, y in zip((a + b + c, a * b + b * c + a * c, a * b * c),
                                           _characteristic(t), strict=True)]
            labels = ["sum of the eigenvalues − tr T", "sum of their pair products − M(T)",
                      "their product − det T"]
        out.append(_vanish(ctx, exprs, labels))
    return combine(out)


@quantity('principal_axes',
          book='list of `{value: λ, axis: [x, y, z]}` or `{value: λ, plane: n}`',
          how=('each axis v is an eigenvector, T·v = λv, and not zero (up to scale and '
               'sign); `plane: n`: every vector perpendicular to n is one (a degenerate '
               'eigenvalue), (T − λ1)·(n²1 − nn) = 0. Three axes (or a plane and an axis) '
               'must also be independent'),
          keys={"tensor": TENSOR, "for_all": FOR_ALL, "axes": AXES}, needs_system=False)
def check_principal_axes(ctx: Context, val) -> Verdict:
    entries = ctx.as_list(val, ("book",))
    out = []
    for names in instances(ctx):
        t = _tensor_subject(ctx, names)
        exprs, labels, vectors, normals = [], [], [], []
        for i, entry in enumerate(entries):
            entry = ctx.as_map(entry, ("book", i))
            if "value" not in entry or len(set(entry) & {"axis", "plane"}) != 1 \
                    or set(entry) - {"value", "axis", "plane"}:
                raise ctx.part.error(("book", i), "an entry is {value: λ, axis: v} or "
                                     "{value: λ, plane: n}")
            lam = tparse(ctx, entry["value"], ("book", i, "value"), names)
            key = "axis" if "axis" in entry else "plane"
            v = _vec(ctx, entry[key], ("book", i, key), names)
            if key == "axis":
                residual = (t - lam * sp.eye(3)) * v
                vectors.append(v)
            else:
                residual = (t - lam * sp.eye(3)) * (v.dot(v) * sp.eye(3) - v * v.T)
                normals.append(v)
            exprs += list(residual)
            labels += [f"entry {i + 1} ({key}), component {k + 1}"
                       for k in range(len(residual))]
        verdict = _vanish(ctx, exprs, labels)
        if verdict.ok:
            shape = _nonzero_and_independent(ctx, vectors, normals)
            verdict = verdict if shape.ok else shape
        out.append(verdict)
    return combine(out)


def _vec(ctx: Context, spec, sub: tuple, names: dict) -> sp.Matrix:
    v = tparse(ctx, spec, sub, names) if isinstance(spec, str) else \
        sp.Matrix([tparse(ctx, x, sub + (j,), names) for j, x in enumerate(spec)])
    if kind(v) != "vector":
        raise ctx.part.error(sub, f"expected a vector, got a {kind(v)}")
    return sp.Matrix(v)


def _nonzero_and_independent(ctx: Context, vectors: list, normals: list) -> Verdict:
    """At a random point: no axis or plane normal is zero, and three directions (a plane
    counting two) are independent (judged on the numbers, never on symbolic determinants)."""
    free = set().union(*(e.free_symbols for v in vectors + normals for e in v))
    point = ctx.sampler.draw(free - set(ctx.sampler.base))
    vecs = [np.array([value(e, point) for e in v]) for v in vectors]
    norms = [np.array([value(e, point) for e in v]) for v in normals]
    for v in vecs + norms:
        if not np.all(np.isfinite(v)) or np.linalg.norm(v) == 0:
            return Verdict(False, "numeric", "an axis (or a plane's normal) is zero or "
                           "does not evaluate")
    if len(vecs) + 2 * len(norms) == 3:
        if norms:
            independent = abs(np.dot(vecs[0], norms[0]))
            scale = np.linalg.norm(vecs[0]) * np.linalg.norm(norms[0])
        else:
            independent = abs(np.linalg.det(np.array(vecs)))
            scale = float(np.prod([np.linalg.norm(v) for v in vecs]))
        if independent <= 1e-9 * scale:
            return Verdict(False, "numeric", "the principal axes given are not independent")
    return Verdict(True, "numeric", "")


@quantity('identity',
          book='equation `lhs = rhs` (scalars, vectors or tensors; `= 0` for a zero one), '
               'or a list of them',
          how=('holds for every instance of `for_all:` ({name: kind}: scalar, positive, '
               'angle, vector, unit_vector, tensor, symmetric, antisymmetric, diagonal, '
               'rotation, improper_rotation, orthogonal) and at random parameter points: '
               'decided on 12 random instances, exactly (rational arithmetic) when the '
               'statement is rational in them, else in 30-digit arithmetic; then proved '
               'for the generic objects by `cancel` (2 s; `simplify` with `--prove`) '
               'where SymPy can. The method says which: symbolic, exact(…) or numeric(…)'),
          keys={"for_all": FOR_ALL}, needs_system=False)
def check_identity(ctx: Context, val) -> Verdict:
    statements = val if isinstance(val, list) else [val]
    out = []
    for names in instances(ctx):
        exprs, labels = [], []
        for i, text in enumerate(statements):
            sub = ("book", i) if isinstance(val, list) else ("book",)
            lhs, rhs = tequation(ctx, text, sub, names)
            diff = lhs - rhs
            flat = list(diff) if isinstance(diff, sp.MatrixBase) else [diff]
            exprs += flat
            labels += [f"{text!r}" + (f", component {k + 1}" if len(flat) > 1 else "")
                       for k in range(len(flat))]
        out.append(_vanish(ctx, exprs, labels))
    return combine(out)


@quantity('solves',
          book='the value (scalar, vector or tensor) of the unknown `unknown:`',
          how=('the book\'s value, put for the unknown in the equations `equations:` '
               '(tensor equations, e.g. a constitutive law), satisfies every one of them, '
               'decided as for `identity` (uniqueness is the equations\' business: say so '
               'in the note)'),
          keys={"unknown": {"type": "string", "pattern": "^[A-Za-z][A-Za-z0-9_]*$"},
                "equations": {"type": "array", "minItems": 1, "items": {"type": "string"}},
                "for_all": FOR_ALL}, needs_system=False)
def check_solves(ctx: Context, val) -> Verdict:
    unknown = ctx.part.data.get("unknown")
    equations = ctx.part.data.get("equations")
    if not unknown or not equations:
        raise ctx.part.error((), "a 'solves' part names `unknown:` and `equations:`")
    out = []
    for names in instances(ctx):
        if unknown in names:
            raise ctx.part.error(("unknown",), f"{unknown!r} is already a name")
        if isinstance(val, list) and val and isinstance(val[0], list):
            book = sp.ImmutableMatrix([[tparse(ctx, x, ("book", i, j), names)
                                        for j, x in enumerate(row)]
                                       for i, row in enumerate(val)])
        elif isinstance(val, list):
            book = sp.ImmutableMatrix([tparse(ctx, x, ("book", i), names)
                                       for i, x in enumerate(val)])
        else:
            book = tparse(ctx, val, ("book",), names)
        if kind(book) not in ("scalar", "vector", "tensor"):
            raise ctx.part.error(("book",), "the value is a scalar, a vector or a tensor")
        names = dict(names)
        names[unknown] = book
        exprs, labels = [], []
        for i, text in enumerate(equations):
            lhs, rhs = tequation(ctx, text, ("equations", i), names)
            diff = lhs - rhs
            flat = list(diff) if isinstance(diff, sp.MatrixBase) else [diff]
            exprs += flat
            labels += [f"equation {i + 1}" + (f", component {k + 1}" if len(flat) > 1 else "")
                       for k in range(len(flat))]
        out.append(_vanish(ctx, exprs, labels))
    return combine(out)


XYZ = ("x", "y", "z")


@quantity('inertia_ellipsoid',
          book='equation in x, y, z',
          how=('the quadric r·T·r = 1 of the symmetric tensor `tensor:` (Symon Eq. '
               '10-157, the size constant set to 1): the book\'s equation f(x, y, z) = 0 '
               'is a nonzero multiple c·(r·T·r − 1), c = −f(0); compared at random points '
               'and random x, y, z'),
          keys={"tensor": TENSOR}, needs_system=False)
def check_inertia_ellipsoid(ctx: Context, val) -> Verdict:
    names = dict(ctx.names)
    r = []
    for c in XYZ:
        if c in names:
            raise ctx.part.error(("book",), f"{c!r} is already a name; the ellipsoid's "
                                 "coordinates are x, y, z")
        names[c] = sp.Symbol(c, real=True)
        r.append(names[c])
    t = _tensor_subject(ctx, names)
    if not re.search(r"=", str(val)):
        raise ctx.part.error(("book",), "the ellipsoid is an equation: '... = 1'")
    lhs, rhs = tequation(ctx, val, ("book",), names)
    if kind(lhs) != "scalar":
        raise ctx.part.error(("book",), "the ellipsoid's equation is between scalars")
    f = lhs - rhs
    rv = sp.Matrix(r)
    quadric = (rv.T * t * rv)[0, 0] - 1
    c = -f.xreplace(dict.fromkeys(r, 0))
    verdict = _vanish(ctx, [f - c * quadric], ["f − c·(r·T·r − 1)"])
    if not verdict.ok:
        return verdict
    point = ctx.sampler.draw(c.free_symbols - set(ctx.sampler.base))
    if abs(value(c, point)) == 0:
        return Verdict(False, "numeric", "the equation has no constant term: not r·T·r = 1")
    return verdict


def validate_part(ctx: Context) -> None:
    """Parse every expression of a tensor part (for `mechbook validate`), nothing derived."""
    names = dict(instances(ctx)[0])
    if ctx.part.quantity == "inertia_ellipsoid":
        names.update({c: sp.Symbol(c, real=True) for c in XYZ if c not in names})

    def walk(v, sub):
        if isinstance(v, dict):
            for k, x in v.items():
                walk(x, sub + (k,))
        elif isinstance(v, list):
            for i, x in enumerate(v):
                walk(x, sub + (i,))
        elif isinstance(v, str) and "=" in v.replace("==", ""):
            tequation(ctx, v, sub, names)
        elif isinstance(v, (str, int, float)) and not isinstance(v, bool):
            tparse(ctx, v, sub, names)

    for key in ("tensor", "axes", "book"):
        if key in ctx.part.data:
            walk(ctx.part.data[key], (key,))
    if "erratum" in ctx.part.data:
        walk(ctx.part.data["erratum"]["corrected"], ("erratum", "corrected"))
