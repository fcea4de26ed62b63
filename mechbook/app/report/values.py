"""The book's value and the engine's, side by side, for one answer part of the report.

The book's value is read from the answer key with the part's own names (the safe parser,
as the checker does) and shown as mathematics; what the part's context cannot build (an
identity for all tensors) is drawn from its syntax (mechbook.app.report.syntax). The
engine's counterpart is what the check derived and stored for that quantity: the
Lagrangian, Lagrange's or the linearized equations (M, C, K), the equilibria, the
stability condition (K positive definite), the conserved momenta and energy; the
frequencies at the part's point come from the stored linear system's numbers. For
quantities with no single derived value to show (a motion, a region of phase space ...)
the page shows how the check compared them instead.

Nothing here decides an outcome: the outcome is the stored check's.
"""

from __future__ import annotations

import html
import re

import numpy as np
import scipy.linalg
import sympy as sp

from mechbook.app.output.mathml import MINUS, NS, identifier_mathml, math
from mechbook.app.report.derivation import StoredSystem
from mechbook.app.report.syntax import syntax_math
from mechbook.errors import MechbookError
from mechbook.verify.context import Context, numbers, strip_const
from mechbook.verify.registry import default_quantities

# the names a registration's `display=` may hold: what the page shows beside the book's value
DISPLAYS = {
    "system_lagrangian": "the system's Lagrangian",
    "equations_of_motion": "Lagrange's equations, or M, C, K about the part's point",
    "frequency_list": "√(K/M) of one degree of freedom, and the frequencies at one point",
    "period_list": "2π/√(K/M) of one degree of freedom, and the periods at one point",
    "equilibrium_points": "the equilibria the check found",
    "sylvester_criterion": "K's leading principal minors positive (up to 3 coordinates)",
    "momenta_and_energy": "the conserved momenta and the energy function",
}

_RELATION = re.compile(r"<=|>=|<|>|!=")
_EQUALS = re.compile(r"(?<![<>=!])=(?!=)")


def book_math(ctx: Context | None, value, sub: tuple = ("book",)) -> str:
    """The book's value as MathML: built in the part's context, else drawn from its
    syntax; a list of values one per row, a mapping as its key beside each value."""
    if isinstance(value, list):
        return "".join(f'<div class="item">{book_math(ctx, v, sub + (i,))}</div>'
                       for i, v in enumerate(value))
    if isinstance(value, dict):
        shown = _equations(ctx, value, sub)
        if shown is not None:
            return shown
        rows = []
        for k, v in value.items():
            rows.append(f'<div class="kv"><span class="key">{_esc(k)}</span>'
                        f'<div class="val">{book_math(ctx, v, sub + (k,))}</div></div>')
        return "".join(rows)
    if isinstance(value, bool):  # as a reader says it, not as Python spells it
        return f'<span class="flag">{"yes" if value else "no"}</span>'
    if ctx is not None:
        try:
            return math(parse_shown(ctx, value, sub))
        except (MechbookError, TypeError, ValueError):
            pass
    drawn = syntax_math(str(value)) if isinstance(value, str | int | float) else None
    return drawn or f"<code>{_esc(value)}</code>"


def _equations(ctx: Context | None, value: dict, sub: tuple) -> str | None:
    """A mapping of names to values ({r: r0, alpha: 0}) as the equations r = r₀, α = 0."""
    if ctx is None or not all(isinstance(k, str) and k.isidentifier() for k in value):
        return None
    if not all(isinstance(v, str | int | float) and not isinstance(v, bool)
               for v in value.values()):
        return None
    try:
        pairs = {sp.Symbol(k): ctx.parse(v, sub + (k,)) for k, v in value.items()}
    except (MechbookError, TypeError, ValueError):
        return None
    return math(pairs)


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


