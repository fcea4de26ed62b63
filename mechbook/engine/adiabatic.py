"""Adiabatic invariants: the action of an oscillation held while a parameter changes slowly.

A book's "the amplitude varies as r^(-3/4) when the string is shortened slowly" is the
statement that the action J = ∮ p dq of the oscillation is kept while the slow variable
changes over many periods. The slow variable is a driven coordinate left free in the
problem (`driven: {r: {free: true}}`), so the Lagrangian holds r and ṙ exactly as the
scene makes them (a string drawn through a hole: the ṙ terms are real forces).

    frozen    the oscillation at fixed r (ṙ = r̈ = 0) about its equilibrium, linearized:
              M(r)·q̈ + K(r)·q = 0, one coordinate; its action at amplitude A is
              J = π·√(M·K)·A² (energy K·A²/2 over frequency √(K/M), times 2π)
    simulate  the full nonlinear equations with r(t) moved from r0 to r1 along a smooth
              step over N periods (r(t) = r0 + (r1 − r0)·S(t/T), S(u) = u − sin(2πu)/2π,
              whose first and second derivatives vanish at both ends), started at rest at
              amplitude A0; the amplitude A1 after the change is half the distance between
              the turning values measured over the next periods (DOP853, rtol 1e-11)

A law f(A, r) = constant is an adiabatic invariant in the small-oscillation limit exactly
when f is a function of J: ∂(f, J)/∂(A, r) = 0 (checked at 30 digits), and the simulation
shows the slow change keeping f (and J) to its stated accuracy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from mechbook.core.compile import compile_exprs
from mechbook.core.numeval import is_zero
from mechbook.engine.lagrange import Dynamics
from mechbook.errors import UnsupportedError

PERIODS = 200  # the slow change lasts this many periods of the initial oscillation
TOLERANCE = 1e-11


@dataclass
class Frozen:
    """The oscillation at a fixed value of the slow variable."""

    coordinate: sp.Symbol
    slow: sp.Symbol  # the free driven coordinate
    M: sp.Expr
    K: sp.Expr

    def action(self, amplitude: sp.Expr) -> sp.Expr:
        return sp.pi * sp.sqrt(self.M * self.K) * amplitude**2


def frozen(dyn: Dynamics, coordinate: sp.Symbol, slow: sp.Symbol, point: dict) -> Frozen:
    """The linearized oscillation of `coordinate` about `point` with `slow` held fixed."""
    sys = dyn.sys
    trio = next((t for t in sys.free_driven if t[0] == slow), None)
    if trio is None:
        raise UnsupportedError(f"{slow} is not a free driven coordinate (`driven: {{{slow}: "
                               "{free: true}}`)")
    if len(dyn.q) != 1:
        raise UnsupportedError("an adiabatic invariant of a system with more than one "
                               "coordinate (one oscillation at a time is supported)")
    if sys.constraints or sys.velocity_constraints:
        raise UnsupportedError("an adiabatic invariant with multiplier constraints")
    q, qd, qdd = dyn.q[0], dyn.qd[0], dyn.qdd[0]
    e = dyn.residuals[0].subs({trio[1]: 0, trio[2]: 0})
    at = {q: point.get(q, sp.S.Zero), qd: 0, qdd: 0}
    if not _vanishes(e.subs(at)):
        raise UnsupportedError(f"{q} = {point.get(q, 0)} is not an equilibrium of the frozen "
                               "oscillation")
    M, C, K = (sp.diff(e, v).subs(at) for v in (qdd, qd, q))
    if not _vanishes(C):
        raise UnsupportedError("the frozen oscillation is damped or driven (no action kept)")
    return Frozen(q, slow, M, K)


def _vanishes(e: sp.Expr) -> bool:
    return e == 0 or is_zero(e)


@dataclass
class SlowRun:
    """What a simulated slow change did."""

    a0: float  # amplitude at the start
    a1: float  # amplitude after the change
    r0: float
    r1: float
    periods: int
    nfev: int


def simulate(dyn: Dynamics, slow: sp.Symbol, values: dict, r0: float, r1: float,
             a0: float, point: float = 0.0, periods: int = PERIODS) -> SlowRun:
    """Integrate the full equations while `slow` moves from r0 to r1 (module docstring)."""
    sys = dyn.sys
    trio = next(t for t in sys.free_driven if t[0] == slow)
    q, qd = dyn.q[0], dyn.qd[0]
    sub = {k: sp.Float(float(v), 17) for k, v in values.items()}
    acc = dyn.accelerations[0].xreplace(sub)
    other = [s for t in sys.free_driven if t[0] != slow for s in t]
    if acc.free_symbols - {sys.t, q, qd, *trio} or other:
        raise UnsupportedError("simulating the slow change: symbols without a value: " +
                               ", ".join(sorted(map(str, acc.free_symbols - {sys.t, q, qd,
                                                                             *trio}))))
    fn, _ = compile_exprs([sys.t, q, qd, *trio], [acc])
    def period_at(r: float) -> float:
        at = {q: point, dyn.qd[0]: 0, dyn.qdd[0]: 0, trio[0]: r, trio[1]: 0, trio[2]: 0}
        m = float(sp.diff(dyn.residuals[0], dyn.qdd[0]).xreplace(sub).subs(at))
        k = float(sp.diff(dyn.residuals[0], q).xreplace(sub).subs(at))
        if not (m > 0 and k > 0):
            raise UnsupportedError("simulating the slow change: the frozen oscillation is "
                                   f"not stable at {slow} = {r:.6g}")
        return 2 * math.pi * math.sqrt(m / k)

    period0, period1 = period_at(r0), period_at(r1)
    T = periods * period0
    d = r1 - r0

    def schedule(t):
        u = min(max(t / T, 0.0), 1.0)
        w = 2 * math.pi
        if t >= T:
            return r1, 0.0, 0.0
        return (r0 + d * (u - math.sin(w * u) / w), d * (1 - math.cos(w * u)) / T,
                d * w * math.sin(w * u) / T**2)

    def rhs(t, y):
        r, rd, rdd = schedule(t)
        return [y[1], float(fn(np.array([t, y[0], y[1], r, rd, rdd]))[0])]

    y0 = [point + a0, 0.0]
    sol = solve_ivp(rhs, (0.0, T), y0, method="DOP853", rtol=TOLERANCE,
                    atol=TOLERANCE * max(abs(a0), 1e-300))
    if not sol.success:
        raise UnsupportedError(f"simulating the slow change: {sol.message}")

    def turn(t, y):
        return y[1]

    tail = solve_ivp(rhs, (T, T + 3.2 * period1),
                     sol.y[:, -1], method="DOP853", rtol=TOLERANCE,
                     atol=TOLERANCE * max(abs(a0), 1e-300), events=[turn])
    extremes = tail.y_events[0][:, 0] - point if len(tail.t_events[0]) else np.array([])
    if len(extremes) < 4:
        raise UnsupportedError("simulating the slow change: too few turning points after it")
    a1 = float((np.max(extremes) - np.min(extremes)) / 2)
    return SlowRun(a0, a1, r0, r1, periods, sol.nfev + tail.nfev)
