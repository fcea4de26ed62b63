"""Tensor expressions: the safe parser (mechbook.model.expr) extended to vectors and tensors.

Values are SymPy scalars, 3-component column vectors and 3×3 tensors (immutable matrices).
`[x, y, z]` is a vector and `[[..], [..], [..]]` a tensor's matrix; `+ -` add objects of
the same kind; `*` multiplies by a scalar or is the dot product of tensors and of a tensor
with a vector (T·S, T·v — Symon's notation); the functions below do the rest. A body declared
in the problem is named only as the first argument of the body functions. Nothing is
evaluated that the whitelist does not name; a wrong combination (a tensor plus a scalar, a
vector times a vector) is an error naming the expression.
"""

from __future__ import annotations

import ast
from collections.abc import Callable, Mapping

import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.expr import MAX_DEPTH, MAX_LENGTH, _Builder, _depth


def _holds_matrix(expr) -> bool:
    """A scalar expression with a matrix inside it (sin of a tensor, 2**T): refused."""
    return isinstance(expr, sp.Basic) and bool(expr.atoms(sp.MatrixBase))


def _vector(v) -> bool:
    return isinstance(v, sp.MatrixBase) and v.shape == (3, 1)


def _tensor(v) -> bool:
    return isinstance(v, sp.MatrixBase) and v.shape == (3, 3)


def _scalar(v) -> bool:
    return not isinstance(v, sp.MatrixBase)


def _kind(v) -> str:
    return "vector" if _vector(v) else "tensor" if _tensor(v) else "scalar" if _scalar(v) \
        else f"{v.shape[0]}x{v.shape[1]} matrix"


def _need(what: str, test: Callable, *args) -> None:
    for a in args:
        if not test(a):
            raise TypeError(f"expected a {what}, got a {_kind(a)}")


def _im(m: sp.MatrixBase) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(m)


def _dyad(a, b):
    _need("vector", _vector, a, b)
    return _im(a * b.T)


def _dot(a, b):
    if _vector(a) and _vector(b):
        return a.dot(b)
    if _vector(a) and _tensor(b):  # v·T
        return _im(b.T * a)
    if _tensor(a) and (_tensor(b) or _vector(b)):
        return _im(a * b)
    raise TypeError(f"dot of a {_kind(a)} and a {_kind(b)}")


def _ddot(a, b):
    """The double dot product A:B = Σ A_ij B_ij of two tensors."""
    _need("tensor", _tensor, a, b)
    return sum((a[i, j] * b[i, j] for i in range(3) for j in range(3)), sp.S.Zero)


def _cross(a, b):
    """u × v; with a tensor, the dyadic rule: w × (AB) = (w × A)B, (AB) × w = A(B × w)."""
    if _vector(a) and _tensor(b):
        return _im(_skew(a) * b)
    if _tensor(a) and _vector(b):
        return _im(a * _skew(b))
    _need("vector", _vector, a, b)
    return _im(a.cross(b))


def _transpose(t):
    _need("tensor", _tensor, t)
    return _im(t.T)


def _det(t):
    _need("tensor", _tensor, t)
    return t.det(method="berkowitz")


def _trace(t):
    _need("tensor", _tensor, t)
    return t.trace()


def _second_invariant(t):
    """Symon's M(T), Eq. (10-139): the sum of the three principal 2×2 minors."""
    _need("tensor", _tensor, t)
    return sum((t[i, i] * t[j, j] - t[i, j] * t[j, i] for i, j in ((0, 1), (1, 2), (0, 2))),
               sp.S.Zero)


def _inverse(t):
    _need("tensor", _tensor, t)
    d = _det(t)
    if d == 0:
        raise ValueError("the tensor is singular (determinant 0)")
    return _im(t.adjugate() / d)


def _unit():
    return _im(sp.eye(3))


def _rotation(axis, angle):
    """The orthogonal tensor turning vectors through `angle` about `axis` (right hand)."""
    _need("vector", _vector, axis)
    _need("scalar", _scalar, angle)
    n2 = axis.dot(axis)
    if n2 == 0:
        raise ValueError("a rotation axis must not be the zero vector")
    n = axis / sp.sqrt(n2)
    cross = sp.Matrix([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    return _im(sp.cos(angle) * sp.eye(3) + sp.sin(angle) * cross
               + (1 - sp.cos(angle)) * n * n.T)


def _skew(w):
    """The antisymmetric tensor T with T·C = w × C (Symon Eqs. 10-62, 10-63)."""
    _need("vector", _vector, w)
    return _im(sp.Matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]))


