"""The book's value and the engine's, side by side, for one answer part of the report.

The book's value is read from the answer key with the part's own names (the safe parser,
as the checker does) and shown as mathematics. The engine's counterpart is what the engine
derives for that quantity: the Lagrangian, Lagrange's (or the linearized) equations, the
normal frequencies, equilibria, the stability condition, the conserved quantities. For
quantities with no single derived value to show (a motion, a constraint force, a region of
phase space ...) the page shows how the check compared them instead. Both values are also
evaluated at the same admissible parameter point where they are lists of numbers.

Nothing here decides an outcome: the outcome is the stored check's.
"""

from __future__ import annotations

import re

import numpy as np
import sympy as sp

from mechbook.app.mathml import math
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.verify.context import Context, numbers, strip_const

_RELATION = re.compile(r"<=|>=|<|>|!=")
_EQUALS = re.compile(r"(?<![<>=!])=(?!=)")


def book_math(ctx: Context, value, sub: tuple = ("book",)) -> str:
    """The book's value as MathML (text it cannot parse is shown as code)."""
    if isinstance(value, list):
        return "".join(book_math(ctx, v, sub + (i,)) for i, v in enumerate(value))
    if isinstance(value, dict):
        rows = []
        for k, v in value.items():
            rows.append(f'<div class="kv"><span class="key">{_esc(k)}</span>'
                        f'{book_math(ctx, v, sub + (k,))}</div>')
        return "".join(rows)
    if isinstance(value, bool):
        return f"<code>{value}</code>"
    try:
        return math(parse_shown(ctx, value, sub))
    except MechbookError:
        return f"<code>{_esc(value)}</code>"


def parse_shown(ctx: Context, value, sub: tuple):
    """A book value as a SymPy object to show: an equation stays an equation."""
    if not isinstance(value, str):
        return ctx.parse(value, sub)
    text = strip_const(value)
    if _RELATION.search(text):
        return ctx.parse(text, sub, relation=True)
    pieces = _EQUALS.split(text)
    if len(pieces) == 2:
        return sp.Eq(ctx.parse(pieces[0], sub), ctx.parse(pieces[1], sub), evaluate=False)
    return ctx.parse(text, sub)


def engine_value(ctx: Context):
    """The engine's value for the part's quantity, or None where there is no single one."""
    q = ctx.part.quantity
    data = ctx.part.data
    if q == "lagrangian":
        return ctx.system.lagrangian
    if q == "eom":
        if "about" in data or "steady" in data:
            return [sp.Eq(e, 0) for e in ctx.linear().equations()]
        dyn = ctx.dyn
        lhs = dyn.mass_matrix * sp.Matrix(dyn.qdd)
        rhs = dyn.forcing
        if ctx.system.constraints:
            rhs = rhs + dyn.constraint_jacobian.T * sp.Matrix(dyn.multipliers)
        return [sp.Eq(a, b, evaluate=False) for a, b in zip(lhs, rhs, strict=True)]
    if q in ("frequencies", "period"):
        lin = ctx.linear()
        try:
            freqs = list(lin.frequencies)
        except UnsupportedError:
            return None
        if q == "period":
            return [2 * sp.pi / w for w in freqs if not w.is_zero]
        return freqs
    if q == "equilibrium":
        return ctx.analysis.equilibria(ctx.part.system).symbolic
    if q == "stability_condition":
        return ctx.linear().stability_condition
    if q == "conserved":
        dyn = ctx.dyn
        out = {sp.Symbol(f"p_{k}"): v for k, v in dyn.cyclic.items()}
        if dyn.energy_conserved:
            out[sp.Symbol("h")] = dyn.energy_function
        return out or None
    return None


def numeric_pair(ctx: Context) -> tuple[list[float], list[float]] | None:
    """(book, engine) values at one admissible parameter point for the quantities that are
    lists of numbers (frequencies, periods), else None."""
    q = ctx.part.quantity
    if q not in ("frequencies", "period") or "limit" in ctx.part.data:
        return None
    book = ctx.part.data.get("book")
    items = book if isinstance(book, list) else [book]
    pt = ctx.sampler.default()
    exprs = [ctx.parse(v, ("book", i)) for i, v in enumerate(items)]
    eng = [float(w) for w in ctx.linear().numeric_frequencies(pt)]
    if q == "period":
        eng = [2 * np.pi / w for w in eng if w > 1e-12]
    return numbers(exprs, pt), sorted(eng)


def _esc(text) -> str:
    import html

    return html.escape(str(text))
