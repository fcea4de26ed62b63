"""Cross-check: a first-order linearization's oscillations measured from the nonlinear motion.

A system with velocity constraints (a rolling coin) is linearized in its independent
coordinates and speeds, z = (δs, δu) (mechbook.engine.state_space); its frequencies are the
oscillating exponents ±iω of the state matrix. Here the *nonlinear* equations, constraints
and all, are integrated (DOP853, rtol 1e-12) from the reference motion displaced a little
along each oscillating mode — the state's right eigenvector, mapped to every coordinate and
rate (δq = N·δs, δq̇ = N·(T·δu + R·δs)) and put exactly on the constraint manifold — and the
frequency is read off the upward zero crossings of the mode's own amplitude, the left
eigenvector's projection of the state's deviation from the reference motion. As for
second-order systems (mechbook.crosscheck.frequencies) it must agree with the engine's ω to
REL_TOL, at an amplitude halved until two runs agree within SHIFT_TOL. Zero exponents (the
family of steady motions) are not measured; a growing mode makes the point not applicable.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
import sympy as sp

from mechbook.crosscheck.frequencies import (
    PERIODS,
    REL_TOL,
    SHIFT_TOL,
    START_AMPLITUDE,
    crossing_frequency,
)
from mechbook.engine.analysis import Analysis
from mechbook.engine.state_space import StateSpaceSystem
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.model.manifold import manifold_of
from mechbook.numerics.rhs import build_model
from mechbook.records import CrossCheck, Status


class _Setup:
    """The nonlinear model, the reference motion and the maps between z and (q, q̇)."""

    def __init__(self, analysis: Analysis, lin: StateSpaceSystem, values: dict,
                 models: dict):
        base = lin.dyn.sys
        self.base = base
        vals = {k: float(v) for k, v in values.items()}
        for s in base.small_params:
            vals[s] = 0.0
        params = {k: v for k, v in vals.items() if k in set(base.problem.values())}
        key = (base.problem.id, base.name, tuple(sorted((str(k), v) for k, v in
                                                        params.items())))
        if key not in models:
            models[key] = build_model(base, analysis.dynamics(base.name), params)
        self.model = models[key]
        self.params = params
        self.manifold = manifold_of(base)

        def num(x) -> float:
            return float(sp.N(sp.S(x).subs(values)))

        self.q_star = np.array([num(lin.point.get(q, 0)) for q in base.q])
        self.turn = np.array([num(lin.velocity.get(q, 0)) for q in base.q])
        T, R = lin.speed_map
        self.N = np.array(lin.embedding.subs(values).evalf(), dtype=float)
        self.T = np.array(T.subs(values).evalf(), dtype=float)
        self.R = np.array(R.subs(values).evalf(), dtype=float)
        self.coords = [base.q.index(c) for c in lin.coords]
        self.speeds = [base.qd.index(v) for v in lin.speeds]
        self.A = lin.numeric_state_matrix(values)

    def full_state(self, z: np.ndarray) -> np.ndarray:
        """The model's state (q, q̇) at t = 0 displaced by z, on the constraint manifold."""
        k = len(self.coords)
        ds, du = z[:k], z[k:]
        q = self.q_star + self.N @ ds
        qd = self.turn + self.N @ (self.T @ du + self.R @ ds)
        settled = self.manifold.settle(self.params, q, qd) if self.manifold else (q, qd)
        if settled is None:
            raise MechbookError("the displaced start could not be put on the constraint "
                                "manifold")
        return np.concatenate(settled)

    def deviation(self, t: float, y: np.ndarray) -> np.ndarray:
        """z(t): the independent coordinates' and speeds' deviation from the reference."""
        n = len(self.q_star)
        dq = y[:n] - self.q_star - self.turn * t
        dv = y[n:] - self.turn
        return np.concatenate((dq[self.coords], dv[self.speeds]))


def state_frequency_crosscheck(analysis: Analysis, lin: StateSpaceSystem, values: dict,
                               out: CrossCheck, models: dict) -> None:
    """Measure each oscillating mode of `lin` (fills `out`)."""
    s = _Setup(analysis, lin, values, models)
    lam, W, V = scipy.linalg.eig(s.A, left=True, right=True)
    scale = max(1e-300, float(np.max(np.abs(lam))))
    if np.any(lam.real > 1e-8 * scale):
        raise UnsupportedError("a growing mode: the motion leaves the steady motion (its "
                               "oscillations are not measured)")
    modes = [j for j in range(len(lam)) if lam[j].imag > 1e-9 * scale]
    if not modes:
        raise UnsupportedError("no oscillating mode to measure (every exponent is zero)")
    worst = 0.0
    texts = []
    failed = False
    for j in modes:
        omega = float(lam[j].imag)
        measured, shift, amplitude = _measure_mode(s, V[:, j], W[:, j], omega)
        rel = abs(measured - omega) / omega
        worst = max(worst, rel)
        ok = rel < REL_TOL and shift < SHIFT_TOL
        failed |= not ok
        out.modes.append({"omega": omega, "measured": measured, "relative_error": rel,
                          "amplitude": amplitude, "kind": "",
                          "status": Status.PASS if ok else Status.FAIL})
        texts.append(f"ω {omega:.6g}: measured {measured:.10g} (rel {rel:.1e}, amplitude "
                     f"{amplitude:.0e}, shift {shift:.0e})")
    zeros = len(lam) - 2 * len(modes)
    texts.append(f"{zeros} zero exponents (the steady family, ignorable states) not measured")
    out.error = worst
    out.status = Status.FAIL if failed else Status.PASS
    out.detail = "first-order linearization, the nonlinear motion on the constraint " \
                 "manifold: " + "; ".join(texts)


def _measure_mode(s: _Setup, v: np.ndarray, w: np.ndarray, omega: float
                  ) -> tuple[float, float, float]:
    """(frequency at the final amplitude, shift between the last two, that amplitude)."""
    big = int(np.argmax(np.abs(v)))
    v = v * np.exp(-1j * np.angle(v[big]))
    w = w / np.conj(np.vdot(w, v))
    start = v.real / max(1e-300, float(np.max(np.abs(v.real))))
    period = 2 * np.pi / omega
    amplitude = START_AMPLITUDE
    previous = None
    for _ in range(6):
        measured = _run(s, start, np.conj(w), amplitude, period)
        if previous is not None:
            shift = abs(previous - measured) / omega / 3  # the a² shift left at a/2
            if shift < SHIFT_TOL / 10:
                return measured, shift, amplitude
        previous = measured
        amplitude /= 4
    return measured, abs(previous - measured) / omega, amplitude


def _run(s: _Setup, start: np.ndarray, weights: np.ndarray, amplitude: float,
         period: float) -> float:
    y0 = s.full_state(amplitude * start)

    def signal(t, y):
        return float(np.real(np.dot(weights, s.deviation(t, y))))

    measured, crossings = crossing_frequency(s.model, signal, y0, amplitude, period)
    if measured != measured:
        raise MechbookError(f"only {crossings} zero crossings in {PERIODS + 1} periods")
    return measured