def _index(i) -> int:
    if not (isinstance(i, sp.Integer) and 1 <= int(i) <= 3):
        raise ValueError(f"an index is 1, 2 or 3, not {i}")
    return int(i) - 1


def _entry(t, i, j=None):
    """Component T_ij (1-based) of a tensor, or v_i of a vector."""
    if j is None:
        _need("vector", _vector, t)
        return t[_index(i), 0]
    _need("tensor", _tensor, t)
    return t[_index(i), _index(j)]


def _row(t, i):
    """Row i (1-based) of a tensor's matrix, as a vector (e'_i for a transformation a)."""
    _need("tensor", _tensor, t)
    return _im(t[_index(i), :].T)


def _col(t, j):
    _need("tensor", _tensor, t)
    return _im(t[:, _index(j)])


def _diff(x, s):
    """d/ds of a scalar, vector or tensor; s a parameter or a generic scalar."""
    if not isinstance(s, sp.Symbol):
        raise TypeError("differentiate with respect to a plain symbol (a parameter, or a "
                        "`for_all` scalar)")
    return _im(x.diff(s)) if isinstance(x, sp.MatrixBase) else sp.diff(x, s)


def _coordinates(r) -> list[sp.Symbol]:
    _need("vector", _vector, r)
    if not all(isinstance(c, sp.Symbol) for c in r):
        raise TypeError("the position must be a vector of three plain symbols [x, y, z]")
    return list(r)


def _grad(x, r):
    """∇f (a vector) of a scalar field, or the dyad ∇v, (∇v)_ij = ∂v_j/∂x_i (Symon Eq.
    10-175), of a vector field; `r` = [x, y, z], Cartesian."""
    xs = _coordinates(r)
    if _scalar(x):
        return _im(sp.Matrix([sp.diff(x, c) for c in xs]))
    _need("vector", _vector, x)
    return _im(sp.Matrix(3, 3, lambda i, j: sp.diff(x[j], xs[i])))


def _div(x, r):
    """∇·v of a vector field (a scalar), or ∇·P, (∇·P)_j = Σ_i ∂P_ij/∂x_i, of a tensor."""
    xs = _coordinates(r)
    if _vector(x):
        return sum((sp.diff(x[i], xs[i]) for i in range(3)), sp.S.Zero)
    _need("tensor", _tensor, x)
    return _im(sp.Matrix([sum((sp.diff(x[i, j], xs[i]) for i in range(3)), sp.S.Zero)
                          for j in range(3)]))


def _subs(x, s, v):
    """x with the symbol s replaced by the scalar v (a boundary value, a change of
    variables)."""
    if not isinstance(s, sp.Symbol):
        raise TypeError("substitute for a plain symbol")
    _need("scalar", _scalar, v)
    return _im(x.xreplace({s: v})) if isinstance(x, sp.MatrixBase) else x.xreplace({s: v})


def _integral(f, s, lo, hi):
    """The definite integral of a scalar over s from lo to hi (SymPy's integrate; an
    integral it cannot do in closed form is an error)."""
    if not isinstance(s, sp.Symbol):
        raise TypeError("integrate over a plain symbol")
    _need("scalar", _scalar, f, lo, hi)
    out = sp.integrate(f, (s, lo, hi))
    if out.has(sp.Integral):
        raise ValueError("SymPy finds no closed form for this integral")
    return out


def _norm(v):
    _need("vector", _vector, v)
    return sp.sqrt(v.dot(v))


def _scalar_fn(fn):
    def apply(x):
        _need("scalar", _scalar, x)
        return fn(x)
    return apply


