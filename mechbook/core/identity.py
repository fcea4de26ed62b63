"""Exact zero tests by canonical forms: is an expression identically 0, decided in SymEngine
before (or instead of) SymPy's `simplify`.

The expression is rewritten as a rational function of *generators*: its symbols; for each
angle, its sine and cosine s, c (a trigonometric function of a sum or a multiple expanded
by the addition formulas and Chebyshev's, tan = s/c ...) tied by s² + c² = 1; for each
root R^(1/q), a generator r tied by r^q = R; exp(k·x) as E^k with E free; any other
function (asin, log, Abs, an unknown f(t)) as a free generator. The numerator over a common
denominator is expanded and reduced by the relations (each power r^k, k ≥ q, replaced by
r^(k mod q)·R^(k div q)); 0 after the reduction proves the identity: every step keeps the
value wherever the expression is defined, and a free generator only forgets what is known
about it. Nothing here is numeric: exact rationals throughout.

Where no root and no free generator appears (a rational function of symbols, sines and
cosines), the reduction decides: a nonzero remainder means the expression is not an
identity (the normal form modulo s² + c² − 1 is unique), and so does a nonzero exact value
at a rational point (sines and cosines on the rational circle: s = 2t/(1 + t²)).
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

import symengine as se
import sympy as sp

MAX_TERMS = 20_000  # terms of a product's two factors multiplied: beyond, no expansion
# (200 000 let Symon 12-06's and 12-10's motions spend 80 s each in SymEngine)
# (SymEngine's expansion cannot be interrupted, so its size is bounded before it starts)
MAX_MULTIPLE = 12  # largest multiple of a base angle expanded (sin 12x: degree 12)
POINTS = 2  # exact rational points tried before the expansion

TRIG = (sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)
HYPERBOLIC = (sp.sinh, sp.cosh, sp.tanh, sp.coth, sp.sech, sp.csch)


class NotCanonical(Exception):
    """The expression holds something no canonical form here covers (its reason)."""


@dataclass(frozen=True)
class Decision:
    """The zero test's answer: `zero` True (proved), False (decided: not an identity) or
    None (undecided); `why` a short phrase for False and None."""

    zero: bool | None
    why: str = ""


@dataclass
class _Relation:
    gen: se.Symbol
    power: int
    value: se.Basic  # gen**power == value (a rational function of earlier generators)


@dataclass
class _Form:
    """The generators met while converting one expression, and their relations."""

    symbols: dict = field(default_factory=dict)  # sympy Symbol -> se Symbol
    relations: list = field(default_factory=list)
    free_atoms: dict = field(default_factory=dict)  # sympy atom -> se Symbol (no relation)
    roots: dict = field(default_factory=dict)  # (str(radicand), q) -> se Symbol
    angles: dict = field(default_factory=dict)  # sympy base angle -> (s, c)
    circle: list = field(default_factory=list)  # (s, c) pairs tied by s² + c² = 1
    trig_lcm: dict = field(default_factory=dict)  # angle's non-numeric part -> lcm of denominators
    exp_lcm: dict = field(default_factory=dict)
    exps: dict = field(default_factory=dict)  # sympy base exponent -> se Symbol
    memo: dict = field(default_factory=dict)
    normalized: set = field(default_factory=set)  # radicands already in normal form
    count: int = 0

    def gen(self, tag: str) -> se.Symbol:
        self.count += 1
        return se.Symbol(f"_g{self.count}_{tag}")


def _linear_terms(arg: sp.Expr) -> list[tuple[sp.Rational, sp.Expr]]:
    """arg as Σ coefficient·part with rational coefficients (parts not numbers, or 1 for the
    constant)."""
    out = []
    for term in sp.Add.make_args(sp.expand(arg)):
        coeff, rest = term.as_coeff_Mul()
        if not coeff.is_Rational:  # a float in an angle: no exact multiple of a base
            raise NotCanonical("holds floating-point numbers")
        out.append((coeff, rest))
    return out


def _scan(expr: sp.Basic, form: _Form) -> None:
    """Record each angle part's and exponent part's denominators (its base is part/lcm)."""
    for node in sp.preorder_traversal(expr):
        if isinstance(node, TRIG):
            target = form.trig_lcm
        elif isinstance(node, sp.exp):
            target = form.exp_lcm
        else:
            continue
        for coeff, rest in _linear_terms(node.args[0]):
            if rest != 1:
                target[rest] = math.lcm(target.get(rest, 1), int(coeff.q))


def _convert(e: sp.Basic, form: _Form) -> se.Basic:
    hit = form.memo.get(e)
    if hit is not None:
        return hit
    out = _convert_new(e, form)
    form.memo[e] = out
    return out


def _convert_new(e: sp.Basic, form: _Form) -> se.Basic:
    if e.is_Symbol:
        if e not in form.symbols:
            form.symbols[e] = form.gen("v")
        return form.symbols[e]
    if e.is_Rational:
        return se.Rational(int(e.p), int(e.q))
    if e.is_Float:
        raise NotCanonical("holds floating-point numbers")
    if e in (sp.nan, sp.zoo, sp.oo, -sp.oo):
        raise NotCanonical("holds an infinity or an undefined value")
    if e is sp.I:
        return se.I
    if e.is_Add:
        return se.Add(*[_convert(a, form) for a in e.args])
    if e.is_Mul:
        return se.Mul(*[_convert(a, form) for a in _merged_roots(e, form)])
    if e.is_Pow:
        base, ex = e.args
        if ex.is_Integer:
            return _convert(base, form) ** int(ex)
        if ex.is_Rational:
            return _root(base, int(ex.q), form) ** int(ex.p)
        if base is sp.E:
            return _convert(sp.exp(ex), form)
        return _free(e, form)
    if isinstance(e, sp.exp):
        return _exp(e.args[0], form)
    if isinstance(e, TRIG):
        return _trig(e, form)
    if isinstance(e, HYPERBOLIC):
        return _convert(e.rewrite(sp.exp), form)
    if isinstance(e, sp.Expr) and (e.is_number or isinstance(e, sp.Function)
                                   or isinstance(e, sp.NumberSymbol)):
        if isinstance(e, sp.Function):  # its arguments canonical first: one key per value
            args = [_canonical_arg(a) for a in e.args]
            e = e.func(*args) if args != list(e.args) else e
        return _free(e, form)
    raise NotCanonical(f"holds {type(e).__name__}")


def _canonical_arg(a: sp.Basic) -> sp.Basic:
    return sp.expand(a) if isinstance(a, sp.Expr) and len(str(a)) < 2000 else a


def _free(atom: sp.Basic, form: _Form) -> se.Symbol:
    """A generator that stands for `atom` with nothing known about it."""
    if atom not in form.free_atoms:
        form.free_atoms[atom] = form.gen("f")
    return form.free_atoms[atom]


def _merged_roots(m: sp.Mul, form: _Form) -> list[sp.Basic]:
    """The factors of a product, square roots merged into one where that is exact
    (√a·√b = √(ab) when a ≥ 0: all positive radicands and at most one other), so that
    √a·√b and √(ab) meet as one generator."""
    roots = [f for f in m.args if f.is_Pow and f.exp == sp.Rational(1, 2)
             and not f.base.is_number]
    positive = [f for f in roots if f.base.is_positive]
    other = [f for f in roots if f not in positive]
    merged = positive + other[:1]
    if len(merged) < 2 or not positive:
        return list(m.args)
    rest = [f for f in m.args if f not in merged]
    base = sp.expand(sp.Mul(*[f.base for f in merged]))
    form.normalized.add(base)  # not split again by _normal_radicand
    return rest + [sp.Pow(base, sp.Rational(1, 2), evaluate=False)]


def _root(base: sp.Basic, q: int, form: _Form) -> se.Basic:
    """The generator r for base^(1/q), with r^q = base (one generator per radicand, read
    modulo the relations found so far)."""
    normal = None if base in form.normalized else _normal_radicand(base, q)
    if normal is not None:  # (n/d)^(1/q) = (n·d^(q−1))^(1/q)/d for d > 0, content out
        form.normalized |= {p.base for p in normal.atoms(sp.Pow) if not p.exp.is_Integer}
        return _convert(normal, form) ** 1
    value = _convert(base, form)
    num, den = value.as_numer_denom()
    num, den = (_reduce(_expand(x), form.relations) for x in (num, den))
    exact = _rational_root(num, den, q)
    if exact is not None:  # (sin² + cos²)^(1/2) = 1: the radicand is a number, its root too
        return exact
    key = (str(num), str(den), q)
    if key not in form.roots:
        r = form.gen("r")
        form.roots[key] = r
        form.relations.append(_Relation(r, q, num / den))
    return form.roots[key]


def _rational_root(num: se.Basic, den: se.Basic, q: int) -> se.Basic | None:
    """(num/den)^(1/q) where the radicand reduced to a positive rational number whose
    q-th root is rational (the principal root, exactly), else None."""
    if not (isinstance(num, se.Rational) and isinstance(den, se.Rational)) or den == 0:
        return None
    value = sp.Rational(str(num)) / sp.Rational(str(den))
    if value <= 0:
        return None
    root = value ** sp.Rational(1, q)
    return se.Rational(int(root.p), int(root.q)) if root.is_Rational else None


def _normal_radicand(base: sp.Basic, q: int) -> sp.Basic | None:
    """base^(1/q) with a positive denominator moved out and the content of the numerator
    split off by SymPy (√(4x/m²) = 2√x/m for m > 0), or None where nothing changes."""
    if len(str(base)) > 3000:
        return None
    together = sp.together(base)
    n, d = together.as_numer_denom()
    if d != 1 and d.is_positive:
        return sp.Pow(sp.factor_terms(sp.expand(n * d ** (q - 1))), sp.Rational(1, q)) / d
    content = sp.factor_terms(sp.expand(n)) if d == 1 else None
    if content is not None and content != base and not content.is_Add:
        out = sp.Pow(content, sp.Rational(1, q))
        return out if not (out.is_Pow and out.base == content) else None
    return None


def _exp(arg: sp.Expr, form: _Form) -> se.Basic:
    """exp of Σ kᵢ·xᵢ + c as Π Eᵢ^(kᵢ·lcmᵢ), Eᵢ = exp(xᵢ/lcmᵢ) free, exp(c) exact or free."""
    out = se.Integer(1)
    const = sp.Integer(0)
    for coeff, rest in _linear_terms(arg):
        if rest == 1:
            const += coeff
            continue
        if rest.has(sp.I):  # an oscillating exponential: a free generator, nothing assumed
            out *= _free(sp.exp(coeff * rest), form)
            continue
        lcm = form.exp_lcm.get(rest, 1)
        base = rest / lcm
        if base not in form.exps:
            form.exps[base] = form.gen("e")
        out *= form.exps[base] ** int(coeff * lcm)
    if const != 0:
        out *= _free(sp.exp(const), form)
    return out


def _trig(e: sp.Basic, form: _Form) -> se.Basic:
    s, c = _sin_cos(e.args[0], form)
    if isinstance(e, sp.sin):
        return s
    if isinstance(e, sp.cos):
        return c
    if isinstance(e, sp.tan):
        return s / c
    if isinstance(e, sp.cot):
        return c / s
    if isinstance(e, sp.sec):
        return 1 / c
    return 1 / s


def _sin_cos(arg: sp.Expr, form: _Form) -> tuple[se.Basic, se.Basic]:
    """(sin arg, cos arg) as polynomials in the base angles' sines and cosines."""
    S, C = se.Integer(0), se.Integer(1)
    const = sp.Integer(0)
    for coeff, rest in _linear_terms(arg):
        if rest == 1:
            const += coeff
            continue
        lcm = form.trig_lcm.get(rest, 1)
        n = int(coeff * lcm)
        if abs(n) > MAX_MULTIPLE:
            raise NotCanonical(f"an angle {abs(n)} times its base")
        s1, c1 = _multiple(_base(rest / lcm, form), n)
        S, C = S * c1 + C * s1, C * c1 - S * s1
    if const != 0:
        s1, c1 = _base(const, form)
        S, C = S * c1 + C * s1, C * c1 - S * s1
    return S, C


