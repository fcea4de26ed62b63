"""The fixed-step methods: classical RK4 (explicit, not symplectic: the baseline), Störmer–
Verlet leapfrog and Yoshida's 4th-order composition of it (symplectic; separable H), the
implicit midpoint rule on canonical (q, p) (symplectic for any H). Each runs in the compiled
loops (loops.c) when it can, and in Python otherwise, computing the same numbers."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import ClassVar

import numpy as np

from mechbook.numerics import c_stepping as loops
from mechbook.numerics.integrator_base import Integrator, IntegratorError, Trajectory
from mechbook.numerics.rhs import Model

MAX_STEPS = 10**10  # steps of one fixed-step run: far more than any run's time limit allows


class FixedStep(Integrator):
    """Common driver of the fixed-step methods: `step` (h), `max_points` recorded."""

    def _grid(self, t_span) -> tuple[int, float]:
        t0, t1 = map(float, t_span)
        h = self.options.get("step") or (t1 - t0) / 10_000
        if not t1 > t0:
            raise IntegratorError("a fixed-step method needs t1 > t0")
        if not h > 0:
            raise IntegratorError(f"the span {t1 - t0:g} is too short to divide into steps "
                                  "(its ten-thousandth is 0 in double precision)"
                                  if not self.options.get("step") else
                                  "a fixed-step method needs a step > 0")
        count = (t1 - t0) / h
        if not count <= MAX_STEPS:  # also inf and NaN: a step 1e-300 made a C long overflow
            raise IntegratorError(f"a step of {h:g} over a span of {t1 - t0:g} is {count:.3g} "
                                  f"steps (at most {MAX_STEPS:.0e}): take a larger step or a "
                                  "shorter span")
        steps = max(1, math.ceil(count - 1e-9))
        return steps, (t1 - t0) / steps

    def _wanted(self, t_span, t_eval, steps: int, h: float) -> np.ndarray:
        """The step indices recorded: nearest to t_eval, or every stride-th step."""
        t0 = float(t_span[0])
        max_points = int(self.options.get("max_points") or 200_001)
        if t_eval is not None:
            wanted = np.round((np.asarray(t_eval, float) - t0) / h).astype(int)
            return np.unique(np.clip(wanted, 0, steps))
        stride = max(1, math.ceil(steps / (max_points - 1)))
        return np.unique(np.append(np.arange(0, steps + 1, stride), steps))

    def _native(self, model: Model, canonical: bool = False):
        """The compiled loops' model, or None (option compiled=False, or unavailable)."""
        if self.options.get("compiled") is False:
            return None
        return model.native_canonical if canonical else model.native

    def _run_native(self, nat, model, t_span, start, t_eval, **kw) -> Trajectory:
        """The same run as `_run`, as one call into loops.c (`c_stepping.fixed`)."""

        steps, h = self._grid(t_span)
        t0 = float(t_span[0])
        want = self._wanted(t_span, t_eval, steps, h)
        method = "leapfrog" if isinstance(self, Leapfrog) else self.name
        t, rows, kind, k, evals = loops.fixed(nat, model.stats, method, t0, h, steps, start,
                                              want, **kw)
        model.stats["rhs_calls"] += evals
        n = model.n
        settings = {**self.settings(h, steps), "compiled": True}
        if kind == "newton":
            raise IntegratorError(f"implicit midpoint: Newton iteration did not converge at "
                                  f"t = {t0 + k * h:.6g} (try a smaller step)")
        if kind:
            why = (f"non-finite state at t = {t0 + k * h + h:.6g}" if kind == "non-finite"
                   else "evaluation budget spent")
            return Trajectory(t, rows[:, :n].T, rows[:, n:].T, self.name, settings, evals,
                              False, why)
        return Trajectory(t, rows[:, :n].T, rows[:, n:].T, self.name, settings, evals, True,
                          "fixed steps completed")

    def _run(self, model, t_span, state0, advance, to_output, t_eval,
             flat: Callable = np.asarray) -> Trajectory:
        """Advance `state0` by `advance(t, state, h)`; record `to_output(t, state)`;
        stop when `flat(state)` is not finite."""
        steps, h = self._grid(t_span)
        t0 = float(t_span[0])
        want = set(self._wanted(t_span, t_eval, steps, h).tolist())
        ts, qs, vs = [], [], []
        state = state0
        calls0 = model.stats["rhs_calls"]
        for k in range(steps + 1):
            t = t0 + k * h
            if k in want:
                q, v = to_output(t, state)
                ts.append(t)
                qs.append(q)
                vs.append(v)
            if k < steps:
                state = advance(t, state, h)
                if not np.all(np.isfinite(flat(state))):
                    return Trajectory(np.array(ts), np.array(qs).T, np.array(vs).T, self.name,
                                      self.settings(h, steps), model.stats["rhs_calls"] - calls0,
                                      False, f"non-finite state at t = {t + h:.6g}")
        return Trajectory(np.array(ts), np.array(qs).T, np.array(vs).T, self.name,
                          self.settings(h, steps), model.stats["rhs_calls"] - calls0, True,
                          "fixed steps completed")

    def settings(self, h: float, steps: int) -> dict:
        return {"method": self.name, "step": h, "steps": steps}


