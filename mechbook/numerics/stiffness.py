"""Time scales of a run from the linearized equations, and whether the run is stiff.

`linear_rates` differentiates the compiled right-hand side y' = F(t, y), y = (q, q̇), by
central differences at the initial state (4n evaluations, no symbolic work) and takes the
eigenvalues λ of the 2n×2n Jacobian: for an oscillating system λ = ±iω for each mode, so
|λ| are the linear frequencies (growth rates for an unstable direction). The slowest
non-zero rate sets the period used to size runs and to scale the expected error of
`--accuracy`; the fastest sets the step an explicit method can take.

A run is **stiff** — an implicit method should take over — when the fastest rate is far
above the slowest (ratio ≥ STIFF_RATIO), the span holds many radians of the fastest mode
(ω_max·span ≥ STIFF_RADIANS), and the start hardly excites the fast modes (their relative
amplitude, `fast_excitation`, below the tolerance asked for). An explicit method (RK45,
DOP853) must then keep its step below its stability limit, ≈ 3/ω_max, for the whole span
although the solution is smooth; when the fast modes are excited above the tolerance every
method has to follow them and the explicit one is cheaper.

The thresholds come from the stiffness sweep of `bench/work_precision.py`: two pendulums
coupled by a spring (lim-2033) whose stiffness is raised to 10² … 10⁶ times gravity's,
over 3 slow periods, on the 2-core development machine (docs/performance.md). Started in
phase (the spring never stretches; reference: the pendulum's closed form), Radau at rtol
1e-6 took 19 ms and 822–884 evaluations at every ratio, error 4.7e-7; DOP853 took 27 ms at
the frequency ratio 45 (839 rad of the fast mode: about even, so STIFF_RADIANS = 1000), 90
ms at 141, 274 ms at 446 and 883 ms (84,000 evaluations, error 9e-6) at 1410. With the
fast mode excited (the same energy in the spring at every ratio), Radau cost 6 times
DOP853 (2.5 s against 0.40 s at the ratio 141), which the excitation test avoids. LSODA was
the cheapest in several runs but its error was 100–1000 times its tolerance, so a stiff run
switches to Radau.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mechbook.numerics.rhs import Model

STIFF_RATIO = 30.0  # ω_max / ω_min from which a run counts as stiff
STIFF_RADIANS = 1.0e3  # ... when ω_max · span is at least this (≈ 300 explicit steps)
IMPLICIT = "Radau"  # what a stiff run switches to when no method is forced
EXPLICIT = ("RK45", "DOP853", "RK4", "leapfrog", "yoshida4")
# stability limits of h·ω_max on an undamped oscillation (imaginary axis)
FIXED_LIMIT = {"RK4": 2.0 * math.sqrt(2.0), "leapfrog": 2.0, "yoshida4": 1.5}


@dataclass
class Rates:
    """Moduli of the eigenvalues of the linearized equations at one state."""

    eigenvalues: np.ndarray
    omega_max: float  # fastest rate (0 for a system with no restoring force at all)
    omega_min: float | None  # slowest non-zero rate (None: every rate is zero)

    @property
    def ratio(self) -> float:
        if not self.omega_min:
            return 1.0
        return self.omega_max / self.omega_min

    @property
    def period(self) -> float | None:
        """2π / slowest non-zero rate: the period of the slowest linear mode."""
        return 2 * math.pi / self.omega_min if self.omega_min else None


def jacobian(model: Model, t: float, y: np.ndarray) -> np.ndarray:
    """∂F/∂y of the compiled right-hand side, by central differences."""
    y = np.asarray(y, float)
    m = len(y)
    J = np.empty((m, m))
    with np.errstate(all="ignore"):
        for j in range(m):
            h = 1e-6 * max(1.0, abs(y[j]))
            up, down = y.copy(), y.copy()
            up[j] += h
            down[j] -= h
            J[:, j] = (model.rhs(t, up) - model.rhs(t, down)) / (2 * h)
    return J


def linear_rates(model: Model, t0: float, q0, qd0, zero: float = 1e-6) -> Rates | None:
    """The rates at (t0, q0, q̇0); rates below `zero`·ω_max count as zero (free motions,
    cyclic coordinates). None if the equations do not evaluate there."""
    try:
        J = jacobian(model, float(t0), np.concatenate((np.asarray(q0, float),
                                                       np.asarray(qd0, float))))
    except (np.linalg.LinAlgError, ValueError, ZeroDivisionError):
        return None
    return _rates(J, zero)


def _rates(J: np.ndarray, zero: float = 1e-6) -> Rates | None:
    if not np.all(np.isfinite(J)):
        return None
    lam = np.linalg.eigvals(J)
    mags = np.abs(lam)
    top = float(mags.max()) if len(mags) else 0.0
    if top <= 0:
        return Rates(lam, 0.0, None)
    nonzero = mags[mags > zero * top]
    return Rates(lam, top, float(nonzero.min()) if len(nonzero) else None)


@dataclass
class Stiffness:
    rates: Rates | None
    span: float
    stiff: bool  # switch to an implicit method (when the user forced none)
    reason: str
    excitation: float = math.nan  # relative amplitude of the fast modes (`fast_excitation`)

    @property
    def radians(self) -> float:
        return self.rates.omega_max * self.span if self.rates else 0.0

    @property
    def wide(self) -> bool:
        """Time scales far apart over a long span (stiff whether or not excited)."""
        return bool(self.rates) and self.rates.ratio >= STIFF_RATIO \
            and self.radians >= STIFF_RADIANS


def fast_excitation(model: Model, t0: float, y0: np.ndarray, J: np.ndarray,
                    rates: Rates) -> float:
    """How strongly the start excites the fast modes (|λ| ≥ STIFF_RATIO·ω_min), relative to
    the size of the motion.

    Near the start ẏ ≈ F0 + J (y − y0); in the eigenvectors v_k of J the constant F0 =
    Σ c_k v_k drives mode k to oscillate with amplitude |c_k|/|λ_k| (a stretched stiff
    spring: its stretch; one at rest: its quasi-static deflection, ≈ force/stiffness).
    Returns max over fast modes of |c_k| ‖v_k‖∞ / |λ_k|, divided by the scale of the
    motion max(‖y0‖∞, ‖F0‖∞/ω_min)."""
    F0 = model.rhs(t0, y0)
    lam, V = np.linalg.eig(J)
    try:
        c = np.linalg.solve(V, F0)
    except np.linalg.LinAlgError:
        return np.inf
    fast = np.abs(lam) >= STIFF_RATIO * (rates.omega_min or rates.omega_max)
    if not np.any(fast):
        return 0.0
    amp = np.abs(c[fast]) * np.max(np.abs(V[:, fast]), axis=0) / np.abs(lam[fast])
    scale = max(float(np.max(np.abs(y0))), float(np.max(np.abs(F0))) / rates.omega_min, 1e-300)
    return float(np.max(amp)) / scale


def assess(model: Model, t_span: tuple[float, float], q0, qd0,
           rtol: float = 1e-8) -> Stiffness:
    """Is a run over `t_span` from (q0, q̇0) stiff, so that an implicit method should take
    over? Yes when the rates are far apart over a long span (`Stiffness.wide`) and the fast
    modes are excited below `rtol` (the accuracy asked for), so that they need not be
    resolved; when they are excited more, every method must follow them and an explicit
    one is as good (see the module docstring)."""
    span = float(t_span[1]) - float(t_span[0])
    t0 = float(t_span[0])
    y0 = np.concatenate((np.asarray(q0, float), np.asarray(qd0, float)))
    try:
        J = jacobian(model, t0, y0)
    except (np.linalg.LinAlgError, ValueError, ZeroDivisionError):
        J = np.full((len(y0), len(y0)), np.nan)  # e.g. a singular mass matrix at the start
    rates = _rates(J)
    if rates is None:
        return Stiffness(None, span, False, "the linearized equations do not evaluate at "
                                            "the start")
    radians = rates.omega_max * span
    reason = (f"linear rates from {rates.omega_min or 0:.3g} to {rates.omega_max:.3g} /time "
              f"(ratio {rates.ratio:.3g}); the fastest turns through {radians:.3g} rad over "
              f"the span")
    out = Stiffness(rates, span, False, reason)
    if out.wide:
        with np.errstate(all="ignore"):
            out.excitation = fast_excitation(model, t0, y0, J, rates)
        out.stiff = out.excitation <= rtol
        out.reason += (f"; the fast modes are excited to {out.excitation:.1e} of the motion "
                       + ("(below the tolerance: need not be resolved)" if out.stiff else
                          f"(above the tolerance {rtol:.0e}: they must be resolved, an "
                          "explicit method is as good)"))
    return out


def fixed_step_warning(method: str, step: float | None, span: float,
                       stiffness: Stiffness) -> str:
    """A warning when a fixed step exceeds the method's stability limit on the fastest
    linear mode (the run would blow up or be meaningless), else ''."""
    limit = FIXED_LIMIT.get(method)
    if limit is None or stiffness.rates is None or not stiffness.rates.omega_max:
        return ""
    h = step or span / 10_000
    if h * stiffness.rates.omega_max <= limit:
        return ""
    return (f"warning: step {h:.3g} is above {method}'s stability limit {limit:.3g}/ω_max = "
            f"{limit / stiffness.rates.omega_max:.3g} for the fastest linear mode "
            f"(ω_max = {stiffness.rates.omega_max:.3g}); use a smaller --step or an "
            f"implicit method (Radau, LSODA)")


__all__ = ["FIXED_LIMIT", "IMPLICIT", "STIFF_RADIANS", "STIFF_RATIO", "Rates", "Stiffness",
           "assess", "fixed_step_warning", "jacobian", "linear_rates"]
