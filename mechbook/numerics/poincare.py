"""Poincaré return maps, their fixed points and period-n orbits, and their multipliers.

Two kinds of section:

- **stroboscopic** (a driven system): the state sampled every drive period T from the phase
  t0, P(x) = φ(t0 + T; t0, x); its derivative is the monodromy Φ of the tangent flow.
- **a surface** q_i = c (or q̇_i = c) crossed in a given direction (an autonomous system):
  P(x) is the state at the next crossing; its derivative is Φ(τ) projected along the flow,
  (1 − f·e_iᵀ/f_i)·Φ(τ) (τ the return time, f the flow there), restricted to the section.

A period-n orbit is a fixed point of Pⁿ, found by Newton's method from a guess (least
squares: on a surface the unknowns are the whole state, with the section's equation, and
an energy level where the part gives one, as rows of their own). Coordinates that are
angles of the equations (mechbook.numerics.tangent.angle_coordinates) are compared modulo
2π. The multipliers are the eigenvalues of DPⁿ, on a surface without the trivial one of a
conserved energy. `finite_difference` is the second computation of DPⁿ: central differences
of the map itself, which shares nothing with the tangent flow but the equations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp  # the crossings are its events

from mechbook.errors import UnsupportedError
from mechbook.numerics.tangent import RTOL, TangentFlow, angle_coordinates

NEWTON_STEPS = 40
NEWTON_TOL = 1e-10  # |Pⁿ(x) − x| at convergence, relative to 1 + |x|
STEPS_PER_PERIOD = 200
FD_STEP = 1e-5  # central differences of the map: error ~ h² + 1e-12/h, ~1e-7 relative


class NoCrossing(UnsupportedError):
    """The orbit does not reach the section within the time allowed."""


@dataclass(frozen=True)
class Section:
    """Where the map samples the motion: every `period` from `phase` (stroboscopic), or where
    state component `index` (0..2n−1: coordinates, then velocities) crosses `value` going
    the way of `direction` (+1 up, −1 down), within `within` time units; no step longer
    than `max_step` (a stroboscopic section's default: STEPS_PER_PERIOD steps a period at
    least, so a drive's pulse down to that width is never stepped over)."""

    period: float | None = None
    phase: float = 0.0
    index: int | None = None
    value: float = 0.0
    direction: int = 1
    within: float = 1000.0
    max_step: float | None = None

    @property
    def step(self) -> float:
        if self.max_step is not None:
            return self.max_step
        return self.period / STEPS_PER_PERIOD if self.period is not None else math.inf


@dataclass
class Orbit:
    """A period-n orbit of the map: its points, DPⁿ at the first, the multipliers."""

    points: list  # n states (arrays of 2n)
    jacobian: np.ndarray  # DPⁿ at points[0] (on a surface: the section's reduced one)
    multipliers: np.ndarray
    residual: float  # |Pⁿ(x) − x| at the end of Newton's iteration
    steps: int

    @property
    def spectral_radius(self) -> float:
        return float(np.max(np.abs(self.multipliers)))


class ReturnMap:
    """The return map of one section at fixed parameter values, with its derivative."""

    def __init__(self, system, dyn, values: dict, section: Section,
                 conserved: bool | None = None, free=None):
        """`conserved`: whether the energy function is conserved (decided by the engine
        when not given; a caller building many maps of one system decides it once);
        `free`: a parameter whose value (`move`) may change without compiling again."""
        self.flow = TangentFlow(system, dyn, values, 2 * len(dyn.q), free)
        self.n = len(dyn.q)
        self.section = section
        self.angles = angle_coordinates(self.flow.model, self.n,
                                        self.flow.padding()) + [False] * self.n
        self.energy = None
        self.conserved = bool(dyn.energy_conserved) if conserved is None else conserved
        self.evaluations = 0

    def move(self, value: float, section: Section) -> None:
        """The free parameter at `value`, with the section that goes with it there."""
        self.flow.value, self.section = float(value), section

    # ---- the map ---------------------------------------------------------------------
    def __call__(self, x: np.ndarray, times: int = 1, tangent: bool = True):
        """(Pⁿ(x), DPⁿ(x) as a full 2n × 2n matrix, or None without `tangent`)."""
        y, V = np.array(x, float), np.eye(2 * self.n)
        t = self.section.phase
        for _ in range(times):
            y, W, t = self._once(t, y)
            V = W @ V
        return y, (V if tangent else None)

    def _once(self, t: float, y: np.ndarray):
        s = self.section
        if s.period is not None:
            y1, W = self.flow.flow(t, t + s.period, y, np.eye(2 * self.n), max_step=s.step)
            self.evaluations = self.flow.evaluations
            return y1, W, t + s.period
        t1, y1, W = self._crossing(t, y)
        f = self.flow.rate(t1, y1)
        if abs(f[s.index]) < 1e-300:
            raise UnsupportedError("the orbit touches the section tangentially")
        e = np.zeros(2 * self.n)
        e[s.index] = 1.0
        W = (np.eye(2 * self.n) - np.outer(f, e) / f[s.index]) @ W
        return y1, W, t1

    def _crossing(self, t0: float, y: np.ndarray):
        """The next crossing of the surface after t0: integrate the tangent flow to it in
        chunks (an event of solve_ivp on the augmented model)."""
        s, n = self.section, self.n
        model = self.flow.model
        N = model.n
        z = np.concatenate(self.flow.pack(y, np.eye(2 * n)))
        pos = s.index if s.index < n else N + (s.index - n)

        def event(t, z):
            return z[pos] - s.value

        event.direction = s.direction
        t, chunk = t0, 1.0
        while t < t0 + s.within:
            end = min(t + chunk, t0 + s.within)
            sol = solve_ivp(model.rhs, (t, end), z, method="DOP853", rtol=RTOL, atol=RTOL,
                            events=[event], max_step=s.step)
            self.flow.evaluations += sol.nfev
            self.evaluations = self.flow.evaluations
            if sol.status < 0:
                raise UnsupportedError(f"the return map's integration failed: {sol.message}")
            hits = [(te, ze) for te, ze in zip(sol.t_events[0], sol.y_events[0], strict=True)
                    if te > t0 + 1e-9 * max(1.0, abs(t0))]
            if hits:
                te, ze = hits[0]
                return (float(te), *self.flow.unpack(ze[:N], ze[N:]))
            t, z = sol.t[-1], sol.y[:, -1]
            chunk *= 2
        raise NoCrossing(f"the orbit does not cross the section within t = {s.within:g}")

    # ---- fixed points ------------------------------------------------------------------
    def difference(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """a − b, angles wrapped into (−π, π]."""
        d = np.asarray(a, float) - np.asarray(b, float)
        for i, angle in enumerate(self.angles):
            if angle:
                d[i] = (d[i] + math.pi) % (2 * math.pi) - math.pi
        return d

    def set_energy(self, fn, level: float) -> None:
        """Hold the energy at `level` on a surface section: fn(y) -> (h, ∇h)."""
        self.energy = (fn, level)

    def orbit(self, guess: np.ndarray, times: int = 1) -> Orbit:
        """The period-`times` orbit Newton's method reaches from `guess`."""
        x = np.array(guess, float)
        s = self.section
        for step in range(1, NEWTON_STEPS + 1):
            y, D = self(x, times)
            F = self.difference(y, x)
            rows, J = [F], [D - np.eye(2 * self.n)]
            if s.period is None:
                e = np.zeros(2 * self.n)
                e[s.index] = 1.0
                rows.append([x[s.index] - s.value])
                J.append(e[None, :])
                if self.energy is not None:
                    h, grad = self.energy[0](x)
                    rows.append([h - self.energy[1]])
                    J.append(np.asarray(grad, float)[None, :])
            res = np.concatenate([np.ravel(r) for r in rows])
            size = float(np.max(np.abs(res)))
            if not np.all(np.isfinite(res)):
                raise UnsupportedError("Newton's method on the return map left the "
                                       "region where the motion is defined")
            if size <= NEWTON_TOL * (1 + float(np.max(np.abs(x)))):
                return self._orbit(x, times, size, step)
            dx = np.linalg.lstsq(np.vstack(J), -res, rcond=None)[0]
            x = x + dx
        raise UnsupportedError(f"Newton's method on the return map did not converge from "
                               f"the guess in {NEWTON_STEPS} steps (residual {size:.2g})")

    def _orbit(self, x: np.ndarray, times: int, residual: float, steps: int) -> Orbit:
        points, y = [x], x
        for _ in range(times - 1):
            y, _ = self(y, 1, tangent=False)
            points.append(y)
        _, D = self(x, times)
        J = self.reduced(D)
        return Orbit(points, J, self.multipliers(J), residual, steps)

    def reduced(self, D: np.ndarray) -> np.ndarray:
        """DPⁿ on the section: a surface's component `index` dropped (it stays put)."""
        if self.section.period is not None:
            return D
        keep = [i for i in range(2 * self.n) if i != self.section.index]
        return D[np.ix_(keep, keep)]

    def multipliers(self, J: np.ndarray) -> np.ndarray:
        """The eigenvalues of the map's derivative; on a surface of a system whose energy is
        conserved, without the one at 1 that moves along the energy (and without the flow's
        own direction, which the projection has already sent to 0 and `reduced` removed)."""
        mu = np.linalg.eigvals(J)
        if self.section.period is None and self.conserved and len(mu) > 1:
            mu = np.delete(mu, int(np.argmin(np.abs(mu - 1))))
        return mu

    def finite_difference(self, x: np.ndarray, times: int = 1) -> np.ndarray:
        """DPⁿ(x) by central differences of the map (the cross-check of the monodromy)."""
        k = 2 * self.n
        D = np.empty((k, k))
        for j in range(k):
            h = FD_STEP * max(1.0, abs(x[j]))
            up, down = np.array(x, float), np.array(x, float)
            up[j] += h
            down[j] -= h
            if self.section.period is None and j == self.section.index:
                D[:, j] = 0.0  # off the section: the reduced map never reads this column
                continue
            D[:, j] = self.difference(self(up, times, tangent=False)[0],
                                      self(down, times, tangent=False)[0]) / (2 * h)
        return self.reduced(D)


def stability(multipliers: np.ndarray, resolution: float) -> str | None:
    """'stable' where every multiplier lies on or inside the unit circle, 'unstable' where
    one lies outside, each by more than `resolution` from the circle's edge of the other
    verdict; None (undecided) where the largest |μ| is within the resolution of 1 from
    outside, i.e. cannot be told from a multiplier on the circle."""
    top = float(np.max(np.abs(multipliers)))
    if top <= 1 + resolution:
        return "stable"
    if top > 1 + 100 * resolution:
        return "unstable"
    return None


__all__ = ["NEWTON_TOL", "NoCrossing", "Orbit", "ReturnMap", "Section", "stability"]
