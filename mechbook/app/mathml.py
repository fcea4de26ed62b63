"""SymPy expressions as MathML, which browsers render natively (no script, no CDN).

SymPy's presentation printer does the work; this module adds only what a mechanics reader
expects and SymPy's MathML printer lacks: a velocity `thetadot` printed θ̇ and an
acceleration `thetaddot` θ̈ (SymPy's LaTeX printer already does this), and equations, lists
and mappings laid out one per row.
"""

from __future__ import annotations

from collections.abc import Iterable

import sympy as sp
from sympy.printing.mathml import MathMLPresentationPrinter

from mechbook.core.compile import as_expr

NS = "http://www.w3.org/1998/Math/MathML"
_MARKS = (("ddot", "\u00a8"), ("dot", "\u02d9"))


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
        mo.appendChild(self.dom.createTextNode(mark))
        over.appendChild(mo)
        return over

    _print_Dummy = _print_Symbol


def inner(expr) -> str:
    """The MathML of one SymPy object (no <math> wrapper)."""
    if isinstance(expr, bool):
        expr = sp.true if expr else sp.false
    if isinstance(expr, (int, float)):
        expr = as_expr(expr)  # a Python number, never text
    return _Printer({"mat_delim": "["}).doprint(expr)


def math(expr, display: bool = True) -> str:
    """A complete <math> element for `expr` (a SymPy object, number, list, tuple or dict)."""
    body = _body(expr)
    mode = "block" if display else "inline"
    return f'<math xmlns="{NS}" display="{mode}">{body}</math>'


def _body(expr) -> str:
    if isinstance(expr, dict):
        return _rows((sp.Eq(k, v, evaluate=False) if isinstance(k, sp.Basic) else v)
                     for k, v in expr.items())
    if isinstance(expr, (list, tuple)):
        return _rows(expr)
    return inner(expr)


def _rows(items: Iterable) -> str:
    rows = "".join(f'<mtr><mtd style="text-align:left">{_body(e)}</mtd></mtr>'
                   for e in items)
    return f'<mtable columnalign="left">{rows}</mtable>' if rows else "<mi>∅</mi>"
