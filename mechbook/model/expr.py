"""Safe expression parser: problem text becomes SymPy objects without ever reaching `eval`.

`sympify`, `parse_expr` and `lambdify` of strings all call Python's `eval`, so a problem file
could run arbitrary code through them. Here the text is parsed by `ast.parse` (which only
parses) and the tree is walked with a whitelist of node types, operators, functions and
names; anything else is rejected with a message that says what and where.

Two checks guard what the text means rather than how it reads: every constant a node
produces must be finite and real (`1/0` is SymPy's complex infinity, `sqrt(-1)` the
imaginary unit: neither belongs in a Lagrangian or a book's answer), and names that stand
for expressions (abbreviations, `define:` forms, driven coordinates) count with the size of
what they stand for, so a chain of abbreviations cannot build an expression that doubles at
every step.
"""

from __future__ import annotations

import ast
import io
import math
import tokenize
import unicodedata
import warnings
from collections.abc import Mapping

import sympy as sp

from mechbook.core.special import PARSER_FUNCTIONS as SPECIAL
from mechbook.errors import ExpressionError
from mechbook.model.constants import bad_constant
from mechbook.model.hints import did_you_mean, operator_hint

MAX_LENGTH = 20_000  # characters in one expression
MAX_NODES = 5_000  # AST nodes in one expression
MAX_DEPTH = 60  # nesting of brackets
MAX_AST_DEPTH = 400  # nesting of the parsed tree (a flat sum of n terms is n deep)
MAX_DIGITS = 1000  # largest number of digits a numeric power may produce
MAX_EXPONENT = 64  # largest |numeric exponent| accepted
MAX_INTEGER = 10**30  # largest integer literal accepted
MAX_LITERAL = 1e100  # largest |decimal literal| (SI constants: the sun's mass 2e30 kg ...)
MIN_LITERAL = 1e-100  # smallest nonzero |decimal literal| (... Planck's constant 6.6e-34)
MAX_SUBSTITUTED = 20_000  # tree size of one expression with its names' expressions put in
MAX_SUBSTITUTED_TENSOR = 500_000  # the same for a tensor expression (nine entries of products
# of generic rotations are large; a chain of abbreviations doubling each time still is not)

FUNCTIONS: dict[str, object] = {
    "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "cot": sp.cot, "sec": sp.sec, "csc": sp.csc,
    "asin": sp.asin, "acos": sp.acos, "atan": sp.atan, "atan2": sp.atan2,
    "sinh": sp.sinh, "cosh": sp.cosh, "tanh": sp.tanh,
    "asinh": sp.asinh, "acosh": sp.acosh, "atanh": sp.atanh,
    "exp": sp.exp, "log": sp.log, "sqrt": sp.sqrt, "Abs": sp.Abs, "abs": sp.Abs,
    "sign": sp.sign, "cbrt": sp.cbrt,
    # special functions books write periods with: the complete elliptic integrals of the
    # first and second kind in SymPy's (and mpmath's) parameter m = k², K(m) and E(m)
    # (a pendulum of amplitude θ0: T = 4·sqrt(l/g)·K(sin²(θ0/2))), and Euler's Γ(x)
    "elliptic_k": sp.elliptic_k, "elliptic_e": sp.elliptic_e, "gamma": sp.gamma,
    # and, in the same parameter m (mechbook.core.special): the incomplete integrals
    # elliptic_f(φ, m), elliptic_e(φ, m), elliptic_pi(n[, φ], m), Jacobi's jacobi_sn(u, m),
    # jacobi_cn, jacobi_dn, Bessel's besselj(ν, x), bessely(ν, x) and their n-th positive
    # zeros bessel_j_zero(ν, n), bessel_y_zero(ν, n)
    **{name: fn for name, (fn, _) in SPECIAL.items()},
}
# function names a problem or answer key may also declare as names of its own (gamma is a
# common parameter, coordinate or angle): where it does, the name is its own and a call of
# the function is refused
DECLARABLE = frozenset({"gamma"})
def _diff(expr, var, times=1):
    """diff(expr, x[, n]): the derivative with respect to a declared name (at most 6th)."""
    if not isinstance(var, sp.Symbol):
        raise ValueError("differentiate with respect to a declared name")
    if not (isinstance(times, int | sp.Integer) and 1 <= int(times) <= 6):
        raise ValueError("the order is a whole number from 1 to 6")
    return sp.diff(expr, var, int(times))


