"""A book's expression drawn as mathematics from its syntax alone.

Some book values have no single SymPy object to show: identities "for all tensors" of
Symon's chapter 10 (`cross(row(a, 1), row(a, 2)) = det(a)*row(a, 3)`), or text the part's
own context cannot build. They used to be shown as code. Here the text is parsed by
`ast.parse` (which only parses: nothing is evaluated) and each node is written as MathML in
the book's notation: dot and cross products, dyads, transposes, inverses, determinants,
traces, components, norms, matrices, with Greek letters, subscripts and dotted rates for the
names. Text that does not parse at all is left to the caller (shown as code).
"""

from __future__ import annotations

import ast
import html

from mechbook.app.output.mathml import NS, identifier_mathml

_PREC = {ast.Add: 1, ast.Sub: 1, ast.Mult: 2, ast.Div: 2, ast.Pow: 4}
_REL = {ast.Lt: "&lt;", ast.LtE: "≤", ast.Gt: "&gt;", ast.GtE: "≥", ast.NotEq: "≠",
        ast.Eq: "="}
_NAMED = {"sin", "cos", "tan", "cot", "sec", "csc", "sinh", "cosh", "tanh", "exp", "log",
          "asin", "acos", "atan", "asinh", "acosh", "atanh", "det", "trace", "re", "im"}
MAX_CHARS = 4000


def syntax_math(text: str) -> str | None:
    """MathML of `text` (an expression, `lhs = rhs`, or a relation), or None."""
    if not isinstance(text, str) or len(text) > MAX_CHARS:
        return None
    sides = _split_equation(text)
    try:
        trees = [ast.parse(s.strip(), mode="eval").body for s in sides]
    except (SyntaxError, ValueError, RecursionError):
        return None
    try:
        body = '<mo>=</mo>'.join(_node(t, 0) for t in trees)
    except (_Unknown, RecursionError):
        return None
    return f'<math xmlns="{NS}" display="block"><mrow>{body}</mrow></math>'


class _Unknown(Exception):
    pass


def _split_equation(text: str) -> list[str]:
    out, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == "=" and depth == 0:
            prev = text[i - 1] if i else ""
            nxt = text[i + 1] if i + 1 < len(text) else ""
            if prev not in "<>=!" and nxt != "=":
                out.append(text[start:i])
                start = i + 1
    out.append(text[start:])
    return out


def _wrap(inner: str, need: bool) -> str:
    return f"<mrow><mo>(</mo>{inner}<mo>)</mo></mrow>" if need else f"<mrow>{inner}</mrow>"


def _node(node: ast.AST, outer: int) -> str:  # noqa: C901 - one case per kind of node
    if isinstance(node, ast.Constant) and isinstance(node.value, int | float) \
            and not isinstance(node.value, bool):
        return f"<mn>{html.escape(repr(node.value))}</mn>"
    if isinstance(node, ast.Name):
        return "<mi>π</mi>" if node.id == "pi" else identifier_mathml(node.id)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        sign = "−" if isinstance(node.op, ast.USub) else "+"
        return _wrap(f"<mo>{sign}</mo>{_node(node.operand, 3)}", outer > 2)
    if isinstance(node, ast.BinOp) and type(node.op) in _PREC:
        prec = _PREC[type(node.op)]
        if isinstance(node.op, ast.Div):
            return f"<mfrac>{_node(node.left, 0)}{_node(node.right, 0)}</mfrac>"
        if isinstance(node.op, ast.Pow):
            return f"<msup>{_node(node.left, 5)}{_node(node.right, 0)}</msup>"
        op = {ast.Add: "+", ast.Sub: "−", ast.Mult: "⋅"}[type(node.op)]
        right = _node(node.right, prec + (1 if isinstance(node.op, ast.Sub) else 0))
        return _wrap(f"{_node(node.left, prec)}<mo>{op}</mo>{right}", outer > prec)
    if isinstance(node, ast.Compare) and all(type(o) in _REL for o in node.ops):
        parts = [_node(node.left, 0)]
        for op, right in zip(node.ops, node.comparators, strict=True):
            parts += [f"<mo>{_REL[type(op)]}</mo>", _node(right, 0)]
        return _wrap("".join(parts), outer > 0)
    if isinstance(node, ast.BoolOp):
        word = " and " if isinstance(node.op, ast.And) else " or "
        return _wrap(f"<mtext>{word}</mtext>".join(_node(v, 0) for v in node.values),
                     outer > 0)
    if isinstance(node, ast.List):
        return _list(node)
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        return _call(node.func.id, node.args, outer)
    raise _Unknown(type(node).__name__)


