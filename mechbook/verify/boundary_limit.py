"""A relation that holds only in a limit (`limit:` on a stability condition): its boundary
must approach the engine's, at the order claimed.

Kapitza's inverted pendulum is stable where a²ω² > 2gl only as the drive gets fast and
small; the first resonance tongue of a modulated oscillator is |γ − 2ω0| < hω0/2 only to
first order in h. At finite drive the engine's boundary (Floquet's) differs from the
book's; the claim is that the difference vanishes toward the limit like the next order.

At each step of the walk toward the limit (mechbook.verify.asymptotic) the book's
boundary is located along each *probe*: every free parameter the relation depends on
(directly or through a `restrict:`ed symbol) except the limit's. A ray
through the step's point in that parameter alone (log scale for a positive one, factors up
to e^SPAN each way) finds every place where the book's relation changes truth, refined to
30 digits (mechbook.verify.boundary). Around each crossing the engine's verdict is taken
on both sides at offsets growing by decades from FLOOR until it agrees with the book's on
both (a crossing of the engine's own within that offset), never farther than halfway to
the next crossing; the engine's crossing is then bisected in the logarithm of the offset
to 0.2 %. The error at the step is the largest such offset (relative, for a positive
parameter): the distance between the two boundaries. An engine with no crossing near the
book's is an infinite error. Offsets below FLOOR are not resolved: the walk stops there.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.numeval import holds
from mechbook.errors import MechbookError
from mechbook.verify import boundary
from mechbook.verify.asymptotic import asymptotic
from mechbook.verify.compare import Verdict
from mechbook.verify.context import Context

FLOOR = 1e-14  # the smallest offset from the book's boundary that is tried
GRID = 40  # points along each probe's ray where the book's truth is read
BRACKET = 1e-6  # the Boolean bisection's bracket before the atom's root is refined
BISECTIONS = 10  # of the log offset between two decades: 10^(1/1024), 0.2 %


def probes(ctx: Context, cond: sp.Basic) -> list[sp.Symbol]:
    """The parameters along which the book's boundary is located."""
    sampler = ctx.sampler
    limit = ctx.names[ctx.part.data["limit"]["parameter"]]
    direct = set().union(*(a.free_symbols for a in boundary.atoms_of(cond)))
    deps = set(direct)
    for sym, expr in sampler.derived.items():
        if sym in direct:
            deps |= expr.free_symbols
    out = sorted((s for s in deps if s in sampler.base and s not in sampler.fixed
                  and s not in sampler.derived and s != limit), key=lambda s: s.name)
    if not out:
        raise ctx.part.error(("limit",), "the relation depends on no parameter but the "
                             "limit's: its boundary has nothing to be located along")
    return out


def check(ctx: Context, cond: sp.Basic, classify: boundary.Classifier) -> Verdict:
    """The book's relation as an asymptotic claim: the distance between its boundary and
    the engine's must fall at the order `limit:` states."""
    along = probes(ctx, cond)
    atoms = boundary.atoms_of(cond)

    last: dict = {}  # the probe along which the last step's error was largest

    def error(pt: dict) -> float:
        worst, found = 0.0, 0
        for p in along:
            ray = _Ray(ctx.sampler, pt, np.array([1.0]), [p])
            for t_star, below, above, reach in _book_crossings(cond, atoms, ray):
                found += 1
                e = _engine_offset(classify, ray, t_star, below, above, reach)
                if e >= worst:
                    worst, last["probe"] = e, p.name
        return worst if found else math.inf

    got = asymptotic(ctx, error, floor=FLOOR)
    names = ", ".join(s.name for s in along)
    where = f" (largest along {last['probe']} at the last step)" if len(along) > 1 and \
        "probe" in last else ""
    detail = f"boundary located along {names}{where}; {got.detail}"
    if not got.ok:
        return Verdict(False, got.method, detail)
    return Verdict(True, got.method, detail,
                   power=f"{got.power}; the distance between the book's boundary and the "
                         f"engine's along {names}, resolved to {FLOOR:g}")


class _Ray(boundary.Ray):
    """A probe's ray whose points are computed once each (the grid, the bisection, the
    atoms' values and the engine's verdicts ask for the same points)."""

    def __init__(self, *args):
        super().__init__(*args)
        self._points: dict = {}

    def point(self, t) -> dict | None:
        key = mpmath.mpf(t)
        if key not in self._points:
            self._points[key] = super().point(t)
        return self._points[key]


