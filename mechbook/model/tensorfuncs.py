"""The functions of tensor expressions (mechbook/model/tensorexpr.py): the whitelist, each
a small SymPy computation on scalars, 3-vectors (columns) and 3x3 tensors, refusing a wrong
kind of argument with a TypeError or ValueError the parser turns into an error naming the
expression. Body functions take a declared body (mechbook/model/bodies) first.
"""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp

from mechbook.core.secalc import derivative


def holds_matrix(expr) -> bool:
    """A scalar expression with a matrix inside it (sin of a tensor, 2**T): refused."""
    return isinstance(expr, sp.Basic) and bool(expr.atoms(sp.MatrixBase))


def _vector(v) -> bool:
    return isinstance(v, sp.MatrixBase) and v.shape == (3, 1)


def is_tensor(v) -> bool:
    return isinstance(v, sp.MatrixBase) and v.shape == (3, 3)


def is_scalar(v) -> bool:
    return not isinstance(v, sp.MatrixBase)


def kind(v) -> str:
    """'scalar', 'vector', 'tensor' or '<n>x<m> matrix'."""
    return "vector" if _vector(v) else "tensor" if is_tensor(v) else "scalar" if is_scalar(v) \
        else f"{v.shape[0]}x{v.shape[1]} matrix"


def _need(what: str, test: Callable, *args) -> None:
    for a in args:
        if not test(a):
            raise TypeError(f"expected a {what}, got a {kind(a)}")


def _im(m: sp.MatrixBase) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(m)


def _dyad(a, b):
    _need("vector", _vector, a, b)
    return _im(a * b.T)


def _dot(a, b):
    if _vector(a) and _vector(b):
        return a.dot(b)
    if _vector(a) and is_tensor(b):  # v·T
        return _im(b.T * a)
    if is_tensor(a) and (is_tensor(b) or _vector(b)):
        return _im(a * b)
    raise TypeError(f"dot of a {kind(a)} and a {kind(b)}")


def _ddot(a, b):
    """The double dot product A:B = Σ A_ij B_ij of two tensors."""
    _need("tensor", is_tensor, a, b)
    return sum((a[i, j] * b[i, j] for i in range(3) for j in range(3)), sp.S.Zero)


def _cross(a, b):
    """u × v; with a tensor, the dyadic rule: w × (AB) = (w × A)B, (AB) × w = A(B × w)."""
    if _vector(a) and is_tensor(b):
        return _im(_skew(a) * b)
    if is_tensor(a) and _vector(b):
        return _im(a * _skew(b))
    _need("vector", _vector, a, b)
    return _im(a.cross(b))


def _transpose(t):
    _need("tensor", is_tensor, t)
    return _im(t.T)


def _det(t):
    _need("tensor", is_tensor, t)
    return t.det(method="berkowitz")


def _trace(t):
    _need("tensor", is_tensor, t)
    return t.trace()


def _second_invariant(t):
    """Symon's M(T), Eq. (10-139): the sum of the three principal 2×2 minors."""
    _need("tensor", is_tensor, t)
    return sum((t[i, i] * t[j, j] - t[i, j] * t[j, i] for i, j in ((0, 1), (1, 2), (0, 2))),
               sp.S.Zero)


def _inverse(t):
    _need("tensor", is_tensor, t)
    d = _det(t)
    if d == 0:
        raise ValueError("the tensor is singular (determinant 0)")
    return _im(t.adjugate() / d)


def _unit():
    return _im(sp.eye(3))


def _rotation(axis, angle):
    """The orthogonal tensor turning vectors through `angle` about `axis` (right hand)."""
    _need("vector", _vector, axis)
    _need("scalar", is_scalar, angle)
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
    if j is None and is_tensor(t):
        raise TypeError("a tensor's entry takes two indices: entry(T, i, j)")
    if j is not None and _vector(t):
        raise TypeError("a vector's entry takes one index: entry(v, i)")
    if j is None:
        _need("vector", _vector, t)
        return t[_index(i), 0]
    _need("tensor", is_tensor, t)
    return t[_index(i), _index(j)]


def _row(t, i):
    """Row i (1-based) of a tensor's matrix, as a vector (e'_i for a transformation a)."""
    _need("tensor", is_tensor, t)
    return _im(t[_index(i), :].T)


def _col(t, j):
    _need("tensor", is_tensor, t)
    return _im(t[:, _index(j)])


VARIABLE = "var"  # the label of a `for_all` variable's symbol, x.var (verify.instances)


def for_all_name(symbol) -> str | None:
    """The `for_all` name a symbol of a generic object belongs to (x of x.var, T of T.12),
    None for a parameter or any other plain name (those never hold a '.')."""
    if isinstance(symbol, sp.Symbol) and "." in symbol.name:
        return symbol.name.split(".", 1)[0]
    return None


