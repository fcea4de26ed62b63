"""SymPy expressions as heyoka expressions, by walking the tree (nothing is parsed).

Why a translator of our own: the engine's expressions are SymPy trees; heyoka builds its
Taylor integrators from its own expression type. Walking the tree keeps the rule that no
text is ever evaluated, maps parameters to heyoka's runtime parameters `par[i]` (one
compiled integrator serves every parameter value), and refuses what heyoka cannot
differentiate smoothly (Abs, sign, Piecewise, ...) with an UnsupportedError naming it, so
the caller falls back to the SciPy methods.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import sympy as sp

from mechbook.errors import UnsupportedError

_UNARY = {
    sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.exp: "exp", sp.log: "log",
    sp.asin: "asin", sp.acos: "acos", sp.atan: "atan", sp.sinh: "sinh", sp.cosh: "cosh",
    sp.tanh: "tanh", sp.asinh: "asinh", sp.acosh: "acosh", sp.atanh: "atanh", sp.erf: "erf",
}
_RECIPROCAL = {sp.sec: "cos", sp.csc: "sin", sp.cot: "tan"}
MAX_PRODUCT_POWER = 16  # integer powers up to this are products (see Translator._walk)


def _hy():
    import heyoka

    return heyoka


class Translator:
    """SymPy -> heyoka for one system: `symbols` maps each free symbol to a heyoka
    expression (state variables, `heyoka.time`, `heyoka.par[i]`)."""

    def __init__(self, symbols: Mapping[sp.Symbol, object]):
        self.hy = _hy()
        self.symbols = dict(symbols)
        self._memo: dict[sp.Basic, object] = {}

    def __call__(self, e: sp.Basic):
        if isinstance(e, sp.Basic):
            return self.walk(e)
        if isinstance(e, (int, float)) and not isinstance(e, bool):  # a bare number
            return self.number(e)
        raise TypeError(f"not a SymPy expression: {type(e).__name__} (never parsed as text)")

    def number(self, x) -> object:
        return self.hy.expression(float(x))

    def walk(self, e: sp.Basic):
        hit = self._memo.get(e)
        if hit is not None:
            return hit
        out = self._walk(e)
        self._memo[e] = out
        return out

    def _walk(self, e: sp.Basic):
        hy = self.hy
        if e in self.symbols:
            return self.symbols[e]
        if e.is_Symbol:
            raise UnsupportedError(f"Taylor backend: the symbol {e} has no value")
        if e.is_Number:
            if not e.is_real:
                raise UnsupportedError(f"Taylor backend: complex constant {e}")
            return self.number(e)
        if e is sp.pi:
            return self.number(sp.pi.evalf(20))
        if e is sp.E:
            return self.number(sp.E.evalf(20))
        if e.is_Add:
            return hy.sum([self.walk(a) for a in e.args])
        if e.is_Mul:
            coeff, rest = e.as_coeff_Mul()
            terms = [self.walk(a) for a in sp.Mul.make_args(rest)]
            out = terms[0]
            for t in terms[1:]:
                out = out * t
            return out if coeff == 1 else self.number(coeff) * out
        if e.is_Pow:
            base, exp = e.args
            b = self.walk(base)
            if exp == sp.Rational(1, 2):
                return hy.sqrt(b)
            if exp == -sp.Rational(1, 2):
                return 1.0 / hy.sqrt(b)
            if exp.is_Integer and 0 < abs(int(exp)) <= MAX_PRODUCT_POWER:
                # products, not pow: the Taylor recurrence of b**a divides by b, which is
                # NaN wherever b = 0 (sin(φ)² at φ = 0), while a product is smooth there
                p = _power(b, abs(int(exp)))
                return p if int(exp) > 0 else 1.0 / p
            if exp.is_Number:
                return b ** float(exp)
            if base is sp.E:
                return hy.exp(self.walk(exp))
            return hy.exp(self.walk(exp) * hy.log(b))
        func = e.func
        if func in _UNARY:
            return getattr(hy, _UNARY[func])(self.walk(e.args[0]))
        if func in _RECIPROCAL:
            return 1.0 / getattr(hy, _RECIPROCAL[func])(self.walk(e.args[0]))
        if func is sp.atan2:
            return hy.atan2(self.walk(e.args[0]), self.walk(e.args[1]))
        raise UnsupportedError(f"Taylor backend: no heyoka translation for {func.__name__}")


def _power(b, k: int):
    """b**k by repeated squaring."""
    out, sq = None, b
    while k:
        if k & 1:
            out = sq if out is None else out * sq
        k >>= 1
        if k:
            sq = sq * sq
    return out


def translate_all(exprs, symbols: Mapping[sp.Symbol, object]) -> list:
    """Translate a list of SymPy expressions with one shared memo (shared subtrees stay
    shared)."""
    tr = Translator(symbols)
    return [tr(e) for e in exprs]


def solve_spd(M: list[list], rhs: list, zero: Callable[[object], bool]) -> list:
    """x with M x = rhs for a symmetric positive definite M of heyoka expressions, by
    LDLᵀ without pivoting (stable for SPD matrices: mass matrices, A M⁻¹ Aᵀ). Entries for
    which `zero(entry)` holds are skipped, so a diagonal M costs n divisions."""
    n = len(rhs)
    L = [[None] * n for _ in range(n)]
    D = [None] * n

    def dot(terms):
        terms = [t for t in terms if t is not None]
        if not terms:
            return None
        out = terms[0]
        for t in terms[1:]:
            out = out + t
        return out

    def sub(a, b):
        if b is None:
            return a
        if a is None:
            return -b
        return a - b

    for j in range(n):
        D[j] = sub(M[j][j], dot(L[j][k] * L[j][k] * D[k] for k in range(j)
                               if L[j][k] is not None))
        for i in range(j + 1, n):
            s = dot(L[i][k] * L[j][k] * D[k] for k in range(j)
                    if L[i][k] is not None and L[j][k] is not None)
            v = sub(None if zero(M[i][j]) else M[i][j], s)
            L[i][j] = None if v is None else v / D[j]
    z = [None] * n
    for i in range(n):
        z[i] = sub(None if zero(rhs[i]) else rhs[i],
                   dot(L[i][k] * z[k] for k in range(i)
                       if L[i][k] is not None and z[k] is not None))
    x = [None] * n
    for i in reversed(range(n)):
        w = None if z[i] is None else z[i] / D[i]
        x[i] = sub(w, dot(L[k][i] * x[k] for k in range(i + 1, n)
                          if L[k][i] is not None and x[k] is not None))
    return x


__all__ = ["Translator", "solve_spd", "translate_all"]
