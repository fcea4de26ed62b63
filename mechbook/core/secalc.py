"""Differentiation and expansion of SymPy expressions done by SymEngine.

SymPy's `diff` and `expand` dominate the derivation of a system's equations (seconds for a
rigid body's Lagrangian); SymEngine does the same calculus in C++ in milliseconds. The
functions here give their results back as SymPy expressions with the original symbols
(SymEngine keeps no assumptions: its `x` would come back as another symbol than a real
`x`); `either` runs a computation written for both algebras in SymEngine and leaves its
result SymEngine's (for the compile layer, which takes it as it is, or for the caller to
convert once). Where SymEngine does not know a function, SymPy does the work, so the
answer never depends on which did.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from typing import Any, TypeVar

import symengine as se
import sympy as sp

from mechbook.errors import MechbookError

T = TypeVar("T")


class SymEngineCannot(Exception):
    """SymEngine cannot do this one (an unknown function, a derivative left unevaluated)."""


class _Carrier(se.Symbol):
    """A SymEngine symbol that converts back to the SymPy symbol it stands for (its
    assumptions kept), so that a result comes back with the caller's symbols in one pass
    instead of a second pass of SymPy's xreplace over the whole tree (half the time of
    the conversion of a rigid body's derivatives).

    Its SymEngine name is its own ("r#3"), not the symbol's: SymEngine compares symbols by
    name, and SymPy's cache keys a conversion (`Mul(*args)` of SymEngine arguments) by
    them, so a carrier named plain "r" would be taken for the carrier of another problem's
    r (real here, positive there) and come back as that r."""

    def __init__(self, sym: sp.Symbol, index: int):
        super().__init__(f"{sym.name}#{index}")
        self.sym = sym

    def _sympy_(self) -> sp.Symbol:
        return self.sym


_CARRIERS: dict[sp.Symbol, _Carrier] = {}  # one for each symbol (a subclass of Symbol is
# kept alive by SymEngine's reference to it: made once, it is not made again)


def _carrier(sym: sp.Symbol) -> _Carrier:
    found = _CARRIERS.get(sym)
    if found is None:
        found = _CARRIERS[sym] = _Carrier(sym, len(_CARRIERS))
    return found


def to_sympy(e, symbols: Iterable[sp.Symbol]) -> sp.Basic:
    """A SymEngine result as SymPy, its symbols replaced by those of `symbols` (by name)."""
    by_name = {s.name: s for s in symbols if type(s) is not sp.Dummy}
    carry = {s: _carrier(by_name[s.name]) for s in e.free_symbols
             if type(s) is se.Symbol and s.name in by_name}
    out = (e.xreplace(carry) if carry else e)._sympy_()
    if out.has(sp.Derivative, sp.Subs):
        raise SymEngineCannot("a derivative left unevaluated")
    return out  # a Dummy comes back equal to itself (SymEngine keeps its index)


def derivative(expr: sp.Basic, s: sp.Symbol) -> sp.Basic:
    """∂expr/∂s (SymPy's own where SymEngine cannot)."""
    try:
        return to_sympy(se.diff(se.sympify(expr), se.sympify(s)), expr.free_symbols)
    except Exception:  # noqa: BLE001 - any failure: SymPy's derivative
        return sp.diff(expr, s)


def euler_lagrange(L: sp.Expr, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
                   chains: Sequence[tuple[sp.Symbol, sp.Symbol]], t: sp.Symbol,
                   forces: Sequence[sp.Expr], stop: Sequence[sp.Symbol] = ()) -> list[sp.Expr]:
    """expand(d/dt(∂L/∂q̇_i) − ∂L/∂q_i − Q_i) for each i, with d/dt = ∂/∂t + Σ ẋ ∂/∂x over
    `chains` [(x, ẋ), ...]. Raises SymEngineCannot where SymEngine cannot do it all, or where
    ∂L/∂q̇_i holds a symbol of `stop` (one whose time derivative is not defined)."""
    names = set(L.free_symbols).union(*(f.free_symbols for f in forces))
    names |= set(q) | set(qd) | {t} | {s for pair in chains for s in pair}
    try:
        Ls = se.sympify(L)
        ts = se.sympify(t)
        pairs = [(se.sympify(x), se.sympify(v)) for x, v in chains]
        stops = {se.sympify(x) for x in stop}
        out = []
        for qi, vi, force in zip(q, qd, forces, strict=True):
            p = Ls.diff(se.sympify(vi))
            if stops & p.free_symbols:
                raise SymEngineCannot("a symbol without a time derivative")
            d = p.diff(ts)
            for x, v in pairs:
                d += p.diff(x) * v
            e = d - Ls.diff(se.sympify(qi)) - se.sympify(force)
            out.append(to_sympy(se.expand(e), names))
        return out
    except SymEngineCannot:
        raise
    except Exception as exc:  # noqa: BLE001 - SymEngine's conversion or calculus failed
        raise SymEngineCannot(str(exc)) from None


def total_derivative(expr: sp.Basic, t: sp.Symbol,
                     chains: Sequence[tuple[sp.Symbol, sp.Symbol]]) -> sp.Basic:
    """∂expr/∂t + Σ ẋ·∂expr/∂x over `chains` [(x, ẋ), ...], not expanded. Raises
    SymEngineCannot where SymEngine cannot do it (then the caller differentiates with SymPy)."""
    names = set(expr.free_symbols) | {t} | {s for pair in chains for s in pair}
    try:
        e = se.sympify(expr)
        present = e.free_symbols
        out = e.diff(se.sympify(t))
        for x, v in chains:
            sx = se.sympify(x)
            if sx in present:
                out += e.diff(sx) * se.sympify(v)
        return to_sympy(out, names)
    except SymEngineCannot:
        raise
    except Exception as exc:  # noqa: BLE001 - SymEngine's conversion or calculus failed
        raise SymEngineCannot(str(exc)) from None


def expand(expr: sp.Basic) -> sp.Basic:
    """`sympy.expand(expr)`, the expansion done by SymEngine (SymPy's where it cannot)."""
    try:
        return to_sympy(se.expand(se.sympify(expr)), expr.free_symbols)
    except Exception:  # noqa: BLE001 - a function SymEngine does not know: SymPy's expand
        return sp.expand(expr)


def same(e: T) -> T:
    """The identity: SymPy's algebra for a computation written for either (`either`)."""
    return e


def either(build: Callable[[Callable], T]) -> T:
    """build(se.sympify): a computation written once for either algebra (SymEngine's and
    SymPy's objects both have diff, xreplace, +, * and free_symbols) done in SymEngine;
    where SymEngine cannot (an unknown function, a conversion that fails, or a derivative
    it leaves unevaluated in what `build` returns: d|x|/dx, d floor(x)/dx), done again in
    SymPy, build(same). A MechbookError (the problem's own fault, or a capability the
    engine lacks), running out of memory or of recursion depth are not reasons to try
    again."""
    try:
        out = build(se.sympify)
    except (MechbookError, MemoryError, RecursionError):
        raise
    except Exception:  # noqa: BLE001 - SymEngine's conversion or calculus failed
        return build(same)
    if _unevaluated(out):
        return build(same)
    return out


def _unevaluated(out: Any) -> bool:
    """Does a result (SymEngine objects, or lists and tuples of them) hold a derivative or
    substitution SymEngine left unevaluated?"""
    if isinstance(out, (list, tuple)):
        return any(_unevaluated(x) for x in out)
    return isinstance(out, se.Basic) and bool(out.atoms(se.Derivative, se.Subs))