class RK4(FixedStep):
    """Classical 4th-order Runge–Kutta on y = (q, q̇): explicit, not symplectic."""

    def solve(self, model, t_span, q0, qd0, t_eval=None, events=None) -> Trajectory:
        n = model.n
        nat = self._native(model)
        if nat is not None:
            start = np.concatenate((q0, qd0)).astype(float)
            return self._run_native(nat, model, t_span, start, t_eval)
        f = model.rhs_python

        def advance(t, y, h):
            k1 = f(t, y)
            k2 = f(t + h / 2, y + h / 2 * k1)
            k3 = f(t + h / 2, y + h / 2 * k2)
            k4 = f(t + h, y + h * k3)
            return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)

        y0 = np.concatenate((q0, qd0)).astype(float)
        return self._run(model, t_span, y0, advance, lambda t, y: (y[:n], y[n:]), t_eval)


class Leapfrog(FixedStep):
    """Störmer–Verlet (velocity Verlet, kick-drift-kick) for H = p·M⁻¹p/2 + V(q).

    In velocities v = M⁻¹p with constant M this is exactly the symplectic map on (q, p)."""

    symplectic = True
    requires = "separable"
    weights: ClassVar[tuple[float, ...]] = (1.0,)

    def solve(self, model, t_span, q0, qd0, t_eval=None, events=None) -> Trajectory:
        n = model.n
        zero = np.zeros(n)
        weights = self.weights

        nat = self._native(model)
        if nat is not None:
            start = np.concatenate((q0, qd0)).astype(float)
            return self._run_native(nat, model, t_span, start, t_eval, weights=weights)

        def acc(t, q):
            return model.accelerations_python(t, q, zero)

        def advance(t, state, h):
            q, v, a = state
            for w in weights:
                hw = w * h
                v = v + hw / 2 * a
                q = q + hw * v
                a = acc(t, q)
                v = v + hw / 2 * a
            return (q, v, a)

        q = np.asarray(q0, float)
        state0 = (q, np.asarray(qd0, float), acc(t_span[0], q))
        return self._run(model, t_span, state0, advance, lambda t, s: (s[0], s[1]), t_eval,
                         flat=lambda s: np.concatenate(s[:2]))

    def settings(self, h: float, steps: int) -> dict:
        return {**super().settings(h, steps), "order": 2 if len(self.weights) == 1 else 4}


class Yoshida4(Leapfrog):
    """Yoshida's 4th-order composition (the Forest–Ruth integrator): leapfrog steps of
    w₁h, w₀h, w₁h with w₁ = 1/(2 − 2^{1/3}), w₀ = 1 − 2w₁."""

    _w1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
    weights = (_w1, 1.0 - 2.0 * _w1, _w1)


class ImplicitMidpoint(FixedStep):
    """Implicit midpoint rule on canonical z = (q, p): z₁ = z₀ + h F(t + h/2, (z₀ + z₁)/2).

    Symplectic for any Hamiltonian (also non-separable and gyroscopic ones) and exact for
    quadratic invariants. The implicit equation is solved by simplified Newton iteration
    to `tol` (default 1e-14), with a finite-difference Jacobian refreshed every 50 steps or
    when the iteration slows (the converged solution does not depend on it)."""

    symplectic = True
    requires = "canonical"

    def solve(self, model, t_span, q0, qd0, t_eval=None, events=None) -> Trajectory:
        n = model.n
        tol = float(self.options.get("tol") or 1e-14)
        max_iter = int(self.options.get("max_iter") or 50)

        def F(t, z):
            return model.hamilton(t, z[:n], z[n:])

        def jacobian(t, z, f0):
            J = np.empty((2 * n, 2 * n))
            for j in range(2 * n):
                dz = 1e-7 * max(1.0, abs(z[j]))
                z2 = z.copy()
                z2[j] += dz
                J[:, j] = (F(t, z2) - f0) / dz
            return J

        nat = self._native(model, canonical=True)
        if nat is not None:
            t0 = float(t_span[0])
            q0 = np.asarray(q0, float)
            z0 = np.concatenate((q0, model.momenta(t0, q0, np.asarray(qd0, float))))
            return self._run_native(nat, model, t_span, z0, t_eval, tol=tol,
                                    max_iter=max_iter)
        cache: dict = {"lu": None, "age": 0}

        def advance(t, z, h):
            tm = t + h / 2
            f0 = F(tm, z)
            for fresh in (False, True):
                if fresh or cache["lu"] is None or cache["age"] >= 50:
                    cache["lu"] = np.eye(2 * n) - h / 2 * jacobian(tm, z, f0)
                    cache["age"] = 0
                cache["age"] += 1
                z1 = z + h * f0
                for it in range(max_iter):
                    g = z1 - z - h * F(tm, (z + z1) / 2)
                    dz = np.linalg.solve(cache["lu"], -g)
                    z1 = z1 + dz
                    if np.max(np.abs(dz)) <= tol * max(1.0, float(np.max(np.abs(z1)))):
                        if it > 6:  # slow: refresh the Jacobian next step
                            cache["age"] = 50
                        return z1
            raise IntegratorError(f"implicit midpoint: Newton iteration did not converge at "
                                  f"t = {t:.6g} (try a smaller step)")

        t0 = float(t_span[0])
        q0 = np.asarray(q0, float)
        z0 = np.concatenate((q0, model.momenta(t0, q0, np.asarray(qd0, float))))
        return self._run(model, t_span, z0, advance,
                         lambda t, z: (z[:n], model.velocities(t, z[:n], z[n:])), t_eval)

