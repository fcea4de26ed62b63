"""Numeric equilibria at the default parameter values, and which of them are stable.

SymPy's closed-form search (simplify, then solve) is the expensive way to find equilibria:
on most of the book's systems it spends its whole time limit and finds nothing, because
the conditions are transcendental. Where no part asks for a closed form (the engine's own
cross-checks, the choice of an equilibrium a part does not name), Newton's method from a
grid of starts, all at once as arrays, finds the equilibria at the default values in
milliseconds, and M, C, K there say which are stable. Points that the equations cannot
tell apart (a full turn of an angle, a shift along a symmetry of the whole system) count
as one; an equilibrium that is not isolated (a free translation or a cyclic angle) is
reported as such. A flat equilibrium (a degenerate minimum, V = c·x⁴), where Newton's method
converges slowly and stops at points around it whose force is small but not zero, is found
as one: each converged point is polished and the points the arithmetic cannot tell apart
merged (mechbook.engine.flat_roots).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import symengine as se
import sympy as sp

from mechbook.core.compile import compile_batch
from mechbook.engine.equilibria import Equilibria
from mechbook.engine.flat_roots import FlatRoots, jacobian_scale
from mechbook.engine.linear import classify_matrices
from mechbook.errors import UnsupportedError

STARTS = 7  # per coordinate, on [-π, π] (as Equilibria.numeric); sampled beyond MAX_STARTS
MAX_STARTS = 2000
NEWTON_STEPS = 50
MAX_FOUND = 64  # more distinct equilibria than this: a continuum, not isolated points
SAME_POINT = 1e-7  # coordinates closer than this (relative) are one point
SHIFT_TOL = 1e-9  # the equations agree to this (relative) after a shift: a symmetry
SINGULAR = 1e-9  # Jacobian's smallest singular value relative to its largest: not isolated


@dataclass(frozen=True)
class Found:
    """A numerically found equilibrium and its stability at the default values."""

    point: np.ndarray  # one value per coordinate
    stability: str  # 'stable', 'marginal', 'unstable' or 'unknown' (did not evaluate)
    isolated: bool  # the conditions' Jacobian is regular there


@dataclass
class Screen:
    """The distinct equilibria of a system at the default values, and a test of whether
    two points are the same for its equations."""

    found: list[Found]
    _entries: object  # X (k, n) -> every entry (conditions, Jacobian, M, C) at each row

    def same(self, a, b) -> bool:
        """Do `a` and `b` name the same equilibrium: equal, or a shift between them that
        leaves the equations unchanged (a full turn, a symmetry of the whole system)?"""
        a, b = np.asarray(a, float), np.asarray(b, float)
        if np.all(np.abs(a - b) <= SAME_POINT * np.maximum(1.0, np.abs(a))):
            return True
        return bool(_invariant(self._entries, (b - a)[None, :])[0])


def snap(x: float) -> sp.Expr:
    """A numerically found coordinate as SymPy: k·π/12 exactly when it is that to 1e-10
    (0, a quarter turn, ...), else a Float."""
    k = round(x * 12 / np.pi)
    return k * sp.pi / 12 if abs(x - k * np.pi / 12) < 1e-10 else sp.Float(float(x))


def screen(eq: Equilibria, values: dict, ranges: dict | None = None) -> Screen:
    """Equilibria of `eq`'s system at `values` (starts on [-π, π] per coordinate, or on
    `ranges` {coordinate: (low, high)}), classified by the linear equations there.

    UnsupportedError where the search does not apply: multiplier constraints, time or a
    parameter without a value left in the conditions, or more distinct equilibria than
    MAX_FOUND (a continuum)."""
    dyn, sys = eq.dyn, eq.sys
    if sys.constraints or sys.velocity_constraints:
        raise UnsupportedError("numeric equilibria with multiplier constraints")
    n = len(dyn.q)
    # the algebra in SymEngine: differentiating and substituting large residuals takes
    # milliseconds there, seconds in SymPy
    q = [se.sympify(x) for x in dyn.q]
    num = {se.sympify(k): float(v) for k, v in values.items()}
    rest = {se.sympify(v): 0 for v in dyn.qd + dyn.qdd}
    rest.update({se.sympify(s): 0 for s in sys.small_params})
    held = {se.sympify(k): se.sympify(v) for k, v in sys.held.items()}
    residuals = [se.sympify(e) for e in dyn.residuals]
    conds = [e.subs(rest).subs(held).subs(num) for e in residuals]
    if any(c.has(se.sympify(sys.t)) for c in conds) or sys.free_driven:
        # time that cancels only numerically, or an arbitrary driven coordinate: the
        # engine's own conditions decide (and refuse what has no static equilibria)
        conds = [se.sympify(c).subs(num) for c in eq.conditions]
    jac = [c.diff(x) for c in conds for x in q]
    mc = [e.diff(se.sympify(a)).subs(rest).subs(held).subs(num)
          for group in (dyn.qdd, dyn.qd) for e in residuals for a in group]
    if set().union(*(x.free_symbols for x in conds + jac + mc)) - set(q):
        raise UnsupportedError("numeric equilibria: a symbol without a default value (or "
                               "time) is left in the equations")
    entries = compile_batch(q, conds + jac + mc)
    starts = _starts(q, ranges)
    scale = jacobian_scale(lambda X: entries(X)[:, n:n + n * n], starts)
    converged = _newton(entries, n, starts.copy())
    flat = FlatRoots(lambda x: entries(np.asarray(x, float)[None, :])[0, :n + n * n], n,
                     scale, lambda: ([c._sympy_() for c in conds], [x._sympy_() for x in q]))
    points = _distinct(entries, converged, n, flat)
    found = []
    if points:
        for x, row in zip(points, entries(np.array(points)), strict=True):
            found.append(_classify(x, row, n))
    return Screen(found, entries)


def _starts(q: list, ranges: dict | None) -> np.ndarray:
    """The grid of starts (a sample of MAX_STARTS of its nodes when it has more)."""
    axes = [np.linspace(*((ranges or {}).get(x, (-np.pi, np.pi))), STARTS) for x in q]
    total = STARTS ** len(q)
    flat = np.arange(total) if total <= MAX_STARTS else \
        np.random.default_rng(0).choice(total, MAX_STARTS, replace=False)
    idx = np.unravel_index(flat, (STARTS,) * len(q))
    return np.column_stack([axes[i][idx[i]] for i in range(len(q))]).astype(float)


def _newton(entries, n: int, X: np.ndarray) -> np.ndarray:
    """Newton's method on every start at once (pseudo-inverse steps, so a singular
    Jacobian does not stop it); the converged points."""
    live = np.ones(len(X), bool)
    done = np.zeros(len(X), bool)
    with np.errstate(all="ignore"):
        for _ in range(NEWTON_STEPS):
            idx = np.flatnonzero(live & ~done)
            if not len(idx):
                break
            out = entries(X[idx])
            F, J = out[:, :n], out[:, n:n + n * n].reshape(-1, n, n)
            finite = np.all(np.isfinite(out[:, :n + n * n]), axis=1)
            live[idx[~finite]] = False
            small = finite & (np.max(np.abs(F), axis=1) < 1e-13)
            done[idx[small]] = True
            step = finite & ~small
            if np.any(step):
                k = idx[step]
                X[k] -= np.einsum("kij,kj->ki", np.linalg.pinv(J[step]), F[step])
        F = entries(X)[:, :n]
    good = live & np.all(np.isfinite(X), axis=1) & (np.max(np.abs(F), axis=1) < 1e-10)
    return X[good]


def _distinct(entries, X: np.ndarray, n: int, flat: FlatRoots) -> list[np.ndarray]:
    """One representative (the smallest) of each class of points the equations cannot
    tell apart (a shift between them, or a flat root's points the arithmetic does not
    resolve: each new flat point is polished first); a flat point whose force is resolved
    is no equilibrium and is dropped."""
    reps: list[np.ndarray] = []

    def known(x) -> bool:
        if any(np.all(np.abs(x - r) <= SAME_POINT * np.maximum(1.0, np.abs(r))) for r in reps):
            return True
        return bool(reps) and bool(np.any(_invariant(entries, np.array(reps) - x)))

    for x in sorted(X, key=lambda x: (float(np.max(np.abs(x))), tuple(x))):
        if known(x):
            continue
        y = flat.polished(x)
        if (y is not x and known(y)) or flat.spurious(y) or any(flat.same(r, y) for r in reps):
            continue
        reps.append(y)
        if len(reps) > MAX_FOUND:
            raise UnsupportedError("numeric equilibria: not isolated (more than "
                                   f"{MAX_FOUND} distinct ones)")
    return reps


def _invariant(entries, shifts: np.ndarray, probes: int = 3) -> np.ndarray:
    """For each shift s (rows), are all entries the same at x and x + s for random x?"""
    rng = np.random.default_rng(5)
    k, n = shifts.shape
    X = rng.uniform(-2.0, 2.0, (probes, n))
    with np.errstate(all="ignore"):
        base = entries(X)  # (probes, m)
        moved = entries((X[None, :, :] + shifts[:, None, :]).reshape(-1, n))
    moved = moved.reshape(k, probes, -1)
    scale = np.maximum(1.0, np.nanmax(np.abs(base))) if np.any(np.isfinite(base)) else 1.0
    ok = np.all(np.isfinite(base)) & np.all(np.isfinite(moved), axis=(1, 2))
    return ok & np.all(np.abs(moved - base[None]) <= SHIFT_TOL * scale, axis=(1, 2))


def _classify(x: np.ndarray, row: np.ndarray, n: int) -> Found:
    J = row[n:n + n * n].reshape(n, n)
    M = row[n + n * n:n + 2 * n * n].reshape(n, n)
    C = row[n + 2 * n * n:].reshape(n, n)
    if not np.all(np.isfinite(row)):
        return Found(x, "unknown", False)
    sv = np.linalg.svd(J, compute_uv=False)
    isolated = bool(sv[0] > 0 and sv[-1] > SINGULAR * sv[0])
    try:
        verdict = classify_matrices(M, C, J)
    except (ValueError, np.linalg.LinAlgError):
        verdict = "unknown"
    return Found(x, verdict, isolated)