def _base(angle: sp.Expr, form: _Form) -> tuple[se.Basic, se.Basic]:
    """(sin, cos) of a base angle: SymPy's exact values where it has them (sin(asin x) = x,
    cos(π/3) = 1/2), else two generators tied by s² + c² = 1."""
    if angle not in form.angles:
        sin, cos = sp.sin(angle), sp.cos(angle)
        if not (isinstance(sin, TRIG) or isinstance(cos, TRIG)):  # evaluated by SymPy
            form.angles[angle] = (_convert(sin, form), _convert(cos, form))
        else:
            s, c = form.gen("s"), form.gen("c")
            form.relations.append(_Relation(s, 2, 1 - c**2))
            form.circle.append((s, c))
            form.angles[angle] = (s, c)
    return form.angles[angle]


def _multiple(sc: tuple, n: int) -> tuple[se.Basic, se.Basic]:
    """(sin nx, cos nx) from (sin x, cos x) by the addition formula, n ≥ 0 or < 0."""
    s, c = sc
    S, C = se.Integer(0), se.Integer(1)
    for _ in range(abs(n)):
        S, C = se.expand(S * c + C * s), se.expand(C * c - S * s)
    return (S, C) if n >= 0 else (-S, C)


def _terms(e: se.Basic) -> int:
    return len(e.args) if isinstance(e, se.Add) else 1


