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
from collections.abc import Mapping

import sympy as sp
from sympy.matrices.utilities import dotprodsimp

from mechbook.errors import ExpressionError
from mechbook.model.expr import (
    MAX_SUBSTITUTED_TENSOR,
    ExprBuilder,
    split_single_equals,
    syntax_tree,
)
from mechbook.model.tensorfuncs import (  # noqa: F401 - `kind` is this module's API too
    BODY_FUNCTIONS,
    TENSOR_ARITY,
    TENSOR_FUNCTIONS,
    holds_matrix,
    is_scalar,
    is_tensor,
    kind,
)


class _TensorBuilder(ExprBuilder):
    complex_ok = True  # eigenvalues of rotations: i(), expi(theta)
    max_substituted = MAX_SUBSTITUTED_TENSOR

    def __init__(self, text: str, names: Mapping, objects: Mapping):
        super().__init__(text, names, False)
        self.objects = objects

    def _List(self, node: ast.List, depth: int):
        items = [self.build(e, depth) for e in node.elts]
        if len(items) == 3 and all(is_scalar(x) for x in items):
            return sp.ImmutableMatrix(items)
        if len(items) == 3 and all(isinstance(x, sp.MatrixBase) and x.shape == (3, 1)
                                   for x in items):
            return sp.ImmutableMatrix([[x[k] for k in range(3)] for x in items])
        raise self.fail(node, "a list is a vector [x, y, z] or a tensor [[..], [..], [..]]")

    def _BinOp(self, node: ast.BinOp, depth: int):
        if isinstance(node.op, ast.Pow):
            base, exponent = self.build(node.left, depth), self.build(node.right, depth)
            if isinstance(base, sp.MatrixBase) or isinstance(exponent, sp.MatrixBase):
                if not (is_tensor(base) and is_scalar(exponent) and exponent.is_Integer
                        and abs(exponent) <= 16):
                    raise self.fail(node, "only a tensor has powers, with an integer exponent "
                                    "(at most 16 in size)")
                try:
                    return sp.ImmutableMatrix(base**int(exponent))
                except (ValueError, ZeroDivisionError) as exc:
                    raise self.fail(node, f"cannot raise this tensor to {exponent} ({exc})") \
                        from None
        try:
            out = super()._BinOp(node, depth)
        except (TypeError, ValueError, NotImplementedError, sp.ShapeError,
                sp.NonSquareMatrixError) as exc:
            raise self.fail(node, f"cannot combine these operands ({exc})") from None
        if not isinstance(out, sp.MatrixBase) and holds_matrix(out):
            raise self.fail(node, "a vector or tensor cannot be an exponent or a base here")
        if isinstance(out, sp.MatrixBase):
            if out.shape not in ((3, 1), (3, 3)):
                raise self.fail(node, f"the result is a {kind(out)}: use dot(u, v) for the "
                                "scalar product of vectors")
            return sp.ImmutableMatrix(out)
        return out

    def _UnaryOp(self, node: ast.UnaryOp, depth: int):
        out = super()._UnaryOp(node, depth)
        return sp.ImmutableMatrix(out) if isinstance(out, sp.MatrixBase) else out

    def _Call(self, node: ast.Call, depth: int):
        if not isinstance(node.func, ast.Name):
            raise self.fail(node, "only calls of whitelisted functions by name are allowed")
        name = node.func.id
        if name in BODY_FUNCTIONS:
            return self._body_call(node, depth)
        if name not in TENSOR_FUNCTIONS:
            out = super()._Call(node, depth)
            if holds_matrix(out):
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
    """Parse a scalar, vector or tensor expression (bodies named in `objects`).

    Without SymPy's intermediate simplification of matrix products (`dotprodsimp`, which
    its matrix powers and 3×3 determinants apply by default: a `cancel` of every entry,
    seconds for rational functions of a dozen symbols); the values are the same functions,
    left unsimplified like every other engine result."""
    names = names or {}
    text, tree = syntax_tree(text)
    with dotprodsimp(False):
        try:
            return _TensorBuilder(text, names, objects or {}).build(tree)
        except RecursionError:  # two frames a level here (500 unary minuses): as `parse`
            raise ExpressionError(f"expression {text[:60]!r} nested too deeply",
                                  text) from None


def parse_tensor_equation(text, names: Mapping[str, sp.Basic] | None = None,
                          objects: Mapping[str, object] | None = None):
    """`lhs = rhs` as the pair (lhs, rhs) of like objects; `= 0` stands for a zero vector or
    tensor too."""
    if not isinstance(text, str):
        raise ExpressionError(f"expected an equation 'lhs = rhs', got {text!r}")
    pieces = split_single_equals(text)
    if len(pieces) != 2:
        raise ExpressionError(f"expected one '=' in equation {text!r}", text)
    lhs = parse_tensor(pieces[0], names, objects)
    rhs = parse_tensor(pieces[1], names, objects)
    for a, b in ((lhs, rhs), (rhs, lhs)):
        if isinstance(a, sp.MatrixBase) and not isinstance(b, sp.MatrixBase) and b == 0:
            return (lhs, sp.ImmutableMatrix.zeros(*a.shape)) if a is lhs else \
                (sp.ImmutableMatrix.zeros(*a.shape), rhs)
    if kind(lhs) != kind(rhs):
        raise ExpressionError(f"the sides of {text!r} differ in kind: a {kind(lhs)} and a "
                              f"{kind(rhs)}", text)
    return lhs, rhs
