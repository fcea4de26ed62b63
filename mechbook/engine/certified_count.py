"""How many solutions lie in a box, certified where the conditions are polynomial.

A multistart search (mechbook.engine.steady_search.roots_in) finds solutions but cannot
prove there are no others: its count is a lower bound. Where the conditions, at a rational
parameter point, reduce to polynomials in the unknowns (after factors that never vanish are
removed: constants, exp(·)), a lexicographic Gröbner basis decides the count exactly: in
shape position (x_i = h_i(x_n) for i < n and one univariate g(x_n)), the real solutions are
the real roots of g (h_i have rational coefficients), which Sturm sequences count and isolate
in rational intervals (sympy's real-root isolation); each root is refined until the other
coordinates, h_i at the interval's ends, sit clearly inside or outside the box. Anything
else (trigonometric conditions, a basis not in shape position, a positive-dimensional set,
a root on a box's edge) returns None: not certified, and the caller says its count is a
lower bound.
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from fractions import Fraction

import mpmath
import sympy as sp

from mechbook.core.timeout import Timeout, time_limit

SECONDS = 10.0  # CPU for one certification (Gröbner bases can blow up)
REFINE = 60  # bisections of an isolating interval at most


def _rational(v) -> sp.Rational:
    """A parameter's value as a nearby simple rational (the certified point)."""
    f = Fraction(float(v)).limit_denominator(10**6)
    return sp.Rational(f.numerator, f.denominator)


def _polynomial_factors(expr: sp.Expr, unknowns: list[sp.Symbol]) -> tuple[list, list] | None:
    """(numerator factors that can vanish, denominators) of one condition, or None if a
    factor that can vanish is not a polynomial in the unknowns."""
    num, den = sp.together(expr).as_numer_denom()
    keep = []
    _, factors = sp.factor_list(sp.expand(num)) if num.is_polynomial(*unknowns) else \
        (None, [(f, 1) for f in sp.Mul.make_args(num)])
    for f, _mult in factors:
        base = f.base if isinstance(f, sp.Pow) and f.exp.is_Integer and f.exp > 0 else f
        if not base.free_symbols & set(unknowns):
            continue  # a constant factor
        if isinstance(base, sp.exp):
            continue  # never zero
        if not base.is_polynomial(*unknowns):
            return None
        keep.append(sp.expand(base))
    dens = []
    for d in sp.Mul.make_args(den):
        base = d.base if isinstance(d, sp.Pow) and d.exp.is_Integer else d
        if not base.free_symbols & set(unknowns) or isinstance(base, sp.exp):
            continue  # a constant or an exponential: never zero
        if not base.is_polynomial(*unknowns):
            return None
        dens.append(base)
    return keep, dens


def certified_count(conds: list[sp.Expr], unknowns: list[sp.Symbol], values: dict,
                    boxes: list[dict]) -> tuple[int, dict] | None:
    """(number of solutions inside the boxes, the rational parameter point) or None."""
    point = {k: _rational(v) for k, v in values.items()}
    try:
        with time_limit(SECONDS):
            return _count(conds, unknowns, point, boxes)
    except (Timeout, sp.PolynomialError, sp.polys.polyerrors.PolificationFailed,
            NotImplementedError, ValueError, TypeError, ZeroDivisionError):
        return None


def _count(conds, unknowns, point, boxes):
    polys, dens = [], []
    for c in conds:
        got = _polynomial_factors(c.xreplace(point), unknowns)
        if got is None:
            return None
        keep, den = got
        if not keep:
            return 0, point  # a condition that never vanishes: no solution anywhere
        polys.append(sp.Mul(*keep))
        dens += den
    if len(polys) < len(unknowns):
        return None
    G = sp.groebner(polys, *unknowns, order="lex", domain="QQ")
    if list(G.exprs) == [1]:
        return 0, point
    if not G.is_zero_dimensional:
        return None
    shape = _shape_position(list(G.exprs), unknowns)
    if shape is None:
        return None
    h, g = shape
    x = unknowns[-1]
    count = 0
    for (lo, hi), _mult in sp.Poly(g, x).intervals():
        inside = _root_inside(g, x, h, sp.Rational(lo), sp.Rational(hi), boxes, dens, unknowns)
        if inside is None:
            return None
        count += inside
    return count, point