FUNCTIONS["diff"] = _diff
ARITY = {"atan2": (2, 2), "log": (1, 2), "diff": (2, 3),
         **{name: arity for name, (_, arity) in SPECIAL.items()}}
CONSTANTS: dict[str, sp.Expr] = {"pi": sp.pi}  # E and I stay free: books use them as symbols


class Operator:
    """A function a quantity offers to the expressions of its own parts (e.g. a perturbation
    coefficient W0(j), or sum(expr, r)): called by name with the parsed arguments. The
    safe parser knows only this class; what it computes is the quantity's business."""

    def __init__(self, name: str, fn, arity: tuple[int, int]):
        self.name, self.fn, self.arity = name, fn, arity

    def __call__(self, *args):
        return self.fn(*args)


# values that are statements, not numbers (a Symbol is also a SymPy Boolean, so not that)
_TRUTHS = (sp.core.relational.Relational, sp.logic.boolalg.BooleanFunction,
           sp.logic.boolalg.BooleanAtom)

_BINOPS = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.Pow: None,  # handled separately (size check)
}
_COMPARE = {ast.Lt: sp.StrictLessThan, ast.LtE: sp.LessThan,
            ast.Gt: sp.StrictGreaterThan, ast.GtE: sp.GreaterThan, ast.NotEq: sp.Ne}


def _depth(text: str) -> int:
    depth = best = 0
    for ch in text:
        if ch in "([{":
            depth += 1
            best = max(best, depth)
        elif ch in ")]}":
            depth -= 1
    return best


_NOT_FINITE = (sp.zoo, sp.oo, -sp.oo, sp.nan)


def tree_size(expr: sp.Basic, memo: dict | None = None) -> int:
    """Nodes of `expr` written out as a tree (shared subexpressions counted each time they
    occur), computed over the DAG in time proportional to its distinct nodes."""
    memo = {} if memo is None else memo
    stack = [expr]
    while stack:
        node = stack[-1]
        if node in memo:
            stack.pop()
            continue
        pending = [a for a in node.args if a not in memo]
        if pending:
            stack.extend(pending)
            continue
        stack.pop()
        memo[node] = 1 + sum(memo[a] for a in node.args)
    return memo[expr]


