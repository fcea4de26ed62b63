"""Relations decided at their boundary: where the book's condition changes truth.

A book's relation (a stability condition, where a steady motion exists) is right only if its
boundary is the engine's. Points drawn at random rarely land between a boundary and one
moved by a percent, so sampling alone passes near misses. Here the parameter space is
crossed along random rays (log coordinates for positive symbols, factors up to e^SPAN each
way); on each ray a grid of points compares the two verdicts widely, every place where
the book's relation changes truth is found by bisection and refined on the atom that
flips (30 digits), and both verdicts are taken just inside and just outside it, a relative
offset EPS away. A boundary the engine puts elsewhere, by more than EPS, disagrees on one
side. Tangencies (an atom touching zero without changing sign: a double root of the
boundary) are found as minima of |atom| along the ray and judged on both sides too.

The engine's verdict is a function `classify(point, near) -> bool | None` (None: no
verdict there, e.g. marginal; a MechbookError it raises is no verdict either, and its
message is kept as the reason); `near` asks for its precise path (a boundary is close).

An outcome says only what was evaluated: `fail` where a point contradicted the book; where
the engine gave no verdict at any point (time-dependent coefficients, say) the check is
unsupported with the engine's reason, and where the points never straddled the book's
boundary it is undecided (an error saying how to widen it), never a fail.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate, evaluate_mp, holds
from mechbook.core.words import plural
from mechbook.errors import MechbookError, UndecidedError, UnsupportedError, WrongAnswerError
from mechbook.verify.compare import DIGITS, Sampler, Verdict

RAYS = 8  # random rays through parameter space
MORE_RAYS = 40  # tried in addition while some side of the relation is not yet crossed
GRID = 40  # points per ray, each judged by both sides
SPAN = 2.5  # a positive parameter moves by factors up to e^SPAN each way along a ray
EPS = 1e-8  # relative offset of the points judged on either side of a crossing
EPS_STEPS = (1e-8, 1e-6, 1e-4)  # coarser offsets where the engine has no verdict closer
BISECT_TOL = 1e-13  # the Boolean bisection's bracket (in ray units, ~ relative change)
BRACKET = 1e-6  # ... or this, where one atom's root in it is closed by the root finder
TANGENT_RTOL = 1e-12  # an atom's minimum this small against its scale is a touching zero
POINTS_KEPT = 4096  # points a ray keeps

Classifier = Callable[[dict, bool], "bool | None"]


@dataclass
class BoundaryResult:
    """What the comparison saw: crossings judged, tangencies, the offset used."""

    ok: bool
    crossings: int = 0
    tangencies: int = 0
    unjudged: int = 0  # crossings where the engine gave no verdict even at the coarsest EPS
    points: int = 0  # grid points judged by both sides
    eps: float = EPS
    detail: str = ""
    sides: tuple = (0, 0)  # sides of the relation crossed, of those that can be
    # why ok is False: "fail" (a point contradicted the book), "unsupported" (the engine
    # gave no verdict anywhere: `detail` says why), "undecided" (nothing straddled the
    # boundary, or no crossing could be judged)
    outcome: str = "fail"


class Ray:
    """Parameter points along p(t): log-linear in positive symbols, linear in the others
    (in units of `scales[symbol]`, by default max(1, |value|))."""

    def __init__(self, sampler: Sampler, origin: dict, direction: np.ndarray,
                 symbols: list[sp.Symbol], scales: dict | None = None):
        self.sampler = sampler
        self.origin = origin
        self.symbols = symbols
        self.direction = direction
        self.scales = scales or {}
        self._points: dict = {}
        self._values: dict = {}

    def point(self, t) -> dict | None:
        """The admissible point at t (None where a condition fails or a derived symbol is
        not real), all values at 30 digits. Each is computed once (the grid's points are
        asked for by the atoms' roots, the tangencies and both verdicts), and handed out
        as a copy."""
        with mpmath.workdps(DIGITS + 20):  # the key at full precision (offsets of 1e-25)
            key = mpmath.mpf(t)
        if key not in self._points:
            if len(self._points) >= POINTS_KEPT:
                self._points.clear()
            self._points[key] = self._point(t)
        got = self._points[key]
        return None if got is None else dict(got)

    def value(self, f: sp.Expr, t) -> tuple[float, float] | None:
        """`value_at(f, self.point(t))`, each computed once (the atoms' roots and the
        tangencies read the same grid)."""
        with mpmath.workdps(DIGITS + 20):
            key = (f, mpmath.mpf(t))
        if key not in self._values:
            if len(self._values) >= POINTS_KEPT:
                self._values.clear()
            pt = self.point(t)
            self._values[key] = None if pt is None else value_at(f, pt)
        return self._values[key]

    def _point(self, t) -> dict | None:
        with mpmath.workdps(DIGITS + 5):
            t = mpmath.mpf(t)
            pt = dict(self.origin)
            for sym, d in zip(self.symbols, self.direction, strict=True):
                x0 = mpmath.mpf(self.origin[sym]._mpf_)
                d = float(d)  # a NumPy double: the same number, mpmath's fast path
                if sym in self.scales:
                    x = x0 + t * d * mpmath.mpf(self.scales[sym])
                elif sym.is_positive:
                    x = x0 * mpmath.exp(t * d)
                else:
                    x = x0 + t * d * max(1, abs(x0))
                pt[sym] = float_at_digits(x)
        pt = self.sampler.complete(pt)
        if pt is None or not all(holds(c, pt) for c in self.sampler.conditions):
            return None
        return pt


_PREC = mpmath.libmp.dps_to_prec(DIGITS)


def float_at_digits(x: mpmath.mpf) -> sp.Float:
    """`sp.Float(x, DIGITS)`, the same number bit for bit (x rounded to nearest at DIGITS'
    binary precision), without SymPy's inspection of its arguments (a third of a ray
    point's cost: thousands of points a check). Zero, infinities and NaN: SymPy's own.
    Example: float_at_digits(mpmath.mpf(1) / 3) == sp.Float(mpmath.mpf(1) / 3, 30)."""
    m = x._mpf_
    if not m[1]:
        return sp.Float(x, DIGITS)
    return sp.Float._new(mpmath.libmp.mpf_pos(m, _PREC, "n"), _PREC, zero=False)


def atoms_of(cond: sp.Basic) -> list[sp.Expr]:
    """lhs − rhs of every relation in a condition (joined by and/or/not)."""
    rels = [a for a in cond.atoms(sp.core.relational.Relational)] \
        if isinstance(cond, sp.Basic) else []
    return [r.lhs - r.rhs for r in rels]


def atom_roots(atoms: list[sp.Expr], ray: Ray, ts: np.ndarray) -> list[tuple]:
    """Every place along the ray where an atom of the relation goes through zero, as
    (t, atom's index), sorted: a change of sign between grid points, and a dip through zero
    and back between them (its minimum located by golden sections, each side's root
    refined). A compound relation (`or`, `and`, a chained inequality, a piecewise form)
    changes truth only at such places, and a zone narrower than the grid (a resonance
    tongue as its width goes to 0) lies between two of them, of one atom or of two."""
    out: list[tuple] = []
    for i, f in enumerate(atoms):
        vals = []
        for t in ts:
            got = ray.value(f, t)
            vals.append(None if got is None else got[0])
        for k in range(len(ts) - 1):
            a, b = vals[k], vals[k + 1]
            if a is not None and b is not None and (a > 0) != (b > 0):
                out.append((refine([f], ray, float(ts[k]), float(ts[k + 1]))[0], i))
        for k in range(1, len(ts) - 1):
            a, b, c = vals[k - 1: k + 2]
            if a is None or b is None or c is None or not (a > 0) == (b > 0) == (c > 0) \
                    or abs(b) > abs(a) or abs(b) > abs(c):
                continue
            sign = 1 if b > 0 else -1
            t_min, v = _signed_minimum(f, ray, sign, float(ts[k - 1]), float(ts[k + 1]))
            if v is None or v * sign >= 0:
                continue
            out += [(refine([f], ray, float(ts[k - 1]), t_min)[0], i),
                    (refine([f], ray, t_min, float(ts[k + 1]))[0], i)]
    out.sort(key=lambda x: x[0])
    return out


def truth_changes(cond: sp.Basic, atoms: list[sp.Expr], ray: Ray,
                  ts: np.ndarray) -> list[tuple]:
    """(t, the book's truth just below, just above, the atom's index) at every atom root
    along the ray where
    the relation's truth changes (mechbook.verify.boundary.atom_roots), each side read a
    quarter of the way to the next root (at most 1e-9 in ray units)."""
    roots = atom_roots(atoms, ray, ts)
    out = []
    for k, (t0, i) in enumerate(roots):
        gaps = [abs(t0 - roots[j][0]) for j in (k - 1, k + 1) if 0 <= j < len(roots)]
        gaps = [g for g in gaps if g > mpmath.mpf(10) ** -(DIGITS - 2)]
        with mpmath.workdps(DIGITS + 20):  # offsets below 1e-16 of t0 need the digits
            d = min([mpmath.mpf(1e-9)] + [g / 4 for g in gaps])
            lo, hi = ray.point(t0 - d), ray.point(t0 + d)
        if lo is None or hi is None:
            continue
        below, above = holds(cond, lo), holds(cond, hi)
        if below != above and all(abs(t0 - s[0]) > 1e-25 for s in out):
            out.append((t0, below, above, i))
    return out


def _narrow_changes(cond, atoms, ray, ts, grid) -> list[tuple]:
    """The truth changes (truth_changes) inside grid cells whose two ends the book's
    relation gives the same truth: those the grid's own brackets miss."""
    out = []
    for change in truth_changes(cond, atoms, ray, ts):
        k = int(np.searchsorted(ts, float(change[0]))) - 1
        if 0 <= k < len(ts) - 1 and grid[k][0] is not None and grid[k][0] == grid[k + 1][0]:
            out.append(change)
    return out


def _signed_minimum(f: sp.Expr, ray: Ray, sign: int, a: float, b: float):
    """The minimum of sign·f on [a, b] by golden sections: (t, f there or None)."""
    ratio = (math.sqrt(5) - 1) / 2

    def f_at(t):
        pt = ray.point(t)
        got = None if pt is None else value_at(f, pt)
        return None if got is None else got[0]

    def g(t):
        v = f_at(t)
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
        if b - a < BISECT_TOL:
            break
    t = c if gc <= gd else d
    return t, f_at(t)


def value_at(f: sp.Expr, pt: dict) -> tuple[float, float] | None:
    try:
        v, m = evaluate(f, pt, DIGITS)
    except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError):
        return None
    if not (math.isfinite(v.real) and abs(v.imag) <= 1e-20 * max(1.0, abs(v))):
        return None
    return v.real, m


class _Silence:
    """Why the engine gave no verdict, counted over a whole comparison: the reasons an
    UnsupportedError or another MechbookError gave, and the points it called marginal."""

    def __init__(self):
        self.unsupported: dict[str, int] = {}
        self.errors: dict[str, int] = {}
        self.marginal = 0

    def ask(self, classify: Classifier, pt: dict, near: bool) -> bool | None:
        try:
            got = classify(pt, near)
        except WrongAnswerError:
            raise  # the answer named something wrong: a fail, decided elsewhere
        except UnsupportedError as exc:
            self.unsupported[exc.capability] = self.unsupported.get(exc.capability, 0) + 1
            return None
        except MechbookError as exc:
            self.errors[str(exc)] = self.errors.get(str(exc), 0) + 1
            return None
        if got is None:
            self.marginal += 1
        return got

    def reason(self) -> tuple[str, str]:
        """(outcome, why) where the engine decided nothing: unsupported where it said it
        cannot (or found every point marginal), undecided where it failed otherwise."""
        def most(d: dict) -> str:
            return max(d, key=d.get)
        if self.unsupported:
            return "unsupported", most(self.unsupported)
        if self.errors:
            return "undecided", most(self.errors)
        return "unsupported", "the engine finds every point marginal (no verdict)"


class _Judge:
    """Both verdicts at points of one ray."""

    def __init__(self, cond: sp.Basic, classify: Classifier, ray: Ray, silence: _Silence):
        self.cond, self.classify, self.ray, self.silence = cond, classify, ray, silence

    def engine(self, pt: dict | None, near: bool) -> bool | None:
        return None if pt is None else self.silence.ask(self.classify, pt, near)

    def book(self, t) -> bool | None:
        pt = self.ray.point(t)
        return None if pt is None else holds(self.cond, pt)

    def both(self, t, near: bool) -> tuple[bool | None, bool | None, dict | None]:
        pt = self.ray.point(t)
        if pt is None:
            return None, None, None
        book = holds(self.cond, pt)
        return book, (None if book is None else self.engine(pt, near)), pt


def _bisect(fn: Callable, a: float, b: float, fa,
            tol: float = BISECT_TOL) -> tuple[float, float] | None:
    """Shrink [a, b] (fn(a) = fa ≠ fn(b)) to `tol`; None if fn has no value inside."""
    while b - a > tol:
        m = (a + b) / 2
        fm = fn(m)
        if fm is None:
            return None
        if fm == fa:
            a = m
        else:
            b = m
    return a, b


def _crossing(atoms: list[sp.Expr], judge: _Judge, a: float, b: float,
              fa: bool) -> tuple[mpmath.mpf, int] | None:
    """Where the book's truth changes in the grid cell [a, b] (fa at a), to 30 digits, and
    the index of the atom whose root it is: the Boolean bisection to BRACKET, then the
    atom's root there (`refine`) where exactly one atom changes sign in that bracket and
    its root lies inside; else, as everywhere before, the bisection on to BISECT_TOL and
    the root refined from there. None where the relation has no truth value on the way.
    The Boolean steps below BRACKET only narrowed what the root finder closes anyway."""
    ray = judge.ray
    coarse = _bisect(judge.book, a, b, fa, BRACKET)
    if coarse is None:
        return None
    lo, hi = coarse
    flips = _changing(atoms, ray, lo, hi)
    if len(flips) == 1:
        t = _root(atoms[flips[0]], ray, lo, hi)
        if t is not None and lo <= t <= hi:
            return t, flips[0]
    fine = _bisect(judge.book, lo, hi, fa)
    return None if fine is None else refine(atoms, ray, *fine)


def _changing(atoms: list[sp.Expr], ray: Ray, a: float, b: float) -> list[int]:
    """The atoms whose values at a and b have opposite signs ([] where one has none)."""
    pa, pb = ray.point(a), ray.point(b)
    if pa is None or pb is None:
        return []
    out = []
    for i, f in enumerate(atoms):
        va, vb = value_at(f, pa), value_at(f, pb)
        if va is None or vb is None:
            return []
        if (va[0] > 0) != (vb[0] > 0):
            out.append(i)
    return out


def refine(atoms: list[sp.Expr], ray: Ray, a: float, b: float) -> tuple[mpmath.mpf, int]:
    """The crossing to 30 digits: the root of the atom that changes sign in [a, b], and
    that atom's index (the bisection's midpoint and -1 where none does cleanly)."""
    pa, pb = ray.point(a), ray.point(b)
    for i, f in enumerate(atoms):
        va = value_at(f, pa) if pa else None
        vb = value_at(f, pb) if pb else None
        if va is None or vb is None or (va[0] > 0) == (vb[0] > 0):
            continue

        got = _root(f, ray, a, b)
        return (mpmath.mpf((a + b) / 2) if got is None else got), i
    return mpmath.mpf((a + b) / 2), -1


def _root(f: sp.Expr, ray: Ray, a: float, b: float) -> mpmath.mpf | None:
    """The root of f along the ray from the bracket [a, b] (30 digits), None where the
    root finder fails."""
    g = _along(f, ray)
    try:
        with mpmath.workdps(DIGITS):
            return mpmath.findroot(g, (mpmath.mpf(a), mpmath.mpf(b)), solver="anderson",
                                   tol=mpmath.mpf(10) ** (-2 * DIGITS + 10))
    except (ValueError, ZeroDivisionError):
        return None


def _along(f: sp.Expr, ray: Ray) -> Callable:
    """t ↦ f at the ray's point (an mpmath number; ValueError where it has none)."""
    def g(t):
        pt = ray.point(t)
        if pt is None:
            raise ValueError("no admissible point")
        try:
            got = evaluate_mp(f, pt, DIGITS)
        except (NotNumeric, ZeroDivisionError, TypeError, OverflowError) as exc:
            raise ValueError(str(exc)) from None
        if not isinstance(got, mpmath.mpf):
            if abs(mpmath.im(got)) > 1e-20 * max(1, abs(got)):
                raise ValueError("not real")
            got = mpmath.re(got)
        return got

    return g


def _tangencies(atoms: list[sp.Expr], ray: Ray, ts: np.ndarray) -> list[tuple]:
    """Places where an atom touches zero without changing sign (a double root): local
    minima of |atom| on the grid, refined by golden-section search, kept if they reach
    TANGENT_RTOL of the atom's scale."""
    out = []
    for i, f in enumerate(atoms):
        vals = []
        for t in ts:
            vals.append(ray.value(f, t))
        for k in range(1, len(ts) - 1):
            trio = vals[k - 1: k + 2]
            if any(v is None for v in trio):
                continue
            (a, _), (b, _), (c, _) = trio
            if not (abs(b) <= abs(a) and abs(b) <= abs(c)) or (a > 0) != (c > 0) or \
                    (a > 0) != (b > 0):
                continue
            t_min, v_min, scale = _golden(f, ray, ts[k - 1], ts[k + 1])
            if v_min is not None and v_min <= TANGENT_RTOL * max(scale, 1e-300):
                out.append((t_min, i))
    return out


def _golden(f: sp.Expr, ray: Ray, a: float, b: float, steps: int = 80):
    ratio = (math.sqrt(5) - 1) / 2

    def h(t):
        pt = ray.point(t)
        got = None if pt is None else value_at(f, pt)
        return (math.inf, 1.0) if got is None else (abs(got[0]), got[1])

    c, d = b - ratio * (b - a), a + ratio * (b - a)
    hc, hd = h(c), h(d)
    for _ in range(steps):
        if hc[0] <= hd[0]:
            b, d, hd = d, c, hc
            c = b - ratio * (b - a)
            hc = h(c)
        else:
            a, c, hc = c, d, hd
            d = a + ratio * (b - a)
            hd = h(d)
        if b - a < BISECT_TOL:
            break
    best = min((hc, c), (hd, d), key=lambda x: x[0][0])
    (v, scale), t = best
    return mpmath.mpf(t), (None if v == math.inf else v), scale


def _show(pt: dict) -> str:
    items = sorted(pt.items(), key=lambda kv: kv[0].name)[:8]
    return "{" + ", ".join(f"{k}={float(v):.10g}" for k, v in items) + "}"


def _engine_crossing(judge: _Judge, a: float, b: float) -> str:
    """Where the engine's verdict changes between a and b, for the message."""
    ea = judge.engine(judge.ray.point(a), True)
    eb = judge.engine(judge.ray.point(b), True)
    if ea is None or eb is None or ea == eb:
        return ""
    got = _bisect(lambda t: judge.engine(judge.ray.point(t), True), a, b, ea)
    if got is None:
        return ""
    return f"; the engine's boundary on this ray is at {_show(judge.ray.point(got[0]))}"


def compare(cond: sp.Basic, classify: Classifier, sampler: Sampler,
            words: tuple[str, str] = ("true", "false"), seed: int = 20261125,
            scales: dict | None = None, rays: int = RAYS, grid: int = GRID,
            origins: Callable[[], dict] | None = None) -> BoundaryResult:
    """Does the book's `cond` hold exactly where `classify` says True? `words` name the two
    verdicts in messages (e.g. 'stable', 'unstable'). The rays vary the sampler's free
    symbols (not fixed, not derived); `scales` ({symbol: length}) sets a symbol's unit
    along a ray (a phase-space coordinate in units of its region's size, say); `rays` and
    `grid` trade cost for coverage where one verdict is expensive (a flow integrated);
    `origins` draws each ray's starting point (default: the sampler's draw)."""
    rng = np.random.default_rng(seed)
    symbols = sorted((s for s in sampler.base if s not in sampler.fixed
                      and s not in sampler.derived), key=lambda s: s.name)
    if not symbols:
        return BoundaryResult(False, detail="no free parameter to vary")
    atoms = atoms_of(cond)
    ts = np.linspace(-SPAN, SPAN, grid)
    res = BoundaryResult(True)
    seen = {True: 0, False: 0}
    n_rays = rays
    rays = 0
    sides = {i for i, f in enumerate(atoms) if f.free_symbols & set(symbols)}
    crossed: set[int] = set()
    silence = _Silence()
    book_points = 0  # grid points where the book's relation has a truth value
    while rays < n_rays + MORE_RAYS:
        if rays >= n_rays and res.crossings + res.tangencies > 0 and sides <= crossed:
            break  # every side of the relation crossed at least once
        rays += 1
        origin = origins() if origins is not None else sampler.draw()
        d = rng.normal(size=len(symbols))
        d /= np.linalg.norm(d)
        ray = Ray(sampler, origin, d, symbols, scales)
        judge = _Judge(cond, classify, ray, silence)
        grid = [judge.both(t, False) for t in ts]
        for b, e, pt in grid:
            book_points += b is not None
            if b is None or e is None:
                continue
            res.points += 1
            seen[b] += 1
            if b != e:
                res.ok = False
                res.detail = (f"the book says {words[0] if b else words[1]}, the engine finds "
                              f"{words[0] if e else words[1]} at {_show(pt)}")
                return res
        # every change of the book's truth along the ray: bisect, refine, judge both sides
        for k in range(len(ts) - 1):
            b0, b1 = grid[k][0], grid[k + 1][0]
            if b0 is None or b1 is None or b0 == b1:
                continue
            got = _crossing(atoms, judge, float(ts[k]), float(ts[k + 1]), b0)
            if got is None:
                continue
            t_star, side = got
            crossed.add(side)

            bad = _judge_crossing(judge, t_star, res, words)
            if bad:
                res.ok = False
                res.detail = bad + _engine_crossing(judge, float(ts[k]), float(ts[k + 1]))
                return res
            res.crossings += 1
        # a zone narrower than the grid (the book's truth the same at a cell's two ends,
        # another inside): between two roots of the relation's atoms
        for t_star, _, _, side in _narrow_changes(cond, atoms, ray, ts, grid):
            crossed.add(side)
            bad = _judge_crossing(judge, t_star, res, words)
            if bad:
                res.ok = False
                res.detail = bad
                return res
            res.crossings += 1
        for t_star, side in _tangencies(atoms, ray, ts):
            crossed.add(side)
            bad = _judge_crossing(judge, t_star, res, words, tangent=True)
            if bad:
                res.ok = False
                res.detail = bad
                return res
            res.tangencies += 1
    if res.points == 0:  # not one point judged by both sides: nothing was evaluated
        res.ok = False
        if book_points == 0:
            res.outcome = "undecided"
            res.detail = (f"the book's relation has no truth value at any of the points of "
                          f"{rays} rays (it does not evaluate there)")
        else:
            res.outcome, why = silence.reason()
            res.detail = (f"{why} (no verdict of the engine at any of "
                          f"{plural(book_points, 'point')} "
                          f"on {rays} rays: nothing was compared)")
        return res
    if res.crossings + res.tangencies == 0 or min(seen.values()) == 0:
        res.ok, res.outcome = False, "undecided"
        res.detail = (f"no ray crossed the book's boundary ({rays} rays, "
                      f"{plural(res.points, 'point')}: "
                      f"{seen[True]} {words[0]}, {seen[False]} {words[1]}, all agreeing): the "
                      "check cannot discriminate (widen the parameters or `assume:` a region)")
        return res
    if res.unjudged and res.unjudged == res.crossings:
        res.ok, res.outcome = False, "unsupported"
        res.detail = (f"the engine gives no verdict near any of the {res.crossings} crossings "
                      "(marginal there): the boundary cannot be compared")
        return res
    judged = res.crossings - res.unjudged
    tang = f", {res.tangencies} tangencies" if res.tangencies else ""
    skipped = f", {res.unjudged} not judged (marginal)" if res.unjudged else ""
    missed = len(sides - crossed)
    side_note = (f", {len(sides) - missed} of {len(sides)} sides crossed" if missed else
                 (f", all {len(sides)} sides crossed" if len(sides) > 1 else ""))
    res.sides = (len(sides) - missed, len(sides))
    res.detail = (f"boundary agrees at {judged} crossings to {res.eps:g}{tang}{skipped}"
                  f"{side_note}; {plural(res.points, 'point')} on {rays} rays ({seen[True]} "
                  f"{words[0]}, {seen[False]} {words[1]})")
    return res


def _judge_crossing(judge: _Judge, t_star, res: BoundaryResult, words: tuple[str, str],
                    tangent: bool = False) -> str:
    """Both verdicts just inside and just outside the crossing at t_star ('' if they agree;
    a crossing where the engine has no verdict at any offset counts as unjudged)."""
    for eps in EPS_STEPS:
        sides = [judge.both(t_star + s * eps, True) for s in (-1, 1)]
        if any(b is None for b, _, _ in sides):
            continue  # the crossing sits on the edge of the admissible region
        if any(e is None for _, e, _ in sides):
            continue
        res.eps = max(res.eps, eps)
        for b, e, pt in sides:
            if b != e:
                kind = "touches its boundary" if tangent else "changes"
                return (f"where the book's relation {kind} ({_show(judge.ray.point(t_star))}),"
                        f" at a relative offset {eps:g}: the book says "
                        f"{words[0] if b else words[1]}, the engine finds "
                        f"{words[0] if e else words[1]} at {_show(pt)}")
        return ""
    res.unjudged += 1
    return ""


def verdict(result: BoundaryResult, crossings_word: str = "crossings") -> Verdict:
    """A Verdict stating the boundary's resolution (its power). Where nothing contradicted
    the book (the engine gave no verdict, or nothing straddled the boundary) there is no
    verdict: UnsupportedError or UndecidedError with the reason."""
    if not result.ok:
        if result.outcome == "unsupported":
            raise UnsupportedError(result.detail)
        if result.outcome == "undecided":
            raise UndecidedError(result.detail)
        return Verdict(False, "boundary", result.detail)
    judged = result.crossings - result.unjudged
    tang = f" and {result.tangencies} tangencies" if result.tangencies else ""
    crossed, sides = result.sides
    where = (f" ({crossed} of {sides} sides)" if crossed < sides else
             f" (all {sides} sides)" if sides > 1 else "")
    return Verdict(True, f"boundary({judged} {crossings_word} to {result.eps:g})", result.detail,
                   power=f"boundary at {judged} {crossings_word}{tang}{where} to "
                         f"{result.eps:g}, {plural(result.points, 'point')} on both sides")