def _shape_position(G: list[sp.Expr], unknowns: list[sp.Symbol]):
    """({x_i: h_i(x_n)}, g(x_n)) if the basis is x_i − h_i(x_n) (i < n) and g(x_n)."""
    x = unknowns[-1]
    univariate = [p for p in G if p.free_symbols <= {x}]
    if len(univariate) != 1 or len(G) != len(unknowns):
        return None
    h = {}
    for xi in unknowns[:-1]:
        lead = [p for p in G if p.free_symbols & {xi}]
        if len(lead) != 1:
            return None
        poly = sp.Poly(lead[0], xi)
        if poly.degree() != 1 or not poly.LC().free_symbols <= set():
            return None
        sol = sp.solve(lead[0], xi)
        if len(sol) != 1 or not sol[0].free_symbols <= {x}:
            return None
        h[xi] = sol[0]
    return h, univariate[0]


def _root_inside(g, x, h, lo, hi, boxes, dens, unknowns) -> int | None:
    """1 if the real root of g isolated in [lo, hi] gives a point strictly inside one of
    the boxes (and no denominator vanishes there), 0 if outside all, None if undecided."""
    poly = sp.Poly(g, x)
    for _ in range(REFINE):
        decided = _decide(h, x, lo, hi, boxes, unknowns)
        if decided is not None:
            if decided and dens:
                mid = (lo + hi) / 2
                at = {x: mid, **{xi: hi_.subs(x, mid) for xi, hi_ in h.items()}}
                if any(abs(sp.N(d.xreplace(at), 30)) < sp.Float(1e-20) for d in dens):
                    return None
            return int(decided)
        if lo == hi:
            return None
        # SymPy's refinement of the isolating interval (a bisection by count_roots would
        # count a neighbour's root on a shared end: 0 of x³ − x/10⁶ in [0, 1/2] with 10⁻³)
        lo, hi = (sp.Rational(v) for v in poly.refine_root(lo, hi, eps=(hi - lo) / 4,
                                                             check_sqf=True))
    return None


@contextmanager
def _iv_digits(dps: int):
    """mpmath's interval context at `dps` digits (it has no workdps of its own)."""
    old = mpmath.iv.dps
    mpmath.iv.dps = dps
    try:
        yield
    finally:
        mpmath.iv.dps = old


def _enclosure(hx: sp.Expr, x: sp.Symbol, lo: sp.Rational, hi: sp.Rational):
    """An interval (mpmath.iv) that holds the polynomial hx(x) for every x in [lo, hi]:
    Horner's rule in interval arithmetic on its rational coefficients."""
    coeffs = sp.Poly(hx, x).all_coeffs()
    with _iv_digits(60):
        X = mpmath.iv.mpf([mpmath.mpf(lo.p) / lo.q, mpmath.mpf(hi.p) / hi.q])
        acc = mpmath.iv.mpf(0)
        for c in coeffs:
            c = sp.Rational(c)
            acc = acc * X + mpmath.iv.mpf(c.p) / c.q
        return acc


def _decide(h, x, lo, hi, boxes, unknowns) -> bool | None:
    """Is every point of the interval (and its images h_i, enclosed in interval arithmetic)
    inside a box (True), outside all (False), or undecided (None)?"""
    with _iv_digits(60):
        ranges = {x: mpmath.iv.mpf([mpmath.mpf(lo.p) / lo.q, mpmath.mpf(hi.p) / hi.q])}
        for xi, hx in h.items():
            ranges[xi] = _enclosure(hx, x, lo, hi)
        verdicts = []
        for box in boxes:
            inside, outside = True, False
            for q in unknowns:
                blo, bhi = (float(b) for b in box.get(q, (-math.pi, math.pi)))
                r = ranges[q]
                if not (r.a > blo and r.b < bhi):
                    inside = False
                if r.b < blo or r.a > bhi:
                    outside = True
            if inside:
                return True
            verdicts.append(outside)
    return False if all(verdicts) else None
