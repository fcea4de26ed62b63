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

import sympy as sp
from sympy.matrices.utilities import dotprodsimp

from mechbook.core.compile import as_expr
from mechbook.errors import ExpressionError
from mechbook.model.tensorexpr import kind, parse_tensor, parse_tensor_equation
from mechbook.model.tensorfuncs import for_all_name, is_variable
from mechbook.verify.compare import Verdict
from mechbook.verify.context import Context
from mechbook.verify.instances import (
    KINDS,
    Statement,
    branches,
    decide,
    generic_symbols,
    rational_point,
)
from mechbook.verify.registration import ESTIMATE, NAME, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

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
def check(ctx: Context, build) -> Verdict:
    """Decide the part's statement, `build(names) -> Statement`, on every branch of
    `for_all` (mechbook/verify/instances.py): built at random instances, then tried for
    the generic objects."""
    spec = ctx.part.data.get("for_all") or {}
    for name in spec:
        if name in ctx.names:
            raise ctx.part.error(("for_all", name), f"{name!r} is already a name")
    if ctx.validate_only:  # `mechbook validate`: build once, judge nothing
        branch = branches(spec)[0]
        # as decide builds it: without SymPy's intermediate cancel of matrix products
        # (a 3×3 determinant of Symon 10-26's axes: 2.9 s with it, 0.01 s without)
        with dotprodsimp(False):
            build(branch_names(ctx, branch,
                               rational_point(ctx.sampler, generic_symbols(branch))))
        return Verdict(True, "validated")
    out = []
    memo: dict = {}
    for branch in branches(spec):
        def names_at(point, branch=branch):
            return branch_names(ctx, branch, point)

        out.append(decide(names_at, build, generic_symbols(branch), ctx.sampler, memo))
    return combine(out)


def branch_names(ctx: Context, branch: dict, point: dict | None) -> dict:
    """The part's names with the branch's generic objects and `define:`; at `point` (unless
    None) the generic objects are numbers, but for the `variable`s: those and the
    parameters stay symbols until the statement is built, so that calculus acts on them
    as it does on the generic statement (mechbook.model.tensorfuncs)."""
    names = dict(ctx.names)
    names.update(branch)
    if point is not None:
        early = {k: v for k, v in point.items() if for_all_name(k) and not is_variable(k)}
        names = {k: v.xreplace(early) if isinstance(v, sp.Basic) else v
                 for k, v in names.items()}
    for k, v in (ctx.part.data.get("define") or {}).items():
        if k in names:
            raise ctx.part.error(("define", k), f"{k!r} is already a name")
        names[k] = tparse(ctx, v, ("define", k), names)
    return names


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
    residual = a * a.T - sp.eye(3)
    if not residual.free_symbols:  # at an instance (numbers): checked there
        worst = max(abs(complex(sp.N(e, 30))) for e in residual)
        if worst > 1e-20:
            raise ctx.part.error(("axes",), "the new axes are not orthonormal (a·aᵀ ≠ 1; "
                                 f"off by {worst:.2g})")
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


# ---- quantities --------------------------------------------------------------------------
@quantity('components',
          book='expression, `[x, y, z]`, `[[..], [..], [..]]`, or `{"12": T12, …}` (some '
               'components)',
          how=('the value of the tensor expression `tensor:` (a scalar, vector or tensor; '
               'declared vectors, tensors and bodies), in the axes `axes:` (three unit '
               'vectors e′ᵢ, or a tensor whose rows they are: T′ = a·T·aᵀ, a_ij = '
               'e′ᵢ·e_j) if given, equals the book\'s component by component, at random '
               'points; with `for_all:`, for every instance; with `estimate:`, at the '
               'book\'s numbers, each component to its precision'),
          keys={"tensor": TENSOR, "axes": AXES, "for_all": FOR_ALL, "estimate": ESTIMATE},
          needs_system=False)
def check_components(ctx: Context, val) -> Verdict:
    if "estimate" in ctx.part.data and not ctx.validate_only:
        return _estimate_components(ctx, val)

    def build(names):
        obj = subject(ctx, names)
        pairs = book_value(ctx, val, ("book",), names, obj)
        return Statement([b - e for _, b, e in pairs],
                         [f"component {p[0]}, book − value," for p in pairs])

    return check(ctx, build)