class ExprBuilder:
    def __init__(self, text: str, names: Mapping[str, sp.Basic], allow_relations: bool):
        self.text = text
        self.source = text.strip()
        self.names = names
        self.allow_relations = allow_relations
        self.nodes = 0
        self.substituted = 0
        self.sizes: dict = {}
        self.values: dict = {}  # float values of constants (mechbook.model.constants)

    def fail(self, node: ast.AST | None, what: str) -> ExpressionError:
        col = getattr(node, "col_offset", None)
        where = f" at column {col + 1}" if col is not None else ""
        return ExpressionError(f"{what}{where} in expression {self.text!r}", self.text)

    def build(self, node: ast.AST, depth: int = 0, operand: bool = False) -> sp.Basic:
        """The SymPy value of `node`; with `operand`, it must be a value, not a comparison
        (an operand of arithmetic or a function's argument)."""
        self.nodes += 1
        if self.nodes > MAX_NODES:
            raise self.fail(None, f"expression too large (more than {MAX_NODES} nodes)")
        if depth > MAX_AST_DEPTH:
            raise self.fail(node, f"expression nested too deeply (more than {MAX_AST_DEPTH})")
        method = getattr(self, "_" + type(node).__name__, None)
        if method is None:
            raise self.fail(node, f"{type(node).__name__} is not allowed")
        try:
            result = method(node, depth + 1)
            if isinstance(node, ast.BinOp | ast.UnaryOp | ast.Call):
                self._check_constant(node, result)
        except (TypeError, ValueError, ArithmeticError, AttributeError) as exc:
            # SymPy refused to build or to evaluate it (mpmath overflows on exp(exp(...)))
            raise self.fail(node, f"invalid operation ({type(exc).__name__}: {exc})") \
                from None
        if operand and isinstance(result, _TRUTHS):  # a relation, and/or, true/false
            raise self.fail(node, "a comparison (or and/or) cannot be an operand; it is "
                                  "allowed only as the whole expression")
        return result

    complex_ok = False  # tensor expressions build complex numbers on purpose (i(), expi())
    max_substituted = MAX_SUBSTITUTED

    def _check_constant(self, node: ast.AST, result: sp.Basic) -> None:
        """The node's value, and the constants directly in it (x/0 is zoo*x), must be finite
        and real (finite, where complex numbers are allowed); nodes are built bottom-up, so a
        bad constant is caught where it arises."""
        parts = list(result) if isinstance(result, sp.MatrixBase) else [result, *result.args]
        for part in parts:
            why = bad_constant(part, self.values, self.complex_ok)
            if why:
                segment = ast.get_source_segment(self.source, node) or self.text
                raise self.fail(node, f"{segment!r} {why} (its value is {part})")

    def _Expression(self, node: ast.Expression, depth: int) -> sp.Basic:
        return self.build(node.body, depth)

    def _Constant(self, node: ast.Constant, depth: int) -> sp.Basic:
        value = node.value
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(node, f"constant {value!r} is not a number")
        if isinstance(value, int):
            if abs(value) > MAX_INTEGER:
                raise self.fail(node, "integer literal too large")
            return sp.Integer(value)
        # decimal literals are read exactly from their source text (0.5 -> 1/2, all digits
        # kept) so symbolic checks stay exact
        literal = ast.get_source_segment(self.source, node) or repr(value)
        if not math.isfinite(value) or (value != 0
                                        and not MIN_LITERAL <= abs(value) <= MAX_LITERAL):
            raise self.fail(node, f"number {literal} out of range")
        try:
            return sp.Rational(literal.replace("_", ""))
        except (TypeError, ValueError):
            raise self.fail(node, f"cannot read number {literal}") from None

    def _Name(self, node: ast.Name, depth: int) -> sp.Basic:
        name = node.id
        if name.startswith("_"):
            raise self.fail(node, f"name {name!r} is not allowed (leading underscore)")
        if name in self.names:
            value = self.names[name]
            if isinstance(value, Operator):
                raise self.fail(node, f"function {name!r} used without a call")
            entries = list(value) if isinstance(value, sp.MatrixBase) else [value]
            if any(e.args for e in entries):  # a name standing for an expression (or a
                # vector or tensor of them): count what it brings
                self.substituted += sum(tree_size(e, self.sizes) for e in entries)
                if self.substituted > self.max_substituted:
                    raise self.fail(node, "expression too large once its names are "
                                    f"substituted (more than {self.max_substituted} nodes)")
            return value
        if name in CONSTANTS:
            return CONSTANTS[name]
        if name in FUNCTIONS:
            raise self.fail(node, f"function {name!r} used without a call")
        hint = did_you_mean(name, [*self.names, *CONSTANTS])
        raise self.fail(node, f"unknown name {name!r} ({hint + ' or ' if hint else ''}"
                              "declare it as a parameter or coordinate)")

    def _UnaryOp(self, node: ast.UnaryOp, depth: int) -> sp.Basic:
        operand = self.build(node.operand, depth, True)
        if isinstance(node.op, ast.USub):
            return -operand
        if isinstance(node.op, ast.UAdd):
            return operand
        raise self.fail(node, f"operator {operator_hint(type(node.op).__name__)}")

    def _BinOp(self, node: ast.BinOp, depth: int) -> sp.Basic:
        op = type(node.op)
        if op not in _BINOPS:
            raise self.fail(node, f"operator {operator_hint(op.__name__)}")
        left = self.build(node.left, depth, True)
        right = self.build(node.right, depth, True)
        if op is ast.Pow:
            if right.is_Number and abs(right) > MAX_EXPONENT:
                raise self.fail(node, f"exponent {right} too large (at most {MAX_EXPONENT})")
            if left.is_Number and right.is_Number and left != 0 and \
                    float(abs(right)) * math.log10(max(float(abs(left)), 2.0)) > MAX_DIGITS:
                raise self.fail(node, f"power too large (more than {MAX_DIGITS} digits)")
            result = left**right
            for power in [result, *result.atoms(sp.Pow)]:
                if isinstance(power, sp.Pow) and power.exp.is_Number \
                        and abs(power.exp) > MAX_EXPONENT**2:
                    raise self.fail(node, "power too large (a tower of exponents)")
            for number in result.atoms(sp.Rational):
                if max(abs(number.p), number.q) > 10**MAX_DIGITS:
                    raise self.fail(node, f"power too large (more than {MAX_DIGITS} digits)")
            return result
        return _BINOPS[op](left, right)

    def _Call(self, node: ast.Call, depth: int) -> sp.Basic:
        if not isinstance(node.func, ast.Name):
            raise self.fail(node, "only calls of whitelisted functions by name are allowed")
        name = node.func.id
        op = self.names.get(name)
        if op is not None and not isinstance(op, Operator) and name in FUNCTIONS:
            raise self.fail(node, f"{name!r} is a declared name here, so {name}() is not the "
                                  "function: rename it to use the function")
        if name not in FUNCTIONS and not isinstance(op, Operator):
            known = [*FUNCTIONS, *(k for k, v in self.names.items() if isinstance(v, Operator))]
            hint = did_you_mean(name, known)
            raise self.fail(node, f"call of unknown function {name!r}"
                                  + (f" ({hint})" if hint else ""))
        if node.keywords:
            raise self.fail(node, f"keyword arguments are not allowed in {name}()")
        lo, hi = op.arity if isinstance(op, Operator) else ARITY.get(name, (1, 1))
        if not lo <= len(node.args) <= hi:
            raise self.fail(node, f"{name}() takes {lo if lo == hi else f'{lo} to {hi}'} "
                                  f"argument(s), got {len(node.args)}")
        args = [self.build(a, depth, True) for a in node.args]
        if isinstance(op, Operator):
            try:
                return op(*args)
            except (TypeError, ValueError) as exc:
                raise self.fail(node, f"{name}(): {exc}") from None
        try:
            return FUNCTIONS[name](*args)
        except ValueError as exc:
            raise self.fail(node, f"{name}(): {exc}") from None

    def _Compare(self, node: ast.Compare, depth: int) -> sp.Basic:
        if not self.allow_relations:
            raise self.fail(node, "a comparison is not allowed here")
        terms = [self.build(node.left, depth, True)] + [self.build(c, depth, True)
                                                       for c in node.comparators]
        rels = []
        for op, a, b in zip(node.ops, terms, terms[1:], strict=False):
            if type(op) not in _COMPARE:
                raise self.fail(node, f"comparison {operator_hint(type(op).__name__)}")
            rels.append(_COMPARE[type(op)](a, b, evaluate=False))
        return sp.And(*rels, evaluate=False) if len(rels) > 1 else rels[0]

    def _BoolOp(self, node: ast.BoolOp, depth: int) -> sp.Basic:
        if not self.allow_relations:
            raise self.fail(node, "and/or is not allowed here")
        parts = [self.build(v, depth) for v in node.values]
        for v, part in zip(node.values, parts, strict=True):
            if not isinstance(part, sp.logic.boolalg.Boolean):
                raise self.fail(v, "and/or joins comparisons, not values")
        return sp.And(*parts) if isinstance(node.op, ast.And) else sp.Or(*parts)


