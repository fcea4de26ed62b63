"""Which numerically found roots are one root: polishing, and what the arithmetic resolves.

Newton's method stops where the residual falls below a tolerance. At a simple root that is
within rounding of the root; at a flat one (a degenerate minimum V = c·x⁴, whose force
−4c·x³ has a triple root) it converges only linearly, and starts on either side stop at
different points: x = ±1.6e-5, ±1.8e-5 beside 0, each with a residual below 1e-13. Those
are no equilibria (the force there is small, not zero). So each candidate is polished:
Newton's steps, accelerated by the multiplicity their shrinking shows (a root of
multiplicity m shrinks each step by (m − 1)/m, and m times the step lands on it:
Schröder's method), until a step is at rounding level. Then two candidates are one root
when the conditions, evaluated at 30 digits with the magnitude of what cancelled on the way
(core.numeval), are zero to double precision's rounding at both and all along the segment
between them: within the root's own conditioning radius nothing the search computes tells
the points apart. Two true equilibria, however close, have a resolved force between them
and stay two. Where the conditions are polynomial the count is certified besides
(engine.certified_count, by the callers that count).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate

FLAT = 1e-6  # the Jacobian's smallest singular value against its size over the starts
ROUNDING = 1e-13  # a residual this small against the magnitude of its terms: double's noise
POLISH_STEPS = 60
STALL = 0.98  # steps shrinking slower than this three times running: nothing to polish
SEGMENT_SAMPLES = 8  # points on the segment between two candidates (besides the ends)
NEAR = 1e-3  # farther apart than this (relative) flat points are never one root: a root of
# multiplicity m is blurred over u^(1/m) by double precision, 1e-4 at m = 4
_U = np.finfo(float).eps


def polish(fj: Callable, x: np.ndarray) -> np.ndarray:
    """`x` moved onto the root Newton's method converges to: pseudo-inverse steps (a
    singular Jacobian does not stop it), each multiplied by the multiplicity
    m = 1/(1 − ρ) that the ratio ρ of successive steps shows when it converges linearly;
    until a step is at rounding level. `fj(x)`: (conditions, Jacobian) at x. The point of
    least residual met is returned; `x` itself where the steps stop shrinking (no root
    near: a region where the force only fades)."""
    start = x = np.array(x, dtype=float)
    best, best_res = x.copy(), float("inf")
    prev, stalls = None, 0
    with np.errstate(all="ignore"):
        for _ in range(POLISH_STEPS):
            F, J = fj(x)
            F = np.asarray(F, float)
            J = np.asarray(J, float).reshape(len(F), len(x))
            if not (np.all(np.isfinite(F)) and np.all(np.isfinite(J))):
                break
            res = float(np.max(np.abs(F)))
            if res <= best_res:
                best, best_res = x.copy(), res
            step = np.linalg.pinv(J) @ F
            size = float(np.linalg.norm(step))
            if size <= 4 * _U * max(1.0, float(np.linalg.norm(x))):
                last = x - step
                F_last = np.asarray(fj(last)[0], float)
                if np.all(np.isfinite(F_last)) and float(np.max(np.abs(F_last))) <= best_res:
                    best = last
                break
            m = 1.0
            if prev is not None:
                ratio = size / prev
                stalls = stalls + 1 if ratio >= STALL else 0
                if stalls >= 3:
                    return start
                if 0.2 < ratio < STALL:
                    m = min(1.0 / (1.0 - ratio), 50.0)  # linear convergence: m-fold root
            prev = size
            x = x - m * step
            if not np.all(np.isfinite(x)):
                break
    return best


def unresolved(conds: Sequence[sp.Expr], point: dict) -> bool | None:
    """Every condition zero to double precision's rounding at `point` (30-digit value
    against ROUNDING of the magnitude of its terms); None where one does not evaluate."""
    for c in conds:
        try:
            v, mag = evaluate(c, point, 30)
        except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError):
            return None
        if abs(v) > ROUNDING * mag:
            return False
    return True


def one_root(conds: Sequence[sp.Expr], unknowns: Sequence[sp.Symbol], values: dict,
             a: np.ndarray, b: np.ndarray) -> bool:
    """Are the candidates `a` and `b` one root: the conditions unresolved from zero at both
    and at SEGMENT_SAMPLES points between them (`values`: the parameters)?"""
    for t in np.linspace(0.0, 1.0, SEGMENT_SAMPLES + 2):
        y = (1 - t) * np.asarray(a, float) + t * np.asarray(b, float)
        point = dict(values)
        point.update({u: sp.Float(float(v), 30) for u, v in zip(unknowns, y, strict=True)})
        if unresolved(conds, point) is not True:
            return False
    return True


def jacobian_scale(jacobians: Callable, X: np.ndarray) -> float:
    """The Jacobian's typical size over the starts X (rows): its largest entry, median over
    them: what a flat root's smallest singular value is small against."""
    with np.errstate(all="ignore"):
        J = np.abs(np.asarray(jacobians(X), float).reshape(len(X), -1))
    big = np.max(np.where(np.isfinite(J), J, 0.0), axis=1)
    big = big[big > 0]
    return float(np.median(big)) if len(big) else 0.0


class FlatRoots:
    """Polishing and merging of one search's flat roots. A point whose Jacobian is
    singular against `scale` (FLAT) is flat: it is polished, counts only where the
    conditions are zero to rounding there, and is one root with another flat point when
    they are zero to rounding all along the segment between them. Other points are left
    as the search found them (a simple root is within rounding of itself).

    `entries(x)`: the conditions' values then the Jacobian's entries (row by row) at x
    (doubles); `symbolic()`: (the conditions in SymPy with the parameters' values put in,
    the unknowns), asked only when a flat point is met."""

    def __init__(self, entries: Callable, n: int, scale: float, symbolic: Callable):
        self.entries, self.n, self.scale = entries, n, scale
        self._symbolic, self._made = symbolic, None

    def f(self, x):
        return np.asarray(self.entries(x), float)[:self.n]

    def jac(self, x):
        n = self.n
        return np.asarray(self.entries(x), float)[n:n + n * n].reshape(n, n)

    def is_flat(self, x) -> bool:
        with np.errstate(all="ignore"):
            J = self.jac(x)
        if self.scale == 0 or not np.all(np.isfinite(J)):
            return False
        return bool(np.linalg.svd(J, compute_uv=False)[-1] <= FLAT * self.scale)

    def polished(self, x):
        return polish(lambda y: (self.f(y), self.jac(y)), x) if self.is_flat(x) else x

    def _sym(self):
        if self._made is None:
            self._made = self._symbolic()
        return self._made

    def spurious(self, x) -> bool:
        """A flat point whose conditions are resolved, not zero: one Newton's method
        stopped at beside a flat root, not a root."""
        if not self.is_flat(x):
            return False
        conds, unknowns = self._sym()
        point = {u: sp.Float(float(v), 30) for u, v in zip(unknowns, x, strict=True)}
        return unresolved(conds, point) is False

    def same(self, a, b) -> bool:
        """Flat points `a` and `b` that the arithmetic cannot tell apart (one_root)."""
        a, b = np.asarray(a, float), np.asarray(b, float)
        if np.max(np.abs(a - b)) > NEAR * max(1.0, float(np.max(np.abs(a)))):
            return False
        if not (self.is_flat(a) and self.is_flat(b)):
            return False
        conds, unknowns = self._sym()
        return one_root(conds, unknowns, {}, a, b)