def _estimate_components(ctx: Context, val) -> Verdict:
    """The book's numbers (the problem's values with the estimate's put in): each component
    of the book's value within the estimate's rtol of the object's, relative to the
    larger of the two (a component both give as zero must be zero to 1e-12 of the
    largest)."""
    if ctx.part.data.get("for_all"):
        raise ctx.part.error(("estimate",), "an estimate is at one point: no `for_all:`")
    point = {k: sp.Float(v, 30) for k, v in ctx.sampler.base.items()}
    names = branch_names(ctx, {}, point)
    pairs = book_value(ctx, val, ("book",), names, subject(ctx, names))
    rtol = ctx.sampler.rtol
    values = []
    for label, b, e in pairs:
        b, e = (complex(sp.N(as_expr(x).xreplace(point), 30)) for x in (b, e))
        values.append((label, b, e))
    scale = max(max(abs(b), abs(e)) for _, b, e in values)
    method = f"estimate(rtol {rtol:g})"
    for label, b, e in values:
        size = max(abs(b), abs(e))
        tol = rtol * size if size > 1e-12 * scale else 1e-12 * scale
        if not abs(b - e) <= tol:
            return Verdict(False, method, f"component {label}: book {b.real:.6g}, value "
                           f"{e.real:.6g} (relative difference "
                           f"{abs(b - e) / max(size, 1e-300):.3g} > {rtol:g})")
    worst = max(abs(b - e) / max(abs(b), abs(e)) for _, b, e in values
                if max(abs(b), abs(e)) > 1e-12 * scale)
    return Verdict(True, method, f"{len(values)} component(s) at the book's numbers, "
                   f"largest relative difference {worst:.2g}",
                   power=f"each component within the stated {rtol:g}")



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
               'quantifies over generic tensors; with `--prove`, `symbolic` where the '
               'generic statement is proved (exponentials of imaginary arguments written '
               'cos x + i sin x: a rotation\'s e^{±iα} with α = acos((tr R − 1)/2))'),
          keys={"tensor": TENSOR, "for_all": FOR_ALL, "axes": AXES,
                "partial": {"type": "boolean"}}, needs_system=False)
def check_eigenvalues(ctx: Context, val) -> Verdict:
    values = ctx.as_list(val, ("book",))
    partial = bool(ctx.part.data.get("partial"))
    if not partial and len(values) != 3:
        raise ctx.part.error(("book",), "give all three eigenvalues (with repeats), or "
                             "`partial: true`")

    def build(names):
        t = _tensor_subject(ctx, names)
        lams = [tparse(ctx, v, ("book", i), names) for i, v in enumerate(values)]
        if partial:
            return Statement([(lam * sp.eye(3) - t).det(method="berkowitz") for lam in lams],
                             [f"det(λ1 − T) at λ = {v}" for v in values])
        a, b, c = lams
        return Statement([x - y for x, y in zip((a + b + c, a * b + b * c + a * c, a * b * c),
                                                _characteristic(t), strict=True)],
                         ["sum of the eigenvalues − tr T",
                          "sum of their pair products − M(T)", "their product − det T"])

    return check(ctx, build)


@quantity('principal_axes',
          book='list of `{value: λ, axis: [x, y, z]}` or `{value: λ, plane: n}`',
          how=('each axis v is an eigenvector, T·v = λv, and not zero (up to scale and '
               'sign); `plane: n`: every vector perpendicular to n is one (a degenerate '
               'eigenvalue), (T − λ1)·(n²1 − nn) = 0. Three axes (or a plane and an axis) '
               'must also be independent'),
          keys={"tensor": TENSOR, "for_all": FOR_ALL, "axes": AXES}, needs_system=False,
          equivalent=("direction",))
def check_principal_axes(ctx: Context, val) -> Verdict:

    entries = ctx.as_list(val, ("book",))
    for i, entry in enumerate(entries):
        entry = ctx.as_map(entry, ("book", i))
        if "value" not in entry or len(set(entry) & {"axis", "plane"}) != 1 \
                or set(entry) - {"value", "axis", "plane"}:
            raise ctx.part.error(("book", i), "an entry is {value: λ, axis: v} or "
                                 "{value: λ, plane: n}")

    def build(names):
        t = _tensor_subject(ctx, names)
        exprs, labels, vectors, normals = [], [], [], []
        for i, entry in enumerate(entries):
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
            labels += [f"entry {i + 1} ({key}), component {k + 1} of (T − λ1)·v"
                       for k in range(len(residual))]
        nonzero = [(f"entry {i + 1}'s direction", v.dot(v))
                   for i, v in enumerate(vectors + normals)]
        if len(vectors) + 2 * len(normals) == 3:  # the directions must be independent
            if normals:
                nonzero.append(("the axis along the plane's normal", vectors[0].dot(normals[0])))
            else:
                nonzero.append(("the determinant of the three axes",
                                sp.Matrix.hstack(*vectors).det(method="berkowitz")))
        return Statement(exprs, labels, nonzero)

    return check(ctx, build)


def _vec(ctx: Context, spec, sub: tuple, names: dict) -> sp.Matrix:
    if not isinstance(spec, str | list | tuple):  # a number, a mapping: no vector
        raise ctx.part.error(sub, f"expected a vector ([x, y, z] or a vector expression), "
                             f"got {spec!r:.60}")
    v = tparse(ctx, spec, sub, names) if isinstance(spec, str) else \
        sp.Matrix([tparse(ctx, x, sub + (j,), names) for j, x in enumerate(spec)])
    if kind(v) != "vector":
        raise ctx.part.error(sub, f"expected a vector, got a {kind(v)}")
    return sp.Matrix(v)