def _book_crossings(cond: sp.Basic, atoms: list, ray: boundary.Ray) -> list[tuple]:
    """(t*, the book's truth below and above it, how far the engine's crossing may be
    sought) for every place along the ray where the book's relation changes truth: where
    the truth differs between grid points, and where an atom dips through zero and back
    between them (a resonance tongue narrower than the grid: its minimum is located by
    golden sections and each side bisected)."""
    ts = np.linspace(-boundary.SPAN, boundary.SPAN, GRID)

    def book(t):
        pt = ray.point(t)
        return None if pt is None else holds(cond, pt)

    truths = [book(t) for t in ts]
    brackets = [(float(ts[k]), float(ts[k + 1]), truths[k]) for k in range(len(ts) - 1)
                if truths[k] is not None and truths[k + 1] is not None
                and truths[k] != truths[k + 1]]
    for f in atoms:
        vals = [_signed(f, ray, t) for t in ts]
        for k in range(1, len(ts) - 1):
            a, b, c = vals[k - 1: k + 2]
            if a is None or b is None or c is None or not (a > 0) == (b > 0) == (c > 0) \
                    or abs(b) > abs(a) or abs(b) > abs(c):
                continue
            sign = 1 if b > 0 else -1
            t_min, v = _golden(lambda t, f=f, sign=sign: _signed(f, ray, t), sign,
                               float(ts[k - 1]), float(ts[k + 1]))
            inside = book(t_min)
            if v is None or v * sign >= 0 or inside is None or inside == truths[k - 1] \
                    or truths[k - 1] is None or truths[k + 1] != truths[k - 1]:
                continue
            brackets += [(float(ts[k - 1]), t_min, truths[k - 1]), (t_min, float(ts[k + 1]),
                                                                     inside)]
    found: list[tuple] = []
    for a, b, fa in brackets:
        while b - a > BRACKET:  # Boolean bisection to a bracket the root finder closes
            m = (a + b) / 2
            fm = book(m)
            if fm is None:
                break
            a, b = (m, b) if fm == fa else (a, m)
        else:
            t_star, _ = boundary.refine(atoms, ray, a, b)
            if all(abs(t_star - other) > 1e-12 for other, _, _ in found):
                found.append((t_star, fa, not fa))
    found.sort(key=lambda x: x[0])
    out = []
    for i, (t_star, b0, b1) in enumerate(found):
        left = found[i - 1][0] if i else -boundary.SPAN
        right = found[i + 1][0] if i + 1 < len(found) else boundary.SPAN
        out.append((t_star, b0, b1, float(min(t_star - left, right - t_star)) / 2))
    return out


def _signed(f: sp.Expr, ray: boundary.Ray, t) -> float | None:
    pt = ray.point(t)
    got = None if pt is None else boundary.value_at(f, pt)
    return None if got is None else got[0]


def _golden(f, sign: int, a: float, b: float) -> tuple[float, float | None]:
    """The minimum of sign·f on [a, b] by golden sections: (t, f there)."""
    ratio = (math.sqrt(5) - 1) / 2

    def g(t):
        v = f(t)
        return math.inf if v is None else sign * v

    c, d = b - ratio * (b - a), a + ratio * (b - a)
    gc, gd = g(c), g(d)
    for _ in range(100):
        if gc <= gd:
            b, d, gd = d, c, gc
            c = b - ratio * (b - a)
            gc = g(c)
        else:
            a, c, gc = c, d, gd
            d = a + ratio * (b - a)
            gd = g(d)
        if b - a < boundary.BISECT_TOL:
            break
    t = c if gc <= gd else d
    return t, f(t)


def _engine_offset(classify: boundary.Classifier, ray: boundary.Ray, t_star, below: bool,
                   above: bool, reach: float) -> float:
    """How far from t_star the engine's verdict changes the way the book's does there
    (FLOOR where it already agrees at FLOOR; inf where it does not within `reach`)."""
    def verdict(t) -> bool | None:
        pt = ray.point(t)
        if pt is None:
            return None
        try:
            return classify(pt, True)
        except MechbookError:
            return None

    sigma, previous = FLOOR, None  # previous: (sigma, below agreed, above agreed)
    while sigma <= reach:
        lo, hi = verdict(t_star - sigma), verdict(t_star + sigma)
        if lo == below and hi == above:
            if previous is None:
                return FLOOR
            s_in, below_ok, _ = previous  # the engine's crossing: between s_in and sigma
            side, want = (-1, below) if not below_ok else (1, above)
            s_out = sigma
            for _ in range(BISECTIONS):
                mid = math.sqrt(s_in * s_out)
                if verdict(t_star + side * mid) == want:
                    s_out = mid
                else:
                    s_in = mid
            return math.sqrt(s_in * s_out)
        previous = (sigma, lo == below, hi == above)
        sigma *= 10
    return math.inf
