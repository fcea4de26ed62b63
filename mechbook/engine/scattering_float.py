"""The deflection angle in double precision, with a bound on its error: for decisions.

A decision about Θ(b) (is it monotone between b/100 and 100b, does it exceed π, is it
nonzero) needs Θ to ~1e-13, not the 30 digits mechbook.engine.scattering's quadratures
give at ~5 ms an orbit at 20 digits; NumPy does it in ~1 ms. The same orbit (its P, m∞, core and the
inward search's geometric grid are the mpmath Orbit's), in double precision:

- the turning point: the search's grid r_n = r_0·0.98^n evaluated at once, the first
  point where E − V_eff is not positive bracketing the root, refined by Brent's method;
- the integral after the same r = r_s/(1 − w²), by Gauss–Legendre rules of N and 2N nodes
  on [w_lo, 1] (the integrand is analytic there for a potential analytic in 1/r, as the
  turning point's 1/√ singularity is gone). E − V_eff is small near r_s and its difference
  cancels there: below w = SWITCH it is −(r − r_s)·V_eff′ averaged over [r_s, r] (a
  six-node rule on that short interval, no cancellation), above E′ − V_eff(r) with
  E′ = V_eff(r_s) (so that both vanish exactly at r_s: the orbit is that of energy E′,
  within a rounding of E, not one whose integral misses a √δ near a misplaced root).

The bound: ERROR_SAFETY times the two rules' difference, plus a rounding floor scaled by
the turning point's conditioning E/(r_s·|V_eff′(r_s)|) or by 1/(1 − w_lo) (the rounding
of w near 1 against a short interval, when the root is far inside a core). Where double
precision cannot answer — no NumPy form of the system, an orbit that falls in, a sign of
E − V_eff within rounding of zero on the grid, a nearly double root, a non-finite value,
or a bound above MAX_ERROR — the answer is None and the caller takes the mpmath orbit.
"""

from __future__ import annotations

import math
import warnings
from functools import cache

import numpy as np
from scipy.optimize import brentq

from mechbook.engine.scattering import DIGITS, FAR, MAX_STEPS, STEP, Orbit, float_grid

NODES = 48  # Gauss–Legendre nodes of the coarser rule (the finer has twice as many)
SWITCH = 0.25  # below this w, E − V_eff from its derivative (no cancellation)
ERROR_SAFETY = 10.0  # the bound: this many times the two rules' difference, ...
ROUNDING = 1e-13  # ... plus this, times (1 + |Θ|) and the turning point's conditioning
MARGIN = 1e-9  # a sign of E − V_eff on the grid within this of |E| + |V_eff|: undecided
MAX_CONDITION = 1e4  # E/(r_s|V_eff′|) above this: nearly a double root, undecided
MAX_ERROR = 1e-10  # a bound above this: double precision cannot say