@quantity('identity',
          book='equation `lhs = rhs` (scalars, vectors or tensors; `= 0` for a zero one), '
               'or a list of them',
          how=('holds for every instance of `for_all:` ({name: kind}: '
               + ', '.join(KINDS) + '; `variable` is the kind `diff()`, `grad()`, `div()`, '
               '`subs()` and `integral()` act on, besides the parameters) and at random '
               'parameter points: '
               'decided on 12 random instances, exactly (rational arithmetic) when the '
               'statement is rational in them, else in 30-digit arithmetic; then proved '
               'for the generic objects by a polynomial normal form (the numerator '
               'over a common denominator expanded; `simplify` with `--prove`) where that '
               'is cheap. The method says which: symbolic, exact(…) or numeric(…)'),
          keys={"for_all": FOR_ALL}, needs_system=False)
def check_identity(ctx: Context, val) -> Verdict:
    statements = val if isinstance(val, list) else [val]

    def build(names):
        exprs, labels = [], []
        for i, text in enumerate(statements):
            sub = ("book", i) if isinstance(val, list) else ("book",)
            lhs, rhs = tequation(ctx, text, sub, names)
            flat = _flat(lhs - rhs)
            exprs += flat
            labels += [f"{text!r}" + (f", component {k + 1}" if len(flat) > 1 else "")
                       for k in range(len(flat))]
        return Statement(exprs, labels)

    return check(ctx, build)


def _flat(value) -> list:
    return list(value) if isinstance(value, sp.MatrixBase) else [value]


@quantity('solves',
          book='the value (scalar, vector or tensor) of the unknown `unknown:`',
          how=('the book\'s value, put for the unknown in the equations `equations:` '
               '(tensor equations, e.g. a constitutive law), satisfies every one of them, '
               'decided as for `identity` (uniqueness is the equations\' business: say so '
               'in the note)'),
          keys={"unknown": NAME,
                "equations": {"type": "array", "minItems": 1, "items": {"type": "string"}},
                "for_all": FOR_ALL}, needs_system=False)
def check_solves(ctx: Context, val) -> Verdict:
    unknown = ctx.part.data.get("unknown")
    equations = ctx.part.data.get("equations")
    if not unknown or not equations:
        raise ctx.part.error((), "a 'solves' part names `unknown:` and `equations:`")
    if unknown in ctx.names:
        raise ctx.part.error(("unknown",), f"{unknown!r} is already a name")

    def build(names):
        names = dict(names)
        names[unknown] = _book_object(ctx, val, names)
        exprs, labels = [], []
        for i, text in enumerate(equations):
            lhs, rhs = tequation(ctx, text, ("equations", i), names)
            flat = _flat(lhs - rhs)
            exprs += flat
            labels += [f"equation {i + 1}" + (f", component {k + 1}" if len(flat) > 1 else "")
                       for k in range(len(flat))]
        return Statement(exprs, labels)

    return check(ctx, build)


def _book_object(ctx: Context, val, names: dict):
    """A scalar, vector ([x, y, z]) or tensor (three rows) written in the key."""
    if isinstance(val, list) and val and isinstance(val[0], list):
        return sp.ImmutableMatrix([[tparse(ctx, x, ("book", i, j), names)
                                    for j, x in enumerate(row)] for i, row in enumerate(val)])
    if isinstance(val, list):
        return sp.ImmutableMatrix([tparse(ctx, x, ("book", i), names)
                                   for i, x in enumerate(val)])
    return tparse(ctx, val, ("book",), names)


XYZ = ("x", "y", "z")


@quantity('inertia_ellipsoid',
          book='equation in x, y, z',
          how=('the quadric r·T·r = 1 of the symmetric tensor `tensor:` (Symon Eq. '
               '10-157, the size constant set to 1): the book\'s equation f(x, y, z) = 0 '
               'is a nonzero multiple c·(r·T·r − 1), c = −f(0); compared at random points '
               'and random x, y, z'),
          keys={"tensor": TENSOR}, needs_system=False)
def check_inertia_ellipsoid(ctx: Context, val) -> Verdict:
    if not isinstance(val, str) or "=" not in val:
        raise ctx.part.error(("book",), "the ellipsoid is an equation: '... = 1'")
    r = [sp.Symbol(c, real=True) for c in XYZ]

    def build(names):
        names = dict(names)
        for c, sym in zip(XYZ, r, strict=True):
            if c in names:
                raise ctx.part.error(("book",), f"{c!r} is already a name; the ellipsoid's "
                                     "coordinates are x, y, z")
            names[c] = sym
        t = _tensor_subject(ctx, names)
        lhs, rhs = tequation(ctx, val, ("book",), names)
        if kind(lhs) != "scalar":
            raise ctx.part.error(("book",), "the ellipsoid's equation is between scalars")
        f = sp.expand(lhs - rhs)
        rv = sp.Matrix(r)
        quadric = sp.expand((rv.T * t * rv)[0, 0] - 1)
        c = -f.xreplace(dict.fromkeys(r, 0))
        residual = sp.Poly(f - c * quadric, *r)  # every coefficient in x, y, z must vanish
        coeffs = residual.coeffs() if not residual.is_zero else [sp.S.Zero]
        return Statement(coeffs, [f"coefficient {k + 1} of f − c·(r·T·r − 1)"
                                  for k in range(len(coeffs))],
                         [("the constant term of the book's equation", c)])

    return check(ctx, build)