def _expand(e: se.Basic) -> se.Basic:
    """se.expand(e), bottom up: each product is formed only when its two expanded factors'
    terms multiply to at most MAX_TERMS (SymEngine's expansion cannot be interrupted, so
    its size is bounded before each step; the sizes are the real ones, not a bound)."""
    if isinstance(e, se.Add):
        return se.expand(se.Add(*[_expand(a) for a in e.args]))
    if isinstance(e, se.Mul):
        out = se.Integer(1)
        for f in e.args:
            f = _expand(f)
            if _terms(out) * _terms(f) > MAX_TERMS:
                raise NotCanonical("too large to expand")
            out = se.expand(out * f)
        return out
    if isinstance(e, se.Pow) and e.args[1].is_integer and int(e.args[1]) > 1 \
            and isinstance(e.args[0], (se.Add, se.Mul)):
        base, n = _expand(e.args[0]), int(e.args[1])
        out = se.Integer(1)
        for _ in range(n):
            if _terms(out) * _terms(base) > MAX_TERMS:
                raise NotCanonical("too large to expand")
            out = se.expand(out * base)
        return out
    return e


def _reduce(poly: se.Basic, relations: list) -> se.Basic:
    """The expanded polynomial reduced by the relations, the latest generator first (its
    value may hold earlier ones); twice over, for a power an earlier value brought back."""
    for _ in range(2):
        for rel in reversed(relations):
            poly = _reduce_one(poly, rel)
    return poly


