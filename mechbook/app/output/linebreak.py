"""Long formulas broken into lines that fit a column, as a typesetter would.

A browser lays a MathML formula out on one line however long it is: an unsimplified
Lagrangian or equation of motion four screens wide has to scroll. Here a formula is cut
into pieces at the places a mathematician breaks a line — between the terms of a sum, the
factors of a product, inside a bracket or a function's argument — each piece with its
estimated width (the characters of SymPy's text), and the pieces are packed greedily into
rows of at most `width` characters; an equation's '=' starts a row. A bracket opened on one
row may close on a later one (with its exponent), but never ends a row or starts one
alone; a product's denominator is written first as a factor 1/d. A piece that cannot be
cut (a long fraction) keeps its own row.
"""

from __future__ import annotations

import re
from collections.abc import Callable

import sympy as sp

Piece = tuple[str, int]  # (MathML fragment, estimated width in characters)
_NAMES = {"asin": "arcsin", "acos": "arccos", "atan": "arctan", "asinh": "arsinh",
          "acosh": "arcosh", "atanh": "artanh", "Abs": "abs"}


def rows(expr, width: int, inner: Callable[[object], str]) -> list[str] | None:
    """MathML rows of `expr` (an expression or an equation), each about `width`
    characters at most; None when it fits on one line."""
    if _size(expr) <= width:
        return None
    if isinstance(expr, sp.Equality):
        pieces = _pieces(expr.lhs, width, inner)
        right = _pieces(expr.rhs, width, inner)
        right[0] = ("<mo>=</mo>" + right[0][0], right[0][1] + 2)
        left = _pack(pieces, width)  # a short left side shares its line with the right
        lines = _pack(pieces + right, width) if len(left) == 1 else left + _pack(right, width)
    else:
        lines = _pack(_pieces(expr, width, inner), width)
    return lines if len(lines) > 1 else None


OPEN, CLOSE = "<mo>(</mo>", "<mo>)</mo>"


def _glued(pieces: list[Piece]) -> list[Piece]:
    """An opening bracket joined to what follows it, and a closing one (with its exponent)
    to what precedes it: a row never ends in '(' nor starts with ')', which a browser
    would draw alone and stretched to the row's height."""
    out: list[Piece] = []
    carry: Piece | None = None
    for text, size in pieces:
        if carry is not None:
            text, size, carry = carry[0] + text, carry[1] + size, None
        if text.startswith((CLOSE, "<msup>" + CLOSE)) and out:
            prev_text, prev_size = out.pop()
            text, size = prev_text + text, prev_size + size
        if text.endswith(OPEN):
            carry = (text, size)
            continue
        out.append((text, size))
    if carry is not None:
        out.append(carry)
    return out


def _pack(pieces: list[Piece], width: int) -> list[str]:
    pieces = _glued(pieces)
    out, current, used = [], "", 0
    for text, size in pieces:
        if current and used + size > width:
            out.append(current)
            current, used = "", 0
        current += text
        used += size
    if current:
        out.append(current)
    return out


_GREEK = re.compile(r"\b(?:alpha|beta|gamma|delta|epsilon|zeta|eta|theta|iota|kappa|lambda|mu"
                    r"|nu|xi|omicron|pi|rho|sigma|tau|upsilon|phi|chi|psi|omega)")


def _size(expr) -> int:
    """The width of `expr` as typeset, in characters of text: SymPy's text without what
    MathML does not print ('*', '**') and with a Greek name one letter; a conservative
    estimate (exponents are drawn smaller)."""
    text = _GREEK.sub("a", sp.sstr(expr))
    text = text.replace("**", "").replace("*", "").replace("dot", "").replace("sqrt", "√")
    return len(text.replace(" ", ""))


def _pieces(expr, width: int, inner) -> list[Piece]:  # noqa: C901 - one case per node kind
    """The formula cut at the places a line may break, left to right."""
    if _size(expr) <= width // 2 or not isinstance(expr, sp.Basic) or expr.is_Atom:
        return [(inner(expr), _size(expr))]
    if isinstance(expr, sp.Add):
        out: list[Piece] = []
        for i, term in enumerate(expr.as_ordered_terms()):
            negative = term.could_extract_minus_sign()
            shown = -term if negative else term
            sub = _pieces(shown, width, inner)
            sign = "<mo>\u2212</mo>" if negative else ("<mo>+</mo>" if i else "")
            sub[0] = (sign + sub[0][0], sub[0][1] + (2 if sign else 0))
            out += sub
        return out
    if isinstance(expr, sp.Mul):
        num, den = sp.fraction(expr)
        out = []
        if den != 1:
            out.append((f"<mfrac><mn>1</mn>{inner(den)}</mfrac><mo>&#x2062;</mo>",
                        _size(den) // 2 + 2))
        factors = sp.Mul.make_args(num)
        coeff = [f for f in factors if f.is_Number]
        rest = [f for f in factors if not f.is_Number]
        parts: list[Piece] = []
        for f in rest:
            parts += _factor(f, width, inner)
        if coeff and coeff != [sp.S.One] and parts:  # a coefficient stays with its factor
            c = sp.Mul(*coeff)
            parts[0] = (inner(c) + "<mo>&#x2062;</mo>" + parts[0][0], parts[0][1] + _size(c))
        return out + parts
    if isinstance(expr, sp.Pow) and isinstance(expr.base, sp.Add) and expr.exp.is_Number \
            and expr.exp > 0:
        sub = _pieces(expr.base, width, inner)
        return [("<mo>(</mo>", 1), *sub,
                (f"<msup><mo>)</mo>{inner(expr.exp)}</msup>", 2 + _size(expr.exp))]
    if isinstance(expr, sp.Function) and len(expr.args) == 1:
        name = _NAMES.get(type(expr).__name__, type(expr).__name__)
        return [(f"<mi>{name}</mi><mo>&#x2061;</mo><mo>(</mo>", len(name) + 1),
                *_pieces(expr.args[0], width, inner), ("<mo>)</mo>", 1)]
    return [(inner(expr), _size(expr))]


def _factor(f, width: int, inner) -> list[Piece]:
    """One factor of a product: a sum in brackets (cut inside), or as it is."""
    if isinstance(f, sp.Add) and _size(f) > width // 2:
        return [("<mo>(</mo>", 1), *_pieces(f, width, inner), ("<mo>)</mo>", 1)]
    if isinstance(f, sp.Pow | sp.Function) and _size(f) > width // 2:
        return _pieces(f, width, inner)
    return [(inner(f), _size(f))]