@cache
def _rule(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return (x + 1) / 2, w / 2


def float_deflection(orbit: Orbit) -> tuple[float, float] | None:
    """(Θ, a bound on its error) of `orbit` in double precision, or None where double
    precision cannot decide (the caller then asks `orbit.deflection`). Unbound as
    `orbit.P` raises it.

    >>> # theta, err = float_deflection(scattering.orbit(point, b, E, 20))
    """
    fns = orbit.scattering.float_functions
    if fns is None:
        return None
    P = orbit.P  # the checks of an unbound orbit first (mpmath, cheap)
    try:
        args = (float(P), *(float(p) for p in orbit.params))
        E = float(orbit.E)
        core = None if orbit.core is None else float(orbit.core)
        scale = float(orbit.scale)
    except (OverflowError, ValueError, TypeError):
        return None
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            turn = _turning(fns, args, E, core, scale)
            if turn is None:
                return None
            return _integral(fns, args, E, *turn)
        except (ZeroDivisionError, ValueError, OverflowError, TypeError, FloatingPointError,
                RuntimeError):  # RuntimeError: Brent's method did not converge
            return None


def _values(fn, r, args) -> np.ndarray:
    return np.broadcast_to(np.asarray(fn(r, *args), dtype=float), np.shape(r))


def _turning(fns, args, E: float, core, scale: float):
    """(r_s, r_min, E_s, at_root): the singular point of the substitution (the turning
    point, or on a core the root inside it), where the orbit turns, the energy the
    integrand uses (V_eff(r_s) at a root, E on a core with no root inside) and whether
    r_s is a root; None where undecided."""
    _, V, _, _ = fns
    r0 = scale * FAR
    for _ in range(3):
        v0 = float(_values(V, r0, args))
        if math.isfinite(v0) and E - v0 > MARGIN * (abs(E) + abs(v0)):
            break
        r0 *= FAR
    else:
        return None
    tiny = scale * 10.0 ** (-DIGITS)
    grid = np.concatenate(([r0], float_grid(r0)))
    inside = np.nonzero(grid <= max(core or 0.0, tiny))[0]
    end = int(inside[0]) if inside.size else grid.size  # the first step past the core/tiny
    hit = _first_barred(V, args, E, grid[:end])
    if hit is False:
        return None
    if hit is not None:
        root = _root(V, args, E, grid[hit], grid[hit - 1])
        return root, root, float(_values(V, root, args)), True
    if end == grid.size or core is None or grid[end] > core:
        return None  # out of steps, or falls in (captured): the mpmath orbit says so
    vc = float(_values(V, core, args))
    if not math.isfinite(vc) or abs(E - vc) <= MARGIN * (abs(E) + abs(vc)):
        return None
    if E - vc < 0:
        root = _root(V, args, E, core, grid[end - 1])
        return root, root, float(_values(V, root, args)), True
    n = int(math.log(tiny / core) / math.log(float(STEP))) + 2  # below the core
    below = core * np.cumprod(np.full(min(n, MAX_STEPS), float(STEP)))
    below = np.concatenate(([core], below[below >= tiny]))
    hit = _first_barred(V, args, E, below)
    if hit is False:
        return None
    if hit is None:
        return core, core, E, False
    root = _root(V, args, E, below[hit], below[hit - 1])
    return root, core, float(_values(V, root, args)), True


def _first_barred(V, args, E: float, grid: np.ndarray):
    """The index of the first point of `grid` where E − V_eff is not positive (None if
    none; False if a sign up to there is within rounding of zero, or the value there is not
    finite: undecided)."""
    vals = _values(V, grid, args)
    k = E - vals
    bad = ~(np.isfinite(k) & (k > 0))
    i = int(np.argmax(bad)) if bad.any() else grid.size - 1
    if not (math.isfinite(k[i]) and np.all(np.abs(k[:i + 1]) > MARGIN * (abs(E) +
                                                                          np.abs(vals[:i + 1])))):
        return False
    return i if bad.any() else None


def _root(V, args, E: float, lo: float, hi: float) -> float:
    """The root of E − V_eff in [lo, hi] (not allowed at lo, allowed at hi) to rounding."""
    def k(r):
        return E - float(_values(V, r, args))
    return brentq(k, lo, hi, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=200)


def _integral(fns, args, E: float, rs: float, rmin: float, Es: float, at_root: bool):
    """(Θ, bound) from the two Gauss–Legendre rules on [w_lo, 1]."""
    m, V, dV, u = fns
    if at_root:
        slope = -float(_values(dV, rs, args))  # d(E − V_eff)/dr at r_s
        if not (math.isfinite(slope) and slope > 0):
            return None
        condition = abs(Es) / (rs * slope) if Es else 1.0
        if not condition < MAX_CONDITION:
            return None
    else:
        condition = 1.0
    w_lo = math.sqrt(1 - rs / rmin) if rmin != rs else 0.0
    values = []
    for n in (NODES, 2 * NODES):
        x, wt = _rule(n)
        w = w_lo + (1 - w_lo) * x
        one = (1 - w) * (1 + w)
        r = np.maximum(rs / one, rmin)
        k = Es - _values(V, r, args)
        if at_root:
            near = w < SWITCH
            if near.any():
                k[near] = _near_kinetic(dV, args, rs, rs * w[near] ** 2 / one[near])
        if not np.all(np.isfinite(k) & (k > 0)):
            return None
        f = _values(u, r, args) * np.sqrt(_values(m, r, args) / (2 * k)) * 2 * rs * w / one ** 2
        if not np.all(np.isfinite(f)):
            return None
        values.append(float(np.dot(wt, f)) * (1 - w_lo))
    theta = math.pi - 2 * values[1]
    # the rounding floor: the turning point's conditioning, and w's rounding near 1 against
    # the interval's length (a root far inside a core leaves [w_lo, 1] short)
    bound = ERROR_SAFETY * 2 * abs(values[1] - values[0]) + \
        ROUNDING * (1 + abs(theta)) * max(1.0, condition, 1 / (1 - w_lo))
    if not bound <= MAX_ERROR:
        return None
    return theta, bound


def _near_kinetic(dV, args, rs: float, span: np.ndarray) -> np.ndarray:
    """E′ − V_eff(r_s + span) = −∫ V_eff′ over [r_s, r_s + span]: the span (r_s·w²/(1 − w²),
    not a difference) times V_eff′'s mean there by six Gauss–Legendre nodes (the span is a
    small part of r_s here)."""
    x, wt = _rule(6)
    pts = rs + span[:, None] * x[None, :]
    return -span * (_values(dV, pts, args) @ wt)