def _reduce_one(poly: se.Basic, rel: _Relation) -> se.Basic:
    if not poly.has(rel.gen):
        return poly
    by_power: dict[int, list] = {}
    for term in (poly.args if isinstance(poly, se.Add) else (poly,)):
        k = int(term.as_powers_dict().get(rel.gen, 0)) if isinstance(term, se.Mul) else \
            (int(term.args[1]) if isinstance(term, se.Pow) and term.args[0] == rel.gen else
             (1 if term == rel.gen else 0))
        by_power.setdefault(k, []).append(term)
    top = max(by_power) // rel.power
    if top == 0:
        return poly
    num, den = rel.value.as_numer_denom()
    out = []
    for k, terms in by_power.items():
        j = k // rel.power
        factor = rel.gen ** (k - j * rel.power) / rel.gen ** k  # g^k → g^(k mod q)
        out.append(se.Add(*terms) * factor * num**j * den ** (top - j))
    return _expand(se.Add(*out))


def _factors(e: se.Basic) -> dict:
    """{base: integer exponent} of a product (a sum or a symbol is its own base)."""
    out: dict = {}
    for f in (e.args if isinstance(e, se.Mul) else (e,)):
        if isinstance(f, se.Pow) and f.args[1].is_integer:
            base, k = f.args[0], int(f.args[1])
        else:
            base, k = f, 1
        out[base] = out.get(base, 0) + k
    return out


def _product(factors: dict) -> se.Basic:
    return se.Mul(*[b**k for b, k in factors.items() if k])