TENSOR_FUNCTIONS: dict[str, Callable] = {
    "dyad": _dyad, "dot": _dot, "ddot": _ddot, "cross": _cross, "transpose": _transpose,
    "det": _det,
    "trace": _trace, "second_invariant": _second_invariant, "inverse": _inverse,
    "unit": _unit, "rotation": _rotation, "skew": _skew, "entry": _entry, "norm": _norm,
    "row": _row, "col": _col, "diff": _diff, "grad": _grad, "div": _div, "subs": _subs,
    "integral": _integral,
    "i": lambda: sp.I, "expi": _scalar_fn(lambda x: sp.exp(sp.I * x)),
    "re": _scalar_fn(sp.re), "im": _scalar_fn(sp.im), "conj": _scalar_fn(sp.conjugate),
}
TENSOR_ARITY = {"dyad": (2, 2), "dot": (2, 2), "ddot": (2, 2), "cross": (2, 2), "unit": (0, 0),
                "rotation": (2, 2), "entry": (2, 3), "row": (2, 2), "col": (2, 2),
                "diff": (2, 2), "i": (0, 0), "grad": (2, 2), "div": (2, 2), "subs": (3, 3),
                "integral": (4, 4)}


def _point(obj, p):
    _need("vector", _vector, p)
    return p


# functions whose first argument names a declared body: (method, arity without the body)
BODY_FUNCTIONS: dict[str, tuple[Callable, tuple[int, int]]] = {
    "mass": (lambda b: b.mass, (0, 0)),
    "center_of_mass": (lambda b: _im(b.center_of_mass), (0, 0)),
    "inertia": (lambda b, p=None: _im(b.inertia(None if p is None else _point(b, p))), (0, 1)),
    "moment": (lambda b, p, n: b.moment(_point(b, p), _point(b, n)), (2, 2)),
}


class _TensorBuilder(_Builder):
    def __init__(self, text: str, names: Mapping, objects: Mapping):
        super().__init__(text, names, False)
        self.objects = objects

    def _List(self, node: ast.List, depth: int):
        items = [self.build(e, depth) for e in node.elts]
        if len(items) == 3 and all(_scalar(x) for x in items):
            return sp.ImmutableMatrix(items)
        if len(items) == 3 and all(isinstance(x, sp.MatrixBase) and x.shape == (3, 1)
                                   for x in items):
            return sp.ImmutableMatrix([[x[k] for k in range(3)] for x in items])
        raise self.fail(node, "a list is a vector [x, y, z] or a tensor [[..], [..], [..]]")

    def _BinOp(self, node: ast.BinOp, depth: int):
        if isinstance(node.op, ast.Pow):
            base, exponent = self.build(node.left, depth), self.build(node.right, depth)
            if isinstance(base, sp.MatrixBase) or isinstance(exponent, sp.MatrixBase):
                if not (_tensor(base) and _scalar(exponent) and exponent.is_Integer
                        and abs(exponent) <= 16):
                    raise self.fail(node, "only a tensor has powers, with an integer exponent "
                                    "(at most 16 in size)")
                try:
                    return _im(base**int(exponent))
                except (ValueError, ZeroDivisionError) as exc:
                    raise self.fail(node, f"cannot raise this tensor to {exponent} ({exc})") \
                        from None
        try:
            out = super()._BinOp(node, depth)
        except (TypeError, ValueError, NotImplementedError, sp.ShapeError,
                sp.NonSquareMatrixError) as exc:
            raise self.fail(node, f"cannot combine these operands ({exc})") from None
        if not isinstance(out, sp.MatrixBase) and _holds_matrix(out):
            raise self.fail(node, "a vector or tensor cannot be an exponent or a base here")
        if isinstance(out, sp.MatrixBase):
            if out.shape not in ((3, 1), (3, 3)):
                raise self.fail(node, f"the result is a {_kind(out)}: use dot(u, v) for the "
                                "scalar product of vectors")
            return _im(out)
        return out

    def _UnaryOp(self, node: ast.UnaryOp, depth: int):
        out = super()._UnaryOp(node, depth)
        return _im(out) if isinstance(out, sp.MatrixBase) else out

    def _Call(self, node: ast.Call, depth: int):
        if not isinstance(node.func, ast.Name):
            raise self.fail(node, "only calls of whitelisted functions by name are allowed")
        name = node.func.id
        if name in BODY_FUNCTIONS:
            return self._body_call(node, depth)
        if name not in TENSOR_FUNCTIONS:
            out = super()._Call(node, depth)
            if _holds_matrix(out):
                raise self.fail(node, f"{name}() takes scalars only")
            return out
        if node.keywords:
            raise self.fail(node, f"keyword arguments are not allowed in {name}()")
        lo, hi = TENSOR_ARITY.get(name, (1, 1))
        if not lo <= len(node.args) <= hi:
            raise self.fail(node, f"{name}() takes {lo if lo == hi else f'{lo} to {hi}'} "
                                  f"argument(s), got {len(node.args)}")
        args = [self.build(a, depth) for a in node.args]
        try:
            return TENSOR_FUNCTIONS[name](*args)
        except (TypeError, ValueError, sp.ShapeError) as exc:
            raise self.fail(node, f"{name}(): {exc}") from None

    def _body_call(self, node: ast.Call, depth: int):
        name = node.func.id
        fn, (lo, hi) = BODY_FUNCTIONS[name]
        if node.keywords or not node.args or not isinstance(node.args[0], ast.Name):
            raise self.fail(node, f"{name}() takes a body's name first")
        body = node.args[0].id
        if body not in self.objects:
            known = ", ".join(sorted(self.objects)) or "none"
            raise self.fail(node, f"{name}(): no body {body!r} (bodies: {known})")
        rest = node.args[1:]
        if not lo <= len(rest) <= hi:
            raise self.fail(node, f"{name}() takes a body and {lo if lo == hi else f'{lo} to {hi}'}"
                                  f" more argument(s), got {len(rest)}")
        args = [self.build(a, depth) for a in rest]
        try:
            return fn(self.objects[body], *args)
        except (TypeError, ValueError, sp.ShapeError) as exc:
            raise self.fail(node, f"{name}(): {exc}") from None