def syntax_tree(text: str | int | float) -> tuple[str, ast.Expression]:
    """The text (a number's repr) and its Python syntax tree, after the limits on length
    and nesting; ExpressionError for anything else, a syntax error with its column."""
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
    _refuse_folded(text)
    try:
        with warnings.catch_warnings():  # '\ ' in a string literal warns; it is refused anyway
            warnings.simplefilter("ignore")
            tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        col = f" at column {exc.offset}" if exc.offset else ""
        raise ExpressionError(f"syntax error{col} in expression {text!r}: {exc.msg}",
                              text) from None
    except (RecursionError, MemoryError, ValueError):
        raise ExpressionError(f"expression {text[:60]!r} cannot be parsed safely", text) from None
    return text, tree


def _refuse_folded(text: str) -> None:
    """Python reads identifiers in NFKC form, so a fullwidth 'ｍ' or a ligature 'ﬁ' would
    silently be the name 'm' or 'fi': refuse any character that normalization changes."""
    if text.isascii():
        return
    for col, ch in enumerate(text, 1):
        folded = unicodedata.normalize("NFKC", ch)
        if folded != ch:
            raise ExpressionError(f"character {ch!r} (U+{ord(ch):04X}) at column {col} would "
                                  f"be read as {folded!r}: write {folded!r}", text)


