"""The Taylor backend's form of the equations: accelerations solved in SymPy, Pythagorean
identities applied, parameter-only subexpressions hoisted into derived runtime parameters.

Why: the cost of one Taylor step is the number of elementary operations in heyoka's
decomposition of the right-hand side, each a recurrence over the Taylor order. The engine's
residuals are raw: a pendulum's mass is m·l²·(sin²θ + cos²θ), and its acceleration, solved
as heyoka expressions, was −(g·l·m·sin θ)/(m·l²·(cos²θ + sin²θ)) — 18 operations in
heyoka's decomposition, where −(g/l)·sin θ needs 7. heyoka turns every compound of
runtime parameters (−p₀, p₀·p₁, p₁²) into a series of its own with full recurrences; only
a bare `par[i]` times a series is cheap. So here each maximal subexpression without t, q
or q̇ becomes one derived parameter whose value is computed from the parameters' values
(at 40 digits, then rounded once to the integrator's type), and the entries of M, f, A, b
get `trigsimp` when they are small. The parameters stay runtime parameters: one compiled
integrator still serves every parameter value.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import sympy as sp

from mechbook.numerics.hyexpr import solve_spd

TRIGSIMP_OPS = 40  # entries of M, f, A, b up to this many operations get trigsimp
VALUE_DPS = 40  # digits of a derived parameter's value before rounding to the integrator's type


@lru_cache(maxsize=4096)
def tidy(e: sp.Expr) -> sp.Expr:
    """`e` with sin² + cos² = 1 and its kin applied, when `e` is small and trigonometric
    (trigsimp on a large entry costs more than the steps it saves). Cached: a model
    rebuilt for the same system (each `simulate`) has the same entries, and trigsimp
    costs tens of milliseconds."""
    if e == 0 or not e.has(sp.sin, sp.cos) or sp.count_ops(e) > TRIGSIMP_OPS:
        return e
    out = sp.trigsimp(e)
    return out if sp.count_ops(out) <= sp.count_ops(e) else e


def _none_if_zero(e):
    return None if e == 0 else e


def _sum(terms):
    terms = [x for x in terms if x is not None]
    return sp.Add(*terms) if terms else None


def _dot(xs, ys):
    return _sum(x * y for x, y in zip(xs, ys, strict=True) if x is not None and y is not None)


def accelerations(M: list, f: list, A: list, b: list, n: int) -> list:
    """q̈ from M q̈ = f (+ Aᵀλ, A q̈ + b = 0), row-major M (n×n) and A (m×n), as SymPy
    expressions: LDLᵀ of M (symmetric positive definite), and for constraints the
    multipliers from the Schur complement A M⁻¹ Aᵀ (also SPD), as `Model._solve` does."""
    m = len(b)
    Mm = [[_none_if_zero(tidy(M[i * n + j])) for j in range(n)] for i in range(n)]
    fv = [_none_if_zero(tidy(e)) for e in f]
    Minv_f = solve_spd(Mm, fv, lambda e: e is None)
    if m == 0:
        out = Minv_f
    else:
        Am = [[_none_if_zero(tidy(A[r * n + j])) for j in range(n)] for r in range(m)]
        bv = [_none_if_zero(tidy(e)) for e in b]
        Minv_At = [solve_spd(Mm, [Am[r][i] for i in range(n)], lambda e: e is None)
                   for r in range(m)]
        S = [[_dot(Am[r], Minv_At[c]) for c in range(m)] for r in range(m)]
        rhs = []
        for r in range(m):
            s = _sum([bv[r], _dot(Am[r], Minv_f)])
            rhs.append(None if s is None else -s)
        lam = solve_spd(S, rhs, lambda e: e is None)
        out = [_sum([Minv_f[i]] + [Minv_At[r][i] * lam[r] for r in range(m)
                                   if Minv_At[r][i] is not None and lam[r] is not None])
               for i in range(n)]
    return [sp.Integer(0) if a is None else a for a in out]


@dataclass
class Hoisted:
    """Parameter-only subexpressions replaced by derived parameters, shared across every
    expression hoisted with it (the right-hand side and the events of one system).

    `state` are the symbols that vary along the motion (t, q, q̇); `params` those with a
    value. `derived[i]` is the SymPy expression (in the parameters) of heyoka's par[i]."""

    state: frozenset
    params: frozenset
    symbols: list = field(default_factory=list)  # the derived parameters' own symbols
    derived: list = field(default_factory=list)
    _index: dict = field(default_factory=dict)  # expression -> its derived symbol
    _memo: dict = field(default_factory=dict)

    def __call__(self, e: sp.Expr) -> sp.Expr:
        """`e` with each maximal parameter-only subexpression a derived parameter."""
        hit = self._memo.get(e)
        if hit is None:
            hit = self._walk(e)
            self._memo[e] = hit
        return hit

    def _constant(self, e: sp.Expr) -> sp.Expr:
        """A subexpression free of t, q, q̇: a number stays a number, anything else (a
        parameter, −g/l, π·m) is one derived parameter."""
        if not e.free_symbols:
            if e.is_Number:
                return e
            x = e.evalf(VALUE_DPS)
            return sp.Float(x, VALUE_DPS) if x.is_real else e  # complex: refused later
        if not e.free_symbols <= self.params:  # a symbol without a value: the translator
            return e                          # refuses it, naming it
        sym = self._index.get(e)
        if sym is None:
            sym = sp.Dummy(f"par{len(self.derived)}")
            self._index[e] = sym
            self.symbols.append(sym)
            self.derived.append(e)
        return sym

    def _walk(self, e: sp.Expr) -> sp.Expr:
        if not (e.free_symbols & self.state):
            return self._constant(e)
        if not e.args:  # t, a coordinate or a velocity
            return e
        if e.is_Mul or e.is_Add:
            const = [a for a in e.args if not (a.free_symbols & self.state)]
            rest = [self(a) for a in e.args if a.free_symbols & self.state]
            if const:
                rest.insert(0, self._constant(e.func(*const)))
            return e.func(*rest)
        if e.is_Pow and e.args[1].is_Number:
            return sp.Pow(self(e.args[0]), e.args[1])
        return e.func(*[self(a) for a in e.args])

    def values(self, at: dict, dps: int = VALUE_DPS) -> list:
        """The derived parameters' values (mpmath numbers at `dps` digits) at the
        parameter values `at` ({symbol: float}), each float taken exactly."""
        exact = {s: sp.Float(float(v), dps) for s, v in at.items()}
        out = []
        for e in self.derived:
            x = e.xreplace(exact).evalf(dps)
            if not x.is_real:
                raise ValueError(f"the parameter combination {e} is not real here: {x}")
            out.append(x)
        return out


__all__ = ["Hoisted", "accelerations", "tidy"]