def part_linear(ctx: Context, view: StoredSystem | None, values: dict):
    """The stored linear system the part refers to (its `about:` point; without one, the
    only equilibrium the check linearized about), or None."""
    if view is None:
        return None
    data = ctx.part.data
    steady = "steady" in data
    if "about" in data:
        return view.linear_at(ctx.point(), values, steady=steady)
    plain = [lin for lin in view.linears if lin.steady is None and not lin.rates]
    return plain[0] if len(plain) == 1 and not steady else None


def engine_value(ctx: Context, view: StoredSystem | None, values: dict):
    """The engine's value for the part's quantity from what the check stored, or None
    where there is no single one (or the check did not store it)."""
    shown = display_of(ctx.part.quantity)
    data = ctx.part.data
    if shown == "system_lagrangian":
        return ctx.system.lagrangian
    if view is None:
        return None
    if shown == "equations_of_motion":
        if "about" in data or "steady" in data:
            lin = part_linear(ctx, view, values)
            if lin is None or lin.first_order:
                return None
            return {sp.Symbol("M"): lin.M, sp.Symbol("C"): lin.C, sp.Symbol("K"): lin.K}
        M, f = view.get("mass_matrix"), view.get("forcing")
        if M is None or f is None:
            return None
        dyn = ctx.dyn
        lhs = sp.Matrix(M) * sp.Matrix(dyn.qdd)
        rhs = sp.Matrix(f).reshape(lhs.rows, 1)
        if dyn.constrained:
            rhs = rhs + dyn.velocity_jacobian.T * sp.Matrix(dyn.multipliers)
        return [sp.Eq(a, b, evaluate=False) for a, b in zip(lhs, rhs, strict=True)]
    if shown in ("frequency_list", "period_list"):
        lin = part_linear(ctx, view, values)
        if lin is None or lin.first_order or lin.M.rows != 1 or not lin.C.is_zero_matrix:
            return None  # several modes: their numbers at one point are shown below
        w = sp.sqrt(lin.K[0, 0] / lin.M[0, 0])
        return [w] if shown == "frequency_list" else [2 * sp.pi / w]
    if shown == "equilibrium_points":
        return view.equilibria or None
    if shown == "sylvester_criterion":
        minors = stability_minors(ctx, view, values)
        if minors is None:
            return None
        return sp.And(*[m > 0 for m in minors])
    if shown == "momenta_and_energy":
        out = {}
        cyclic = view.get("cyclic")
        if isinstance(cyclic, dict):
            out.update({sp.Symbol(f"p_{k}"): v for k, v in cyclic.items()})
        energy = view.get("energy_function")
        if energy is not None:
            out[sp.Symbol("h")] = energy
        return out or None
    return None


def stability_minors(ctx: Context, view: StoredSystem | None, values: dict) -> list | None:
    """K's leading principal minors at the part's point, where stability is K positive
    definite (no velocity terms, not first order, K free of t, at most 3 coordinates);
    else None."""
    lin = part_linear(ctx, view, values)
    if lin is None or lin.first_order or lin.C.is_zero_matrix is False:
        return None  # velocity terms, or first order: not K's minors
    t = ctx.system.t
    if any(A.has(t) for A in (lin.M, lin.C, lin.K)) or lin.K.rows > 3:
        return None  # K(t) (Floquet's, not Sylvester's), or too many coordinates to show
    K = lin.K
    return [sp.factor(K[:k, :k].det()) for k in range(1, K.rows + 1)]


def stability_boundary(ctx: Context, view: StoredSystem | None, values: dict) -> dict | None:
    """Where the engine's stability changes: det K = 0 solved for a parameter of the book's
    relation (the first one it can be solved for), {symbol: [roots]}; None where there is
    no such closed form (or no relation)."""
    minors = stability_minors(ctx, view, values)
    if not minors:
        return None
    try:
        relation = ctx.parse(ctx.part.data.get("book"), ("book",), relation=True)
    except (MechbookError, TypeError, ValueError):
        return None
    det = minors[-1]
    text = str(ctx.part.data.get("book"))
    # the book's own order: "omega < sqrt(g/b)" solves for omega
    symbols = sorted((s for s in relation.free_symbols if det.has(s)),
                     key=lambda s: (_first(text, s.name), s.name))
    for sym in symbols:
        roots = [r for r in sp.solve(det, sym) if r.is_real is not False]
        if roots:
            return {sym: roots}
    return None