def _numer_denom(e: se.Basic) -> tuple[se.Basic, se.Basic]:
    """(numerator, denominator) of e over a common denominator, nothing expanded: a sum's
    denominator is the least common multiple of its terms' factors (by base and exponent).
    Why: SymEngine's as_numer_denom spent 6 s on one of Symon 11-05's Euler equations
    (nested fractions), this 0.05 s; the value num/den is e's wherever e is defined."""
    num, den = _nd(e)
    return _product(num), _product(den)


def _nd(e: se.Basic) -> tuple[dict, dict]:
    """_numer_denom's factor dictionaries {base: exponent > 0}."""
    if isinstance(e, se.Add):
        parts = [_nd(a) for a in e.args]
        lcm: dict = {}
        for _, d in parts:
            for b, k in d.items():
                lcm[b] = max(lcm.get(b, 0), k)
        terms = [_product(n) * _product({b: k - d.get(b, 0) for b, k in lcm.items()})
                 for n, d in parts]
        return {se.Add(*terms): 1}, lcm
    if isinstance(e, se.Mul):
        num: dict = {}
        den: dict = {}
        for f in e.args:
            n, d = _nd(f)
            for b, k in n.items():
                num[b] = num.get(b, 0) + k
            for b, k in d.items():
                den[b] = den.get(b, 0) + k
        return num, den
    if isinstance(e, se.Pow) and e.args[1].is_integer:
        n, d = _nd(e.args[0])
        k = int(e.args[1])
        if k < 0:
            n, d, k = d, n, -k
        return {b: j * k for b, j in n.items()}, {b: j * k for b, j in d.items()}
    if isinstance(e, se.Rational) and not isinstance(e, se.Integer):
        n, d = e.as_numer_denom()
        return {n: 1}, {d: 1}
    return {e: 1}, {}


def _exact_values(form: _Form, rng: random.Random) -> dict:
    """A rational point: each symbol and free generator a small rational, each circle
    (s, c) a rational point on it."""
    point = {}
    for sym, g in form.symbols.items():
        v = sp.Rational(rng.randint(1, 97), rng.randint(1, 13))
        point[g] = v if (sym.is_positive or rng.random() < 0.5) else -v
    for s, c in form.circle:
        t = sp.Rational(rng.randint(-40, 40), rng.randint(1, 17))
        point[s], point[c] = 2 * t / (1 + t**2), (1 - t**2) / (1 + t**2)
    return {k: se.sympify(v) for k, v in point.items()}


def _exact_nonzero(v: se.Basic) -> bool:
    """An exact, finite, nonzero number."""
    v = v._sympy_()
    return bool(v.is_number and v.is_finite and v != 0 and not v.has(sp.nan, sp.zoo))


def decide_zero(expr: sp.Basic, seed: int = 20261207) -> Decision:
    """Is `expr` identically 0? Proved (True) by its canonical form's reduction; decided
    False only where the form is complete (no roots, no free generators); None otherwise.

    >>> x = sp.Symbol("x")
    >>> decide_zero(sp.sin(2 * x) - 2 * sp.sin(x) * sp.cos(x)).zero
    True
    """
    if expr == 0:
        return Decision(True)
    form = _Form()
    try:
        _scan(expr, form)
        value = _convert(expr, form)
        complete = not (form.free_atoms or form.exps or form.roots)
        num, den = _numer_denom(value)
        if complete:
            rng = random.Random(seed)
            for _ in range(POINTS):
                point = _exact_values(form, rng)
                if _exact_nonzero(den.subs(point)) and _exact_nonzero(num.subs(point)):
                    return Decision(False, "not an identity: nonzero at an exact rational point")
        reduced = _reduce(_expand(num), form.relations)
    except NotCanonical as exc:
        return Decision(None, str(exc))
    except (RecursionError, RuntimeError, TypeError, ValueError, AttributeError) as exc:
        return Decision(None, f"no canonical form ({type(exc).__name__})")
    if reduced == 0:
        try:
            den_reduced = _reduce(_expand(den), form.relations)
        except NotCanonical as exc:
            return Decision(None, str(exc))
        except (RecursionError, RuntimeError, TypeError, ValueError, AttributeError) as exc:
            return Decision(None, f"no canonical form ({type(exc).__name__})")
        if den_reduced != 0:
            return Decision(True)
        return Decision(None, "its denominator vanishes identically")
    if complete:
        return Decision(False, "not an identity: its canonical form is not 0")
    if form.roots:
        return Decision(None, "a root's branch" if _one_branch(reduced, form) else
                        "not reduced to 0 (roots)")
    return Decision(None, "not reduced to 0 (functions kept whole)")