def _list(node: ast.List) -> str:
    if node.elts and all(isinstance(e, ast.List) for e in node.elts):
        rows = "".join("<mtr>" + "".join(f"<mtd>{_node(c, 0)}</mtd>" for c in r.elts)
                       + "</mtr>" for r in node.elts)
    else:
        rows = "".join(f"<mtr><mtd>{_node(c, 0)}</mtd></mtr>" for c in node.elts)
    return f"<mrow><mo>[</mo><mtable>{rows}</mtable><mo>]</mo></mrow>"


def _call(name: str, args: list, outer: int) -> str:  # noqa: C901 - one case per function
    a = [_node(x, 3) for x in args]
    if name == "dot" and len(a) == 2:
        return _wrap(f"{a[0]}<mo>⋅</mo>{a[1]}", outer > 2)
    if name == "cross" and len(a) == 2:
        return _wrap(f"{a[0]}<mo>×</mo>{a[1]}", outer > 2)
    if name == "ddot" and len(a) == 2:
        return _wrap(f"{a[0]}<mo>:</mo>{a[1]}", outer > 2)
    if name == "dyad" and len(a) == 2:
        return f"<mrow>{a[0]}{a[1]}</mrow>"
    if name == "transpose" and len(a) == 1:
        return f"<msup>{_node(args[0], 5)}<mi>T</mi></msup>"
    if name == "inverse" and len(a) == 1:
        return f"<msup>{_node(args[0], 5)}<mrow><mo>−</mo><mn>1</mn></mrow></msup>"
    if name == "unit" and not a:
        return '<mn mathvariant="bold">1</mn>'
    if name == "i" and not a:
        return "<mi>i</mi>"
    if name == "norm" and len(a) == 1:
        return f"<mrow><mo>‖</mo>{_node(args[0], 0)}<mo>‖</mo></mrow>"
    if name in ("Abs", "abs") and len(a) == 1:
        return f"<mrow><mo>|</mo>{_node(args[0], 0)}<mo>|</mo></mrow>"
    if name == "sqrt" and len(a) == 1:
        return f"<msqrt>{_node(args[0], 0)}</msqrt>"
    if name == "entry" and len(a) in (2, 3):
        index = "".join(_node(x, 0) for x in args[1:])
        return f"<msub>{_node(args[0], 5)}<mrow>{index}</mrow></msub>"
    if name in ("row", "col") and len(a) == 2:
        return (f"<mrow><msub><mi mathvariant=\"normal\">{name}</mi>{_node(args[1], 0)}"
                f"</msub><mo>(</mo>{_node(args[0], 0)}<mo>)</mo></mrow>")
    if name == "second_invariant" and len(a) == 1:
        return f"<mrow><mi>M</mi><mo>(</mo>{_node(args[0], 0)}<mo>)</mo></mrow>"
    label = f"<mi>{html.escape(name)}</mi>" if name in _NAMED else \
        f'<mi mathvariant="normal">{html.escape(name)}</mi>'
    inner = "<mo>,</mo>".join(_node(x, 0) for x in args)
    return f"<mrow>{label}<mo>&#x2061;</mo><mo>(</mo>{inner}<mo>)</mo></mrow>"