def parse_tensor(text, names: Mapping[str, sp.Basic] | None = None,
                 objects: Mapping[str, object] | None = None):
    """Parse a scalar, vector or tensor expression (bodies named in `objects`)."""
    names = names or {}
    if isinstance(text, bool):
        raise ExpressionError(f"expected an expression, got {text!r}")
    if isinstance(text, int | float):
        text = repr(text)
    if not isinstance(text, str):
        raise ExpressionError(f"expected an expression string, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"expression longer than {MAX_LENGTH} characters")
    if not text.strip():
        raise ExpressionError("empty expression")
    if _depth(text) > MAX_DEPTH:
        raise ExpressionError(f"expression nested too deeply (more than {MAX_DEPTH})", text)
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        col = f" at column {exc.offset}" if exc.offset else ""
        raise ExpressionError(f"syntax error{col} in expression {text!r}: {exc.msg}",
                              text) from None
    except (RecursionError, MemoryError, ValueError):
        raise ExpressionError(f"expression {text[:60]!r} cannot be parsed safely", text) from None
    return _TensorBuilder(text, names, objects or {}).build(tree)


def parse_tensor_equation(text, names: Mapping[str, sp.Basic] | None = None,
                          objects: Mapping[str, object] | None = None):
    """`lhs = rhs` as the pair (lhs, rhs) of like objects; `= 0` stands for a zero vector or
    tensor too."""
    from mechbook.model.expr import _split_single_equals

    if not isinstance(text, str):
        raise ExpressionError(f"expected an equation 'lhs = rhs', got {text!r}")
    pieces = _split_single_equals(text)
    if len(pieces) != 2:
        raise ExpressionError(f"expected one '=' in equation {text!r}", text)
    lhs = parse_tensor(pieces[0], names, objects)
    rhs = parse_tensor(pieces[1], names, objects)
    for a, b in ((lhs, rhs), (rhs, lhs)):
        if isinstance(a, sp.MatrixBase) and not isinstance(b, sp.MatrixBase) and b == 0:
            return (lhs, sp.ImmutableMatrix.zeros(*a.shape)) if a is lhs else \
                (sp.ImmutableMatrix.zeros(*a.shape), rhs)
    if _kind(lhs) != _kind(rhs):
        raise ExpressionError(f"the sides of {text!r} differ in kind: a {_kind(lhs)} and a "
                              f"{_kind(rhs)}", text)
    return lhs, rhs


def kind(value) -> str:
    """'scalar', 'vector' or 'tensor'."""
    return _kind(value)