def parse(text: str | int | float, names: Mapping[str, sp.Basic] | None = None,
          allow_relations: bool = False, complex_ok: bool = False) -> sp.Basic:
    """Parse one expression (or, with allow_relations, a condition such as ``a < b``).
    Constants must be finite and real; with `complex_ok` (an answer whose values are complex
    on purpose: exponents, complex modes) finite complex constants such as sqrt(-1) are
    allowed."""
    names = names or {}
    text, tree = syntax_tree(text)
    builder = ExprBuilder(text, names, allow_relations)
    builder.complex_ok = complex_ok
    try:
        result = builder.build(tree)
    except RecursionError:  # MAX_AST_DEPTH keeps clear of it; a deep caller may not
        raise ExpressionError(f"expression {text[:60]!r} nested too deeply", text) from None
    if isinstance(result, sp.Basic) and (result.has(*_NOT_FINITE)
                                         or (result.has(sp.I) and not complex_ok)):
        raise ExpressionError(f"expression {text!r} holds a constant that is not finite "
                              f"and real: {result}", text)
    return result


def parse_equation(text: str, names: Mapping[str, sp.Basic] | None = None,
                   complex_ok: bool = False) -> sp.Expr:
    """Parse ``lhs = rhs`` (or a bare ``expr`` meaning ``expr = 0``) into ``lhs - rhs``."""
    if not isinstance(text, str):
        return parse(text, names, complex_ok=complex_ok)
    pieces = split_single_equals(text)
    if len(pieces) == 1:
        return parse(pieces[0], names, complex_ok=complex_ok)
    if len(pieces) == 2:
        return (parse(pieces[0], names, complex_ok=complex_ok)
                - parse(pieces[1], names, complex_ok=complex_ok))
    raise ExpressionError(f"more than one '=' in equation {text!r}", text)


def split_single_equals(text: str) -> list[str]:
    out, start = [], 0
    for i, ch in enumerate(text):
        if ch == "=":
            prev = text[i - 1] if i else ""
            nxt = text[i + 1] if i + 1 < len(text) else ""
            if prev in "<>=!" or nxt == "=":
                continue
            out.append(text[start:i])
            start = i + 1
    out.append(text[start:])
    return out


DOUBLE_DIGITS = 15  # the significant digits a binary64 number carries


def decimal_digits(text) -> int:
    """The most significant digits a decimal literal (a number with a point or an exponent)
    is written with in `text`; 0 if it writes none. Integers are exact and not counted.
    A literal longer than a double carries (a root to 36 digits) is a rounded value: true
    to its digits, not beyond them. Example: decimal_digits("1.8751040687*x + 2") == 11."""
    if isinstance(text, float):  # a YAML number: the digits of its shortest repr
        text = repr(text)
    if not isinstance(text, str):
        return 0
    most = 0
    try:
        for tok in tokenize.generate_tokens(io.StringIO(text).readline):
            if tok.type != tokenize.NUMBER:
                continue
            body = tok.string.lower().replace("_", "")
            if body.startswith(("0x", "0o", "0b")) or body.endswith("j") \
                    or not ("." in body or "e" in body):
                continue
            mantissa = body.split("e")[0].replace(".", "").lstrip("0")
            most = max(most, len(mantissa.rstrip("0")) if "." not in body.split("e")[0]
                       else len(mantissa))
    except (tokenize.TokenError, IndentationError, SyntaxError):
        pass  # what the parser itself refuses is reported there
    return most