def _one_branch(reduced: se.Basic, form: _Form) -> bool:
    """Does the remainder vanish with some square root's sign flipped: the identity holds
    on one branch only (a sign the assumptions do not fix)?"""
    roots = set(form.roots.values())
    squares = [rel for rel in form.relations if rel.power == 2 and rel.gen in roots]
    point = _float_point(form)
    for rel in squares[:3]:
        if point is not None and _clearly_nonzero(reduced, rel.gen, point):
            continue  # R(r)·R(−r) ≠ 0 at a point of the variety: its reduction cannot be 0
        flipped = reduced.subs({rel.gen: -rel.gen})
        try:
            norm = _reduce(_expand(reduced * flipped), form.relations)
        except NotCanonical:
            return False
        if norm == 0:
            return True
    return False


def _float_point(form: _Form, seed: int = 20261207) -> dict | None:
    """A point of the generators' variety in complex doubles: each free generator a random
    number in [0.6, 1.9] (a circle's cosine in (−0.9, 0.9)), each relation's generator a
    root of its value (any root lies on the variety); None where a value does not
    evaluate."""
    rng = random.Random(seed)
    bound = {rel.gen for rel in form.relations}
    cosines = {c for _, c in form.circle}
    gens = set(form.symbols.values()) | set(form.free_atoms.values()) | \
        set(form.exps.values()) | cosines
    point = {g: complex(rng.uniform(-0.9, 0.9) if g in cosines else rng.uniform(0.6, 1.9))
             for g in gens if g not in bound}
    try:
        for rel in form.relations:
            point[rel.gen] = _at(rel.value, point) ** (1.0 / rel.power)
    except (RuntimeError, TypeError, ValueError, ZeroDivisionError, OverflowError):
        return None
    return point


def _at(e: se.Basic, point: dict) -> complex:
    return complex(e.xreplace({g: se.sympify(v) for g, v in point.items()}))


def _clearly_nonzero(reduced: se.Basic, gen: se.Symbol, point: dict) -> bool:
    """R(r)·R(−r) far from 0 at a point of the variety (a million times double precision's
    rounding of its terms): then no reduction of it is 0, and the exact product (its
    expansion the square of R's size: Symon 12-10's motion, 6 s) is not needed."""
    flipped = dict(point)
    flipped[gen] = -point[gen]
    try:
        terms = reduced.args if isinstance(reduced, se.Add) else (reduced,)
        a = [_at(t, point) for t in terms]
        b = [_at(t, flipped) for t in terms]
    except (RuntimeError, TypeError, ValueError, ZeroDivisionError, OverflowError):
        return False
    scale = sum(abs(x) for x in a) * sum(abs(x) for x in b)
    value = abs(sum(a) * sum(b))
    return math.isfinite(scale) and value > 1e-6 * scale


def nonzero_determinant(M: sp.Matrix, seed: int = 20261207) -> bool:
    """Is det M not identically 0, decided exactly and cheaply: its entries at a rational
    point (each symbol a small positive rational) are rational numbers whose determinant is
    nonzero (a polynomial nonzero at a point is not identically 0). False where that cannot
    be shown so (entries irrational there, or the determinant 0 at the points tried).

    >>> a = sp.Symbol("a", positive=True)
    >>> nonzero_determinant(sp.Matrix([[a, 1], [1, a]]))
    True
    """
    rng = random.Random(seed)
    symbols = sorted(M.free_symbols, key=str)
    for _ in range(POINTS):
        point = {s: sp.Rational(rng.randint(1, 97), rng.randint(1, 13)) for s in symbols}
        try:
            values = M.xreplace(point)
        except Exception:  # noqa: BLE001 - an entry that does not take the point
            return False
        if not all(v.is_Rational for v in values):  # irrational there: a small one exactly
            return M.rows <= 4 and decide_zero(M.det(method="berkowitz")).zero is False
        if values.det(method="bareiss") != 0:
            return True
    return False