def is_variable(symbol) -> bool:
    """A `for_all` name of kind `variable`: it stays a symbol while a statement is built
    (from the generic objects or from one instance), so calculus may act on it."""
    return isinstance(symbol, sp.Symbol) and symbol.name.endswith("." + VARIABLE)


def _calculus_symbol(s, verb: str) -> sp.Symbol:
    """The symbol that `verb` (differentiate with respect to, integrate over, ...) acts on:
    a parameter or a `for_all` variable. Any other `for_all` object is a number at each of
    the instances a statement may be built from (mechbook.verify.instances), so it is
    refused always, whichever way the statement is built."""
    if is_variable(s) or (isinstance(s, sp.Symbol) and for_all_name(s) is None):
        return s
    generic = [x for x in getattr(s, "free_symbols", ()) if for_all_name(x)]
    owners = sorted({for_all_name(x) for x in generic})
    if owners and all(x.name.endswith(".x") for x in generic):  # scalar, positive, angle
        name = owners[0]
        raise TypeError(f"to {verb} {name!r}, declare it a variable (for_all: {{{name}: "
                        f"variable}}): a `for_all` object of another kind is drawn as "
                        "numbers at each instance")
    if owners:  # a vector, tensor or rotation (or a component of one): not a scalar
        name = owners[0]
        raise TypeError(f"to {verb} {name!r} (or a component of it): it is a generic "
                        "vector, tensor or rotation, drawn as numbers at each instance, and "
                        "a `variable` is a scalar; declare its components as variables "
                        "(for_all: {a1: variable, a2: variable, a3: variable}) and write "
                        "the vector [a1, a2, a3]")
    raise TypeError(f"{verb} a plain symbol: a parameter, or a `for_all` name of kind "
                    "`variable` (for_all: {x: variable})")


def _diff(x, s):
    """d/ds of a scalar, vector or tensor; s a parameter or a `for_all` variable."""
    s = _calculus_symbol(s, "differentiate with respect to")
    if isinstance(x, sp.MatrixBase):  # entry by entry (SymPy's Matrix.diff goes through
        # its array-derivative machinery, several times slower for the same entries)
        return _im(x.applyfunc(lambda e: derivative(e, s)))
    return derivative(x, s) if isinstance(x, sp.Basic) else sp.diff(x, s)


def _coordinates(r) -> list[sp.Symbol]:
    """The position [x, y, z] of grad and div: three parameters or `for_all` variables."""
    _need("vector", _vector, r)
    return [_calculus_symbol(c, "differentiate along") for c in r]


def _grad(x, r):
    """∇f (a vector) of a scalar field, or the dyad ∇v, (∇v)_ij = ∂v_j/∂x_i (Symon Eq.
    10-175), of a vector field; `r` = [x, y, z], Cartesian."""
    xs = _coordinates(r)
    if is_scalar(x):
        return _im(sp.Matrix([sp.diff(x, c) for c in xs]))
    _need("vector", _vector, x)
    return _im(sp.Matrix(3, 3, lambda i, j: sp.diff(x[j], xs[i])))


def _div(x, r):
    """∇·v of a vector field (a scalar), or ∇·P, (∇·P)_j = Σ_i ∂P_ij/∂x_i, of a tensor."""
    xs = _coordinates(r)
    if _vector(x):
        return sum((sp.diff(x[i], xs[i]) for i in range(3)), sp.S.Zero)
    _need("tensor", is_tensor, x)
    return _im(sp.Matrix([sum((sp.diff(x[i, j], xs[i]) for i in range(3)), sp.S.Zero)
                          for j in range(3)]))


def _subs(x, s, v):
    """x with the symbol s replaced by the scalar v (a boundary value, a change of
    variables)."""
    s = _calculus_symbol(s, "substitute for")
    _need("scalar", is_scalar, v)
    return _im(x.xreplace({s: v})) if isinstance(x, sp.MatrixBase) else x.xreplace({s: v})


def _integral(f, s, lo, hi):
    """The definite integral of a scalar over s from lo to hi (SymPy's integrate; an
    integral it cannot do in closed form is an error)."""
    s = _calculus_symbol(s, "integrate over")
    _need("scalar", is_scalar, f, lo, hi)
    out = sp.integrate(f, (s, lo, hi))
    if out.has(sp.Integral):
        raise ValueError("SymPy finds no closed form for this integral")
    return out


def _norm(v):
    _need("vector", _vector, v)
    return sp.sqrt(v.dot(v))


def _scalar_fn(fn):
    def apply(x):
        _need("scalar", is_scalar, x)
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
