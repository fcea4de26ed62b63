"""SymPy expressions as MathML, which browsers render natively (no script, no CDN).

SymPy's presentation printer does the work; this module adds only what a mechanics reader
expects and SymPy's MathML printer lacks: a velocity `thetadot` printed θ̇ and an
acceleration `thetaddot` θ̈ (SymPy's LaTeX printer already does this), with dots drawn large
enough to read at 100 % (browsers draw U+02D9 as a speck: θ̇ read as θ²), one minus sign
(U+2212, where SymPy writes a hyphen), equations, lists
and mappings laid out one per row, and a long sum broken into lines of about `width`
characters, so that an equation fits its column instead of scrolling.
"""

from __future__ import annotations

from collections.abc import Iterable

import sympy as sp
from sympy.printing.mathml import MathMLPresentationPrinter

from mechbook.app.output.linebreak import rows as linebreak_rows
from mechbook.core.compile import as_expr

NS = "http://www.w3.org/1998/Math/MathML"
_MARKS = (("ddot", "\u00a8"), ("dot", "\u02d9"))
# the dot drawn larger, bold and lowered onto its letter (judged in headless Chromium's
# screenshots at 100 %); inline, so that a notebook draws it the same way
DOT_STYLE = "font-size:170%;font-weight:bold;position:relative;top:0.04em"
WIDTH = 95  # characters of typeset text per line of a broken formula (linebreak._size)


class _Printer(MathMLPresentationPrinter):
    """Presentation MathML with dotted velocities and accelerations."""

    def _print_Symbol(self, sym, style="plain"):
        name = sym.name
        for suffix, mark in _MARKS:
            if name.endswith(suffix) and len(name) > len(suffix) and name[0].isalpha():
                base = super()._print_Symbol(sp.Symbol(name[: -len(suffix)]), style)
                if base.nodeName in ("msub", "msup", "msubsup"):  # x1dot: the dot on x
                    letter = base.firstChild
                    base.replaceChild(self._accent(letter.cloneNode(True), mark), letter)
                    return base
                return self._accent(base, mark)
        return super()._print_Symbol(sym, style)

    def _accent(self, base, mark: str):
        over = self.dom.createElement("mover")
        over.setAttribute("accent", "true")
        over.appendChild(base)
        mo = self.dom.createElement("mo")
        mo.setAttribute("style", DOT_STYLE)
        mo.appendChild(self.dom.createTextNode(mark))
        over.appendChild(mo)
        return over

    _print_Dummy = _print_Symbol

    def _print_BooleanTrue(self, expr):  # SymPy draws Python's `True`
        return self._text("true")

    def _print_BooleanFalse(self, expr):
        return self._text("false")

    def _text(self, text: str):
        node = self.dom.createElement("mtext")
        node.appendChild(self.dom.createTextNode(text))
        return node


MINUS = "\u2212"  # the minus sign; SymPy's printer writes the hyphen-minus '-'


def inner(expr) -> str:
    """The MathML of one SymPy object (no <math> wrapper), every minus sign U+2212 (the
    line breaker's too: one glyph in a formula, never a hyphen beside a minus)."""
    if isinstance(expr, bool):
        expr = sp.true if expr else sp.false
    if isinstance(expr, (int, float)):
        expr = as_expr(expr)  # a Python number, never text
    out = _Printer({"mat_delim": "["}).doprint(expr)
    return out.replace("<mo>-</mo>", f"<mo>{MINUS}</mo>").replace(
        "<mn>-", f"<mo>{MINUS}</mo><mn>")


def math(expr, display: bool = True, width: int | None = WIDTH) -> str:
    """A complete <math> element for `expr` (a SymPy object, number, list, tuple or dict);
    a sum longer than `width` characters is broken into lines (None: never)."""
    body = _body(expr, width)
    mode = "block" if display else "inline"
    return f'<math xmlns="{NS}" display="{mode}">{body}</math>'


def _body(expr, width: int | None = None) -> str:
    if isinstance(expr, dict):
        return _rows(((sp.Eq(k, v, evaluate=False) if isinstance(k, sp.Basic) else v)
                      for k, v in expr.items()), width)
    if isinstance(expr, (list, tuple)):
        return _rows(expr, width)
    if width is not None:
        lines = _lines(expr, width)
        if lines is not None:
            return lines
    return inner(expr)


def _rows(items: Iterable, width: int | None = None) -> str:
    rows = "".join(f'<mtr><mtd style="text-align:left">{_body(e, width)}</mtd></mtr>'
                   for e in items)
    return f'<mtable columnalign="left">{rows}</mtable>' if rows else "<mi>∅</mi>"


def _lines(expr, width: int) -> str | None:
    """A formula too long for a line as rows (mechbook.app.output.linebreak), or None."""
    if not isinstance(expr, sp.Basic):
        return None
    rows = linebreak_rows(expr, width, inner)
    if rows is None:
        return None
    body = "".join(f'<mtr><mtd style="text-align:left"><mrow>{r}</mrow></mtd></mtr>'
                   for r in rows)
    return f'<mtable columnalign="left">{body}</mtable>'


def identifier_mathml(name: str) -> str:
    """A name as the printer draws a symbol of that name: Greek letters, subscripts from
    trailing digits and underscores, dotted rates (`thetadot` is θ̇)."""
    return inner(sp.Symbol(name))