def numeric_pair(ctx: Context, view: StoredSystem | None,
                 values: dict) -> tuple[list[float], list[float], str] | None:
    """(book, engine, the point) at one admissible parameter point for the quantities that
    are lists of numbers (frequencies, periods), else None. The engine's are the stored
    linear system's frequencies there; the point is said as MathML (point_math)."""
    shown = display_of(ctx.part.quantity)
    if shown not in ("frequency_list", "period_list") or "limit" in ctx.part.data:
        return None
    pt = ctx.sampler.default()
    pair = _numeric_pair(ctx, view, values, pt, shown)
    if pair is None:
        return None
    return (*pair, point_math(pt, ctx.analysis.problem))


def point_math(point: dict, problem) -> str:
    """Where numbers were computed: the parameters' values there, as inline MathML, and
    whether they are the defaults (a condition may rule the defaults out)."""
    defaults = problem.values()
    shown = [(p.symbol, point[p.symbol]) for p in problem.parameters.values()
             if p.symbol in point]
    if not shown:
        return ""
    same = all(abs(float(v) - float(defaults[s])) <= 1e-12 * max(1.0, abs(defaults[s]))
               for s, v in shown)
    pairs = ", ".join(f'<math xmlns="{NS}" display="inline">{identifier_mathml(s.name)}'
                      f"<mo>=</mo>{_number(float(v))}</math>" for s, v in shown)
    return pairs + (" (the default values)" if same else
                    " (a random admissible point: the defaults break a condition)")


def _number(x: float) -> str:
    text = f"{x:.6g}"
    return (f"<mo>{MINUS}</mo><mn>{text[1:]}</mn>" if text.startswith("-")
            else f"<mn>{text}</mn>")


def _numeric_pair(ctx: Context, view: StoredSystem | None, values: dict, pt: dict,
                  shown: str) -> tuple[list[float], list[float]] | None:
    lin = part_linear(ctx, view, values)
    if lin is None:
        return None
    book = ctx.part.data.get("book")
    items = book if isinstance(book, list) else [book]
    exprs = [ctx.parse(v, ("book", i)) for i, v in enumerate(items)]
    if lin.first_order:  # its frequencies are stored at the default values only
        stored = lin.numeric.get("frequencies")
        defaults = ctx.analysis.problem.values()
        if stored is None or any(abs(float(pt[k]) - float(v)) > 1e-12 * max(1.0, abs(v))
                                 for k, v in defaults.items() if k in pt):
            return None
        eng = [float(w) for w in stored if np.isfinite(w)]
        if shown == "period_list":
            eng = [2 * np.pi / w for w in eng if w > 1e-12]
        return numbers(exprs, pt), sorted(eng)
    M, C, K = lin.matrices(pt)
    with np.errstate(all="ignore"):
        if np.any(C):
            n = M.shape[0]
            A = np.block([[np.zeros((n, n)), np.eye(n)],
                          [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
            eng = sorted(np.abs(np.linalg.eigvals(A).imag))[::2]
        else:
            w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
            eng = [float(np.sqrt(w)) for w in w2 if w >= 0]
    if shown == "period_list":
        eng = [2 * np.pi / w for w in eng if w > 1e-12]
    return numbers(exprs, pt), sorted(float(w) for w in eng)


def _first(text: str, name: str) -> int:
    """Where the name `name` first appears in `text` as a whole word (len(text) if not)."""
    m = re.search(rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])", text)
    return m.start() if m else len(text)


def display_of(quantity: str) -> str | None:
    """How the registration of `quantity` says its engine value is shown (DISPLAYS)."""
    entry = default_quantities().get(quantity)
    return entry.display if entry is not None else None


def _esc(text) -> str:
    return html.escape(str(text))
