"""Integrators behind one interface, in the manner of `scipy.integrate.solve_ivp`.

`integrate(model, t_span, q0, qd0, method=..., **options)` returns a `Trajectory` of
(t, q, q̇) whatever the method. The methods:

    RK45, DOP853, Radau, LSODA   SciPy's solve_ivp (adaptive; rtol, atol, max_step)
    RK4                          classical fixed-step Runge–Kutta (explicit, not symplectic):
                                 the baseline against which symplectic methods are judged
    leapfrog (verlet)            Störmer–Verlet, kick-drift-kick: 2nd order, symplectic,
                                 time-reversible; needs a separable H = p·M⁻¹p/2 + V(q)
    yoshida4 (forest-ruth)       Yoshida's / Forest–Ruth's triple-jump composition of
                                 leapfrog: 4th order, symplectic; separable H only
    midpoint                     implicit midpoint rule on canonical (q, p), p = ∂L/∂q̇:
                                 2nd order, symplectic for any H(q, p) (non-separable,
                                 gyroscopic); solved by simplified Newton iteration

Fixed-step methods take `step` (default: the span over 10,000 steps). A symplectic method
keeps the energy error bounded (oscillating, no secular growth) over very long runs, which
an explicit Runge–Kutta method does not; they apply only to conservative systems, and the
separable ones only when the model is separable (`rhs.structure` decides). An option a
method does not take (`rtol` for a fixed-step method, `step` for an adaptive one) would have
no effect, so it is refused (IntegratorError, saying why), never dropped.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from scipy.integrate import solve_ivp

from mechbook.errors import MechbookError
from mechbook.numerics.methods import (  # noqa: F401 - the names, re-exported
    ALIASES,
    FIXED_METHODS,
    METHODS,
    OPTIONS,
    SCIPY_METHODS,
    TAYLOR,
    kind,
    why_not,
)
from mechbook.numerics.rhs import Model, structure

MAX_STEPS = 10**10  # steps of one fixed-step run: far more than any run's time limit allows


class IntegratorError(MechbookError):
    """The method does not apply to this system, or its iteration failed."""


@dataclass
class Trajectory:
    """The result of any integrator: samples of (t, q, q̇), plus how they were made."""

    t: np.ndarray
    q: np.ndarray  # (n, N)
    qd: np.ndarray  # (n, N)
    method: str
    settings: dict
    nfev: int = 0
    success: bool = True
    message: str = ""
    sol: Callable | None = None  # dense output (SciPy methods with dense_output=True)
    t_events: list = field(default_factory=list)
    y_events: list = field(default_factory=list)

    @property
    def y(self) -> np.ndarray:
        return np.vstack((self.q, self.qd))


class Integrator:
    """One integration method; subclasses set `name` and implement `solve`."""

    name: ClassVar[str] = ""
    symplectic: ClassVar[bool] = False
    adaptive: ClassVar[bool] = False
    requires: ClassVar[str] = ""  # "", "separable" or "canonical"

    def __init__(self, **options):
        self.options = options

    def check(self, model: Model, t0: float, q0: np.ndarray, qd0: np.ndarray) -> None:
        """Raise IntegratorError if the method does not apply to `model`."""
        if not self.requires:
            return
        st = structure(model, (t0, q0, qd0))
        if self.requires == "separable" and not st.separable:
            hint = " (use method 'midpoint')" if st.canonical else ""
            raise IntegratorError(f"{self.name} needs a separable Hamiltonian "
                                  f"H = p·M⁻¹p/2 + V(q): {st.reason}{hint}")
        if self.requires == "canonical" and not st.canonical:
            raise IntegratorError(f"{self.name} needs a conservative Lagrangian system "
                                  f"quadratic in the velocities: {st.reason}")

    def solve(self, model: Model, t_span: tuple[float, float], q0: np.ndarray,
              qd0: np.ndarray, t_eval: Sequence[float] | None = None,
              events: Sequence[Callable] | None = None) -> Trajectory:
        raise NotImplementedError


class SciPyMethod(Integrator):
    """solve_ivp with one of its methods; options rtol, atol, max_step, first_step,
    dense_output."""

    adaptive = True

    def __init__(self, method: str, **options):
        super().__init__(**options)
        self.name = method

    def solve(self, model, t_span, q0, qd0, t_eval=None, events=None) -> Trajectory:
        opts = {"rtol": 1e-8, "atol": 1e-10}
        opts.update({k: v for k, v in self.options.items() if v is not None})
        compiled = opts.pop("compiled", True)
        y0 = np.concatenate((q0, qd0)).astype(float)
        n = model.n
        settings = {"method": self.name, **{k: v for k, v in opts.items()
                                             if isinstance(v, (int, float, bool, str))}}
        nat = model.native if compiled and self.name in ("DOP853", "RK45") else None
        if nat is not None and not events and not opts.get("dense_output") \
                and not opts.get("vectorized"):
            from mechbook.numerics import c_stepping as loops

            run = loops.adaptive(
                nat, model.stats, self.name, t_span, y0, opts["rtol"], opts["atol"],
                opts.get("max_step", math.inf), opts.get("first_step"), t_eval)
            model.stats["rhs_calls"] += run.evaluations
            return Trajectory(run.t, run.y[:n], run.y[n:], self.name,
                              {**settings, "compiled": True}, run.evaluations,
                              run.status == 0, run.message)
        sol = solve_ivp(model.rhs, t_span, y0, method=self.name, t_eval=t_eval,
                        events=events, **opts)
        return Trajectory(sol.t, sol.y[:n], sol.y[n:], self.name, settings, int(sol.nfev),
                          bool(sol.success), str(sol.message), sol.sol,
                          list(sol.t_events or []), list(sol.y_events or []))


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
        """The same run as `_run`, as one call into loops.c (`compiled.fixed`)."""
        from mechbook.numerics import c_stepping as loops

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

    name = "RK4"

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

    name = "leapfrog"
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

    name = "yoshida4"
    _w1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
    weights = (_w1, 1.0 - 2.0 * _w1, _w1)


class ImplicitMidpoint(FixedStep):
    """Implicit midpoint rule on canonical z = (q, p): z₁ = z₀ + h F(t + h/2, (z₀ + z₁)/2).

    Symplectic for any Hamiltonian (also non-separable and gyroscopic ones) and exact for
    quadratic invariants. The implicit equation is solved by simplified Newton iteration
    to `tol` (default 1e-14), with a finite-difference Jacobian refreshed every 50 steps or
    when the iteration slows (the converged solution does not depend on it)."""

    name = "midpoint"
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


class TaylorMethod(Integrator):
    """heyoka's adaptive Taylor method (`taylor.py`): options `tol` (default machine
    epsilon; `rtol` is taken for it when `tol` is not given), `max_points`."""

    name = "taylor"
    adaptive = True

    def solve(self, model, t_span, q0, qd0, t_eval=None, events=None) -> Trajectory:
        from mechbook.numerics import taylor

        if events:
            raise IntegratorError("the taylor method takes no solve_ivp events (its own "
                                  "events: taylor.turning_points, taylor.first_crossing)")
        tol = float(self.options.get("tol") or self.options.get("rtol") or taylor.DEFAULT_TOL)
        y0 = np.concatenate((q0, qd0)).astype(float)
        before = taylor.compile_seconds(model)
        start = time.perf_counter()
        t, y, ok, message, steps = taylor.propagate(
            model, t_span, y0, tol, t_eval, int(self.options.get("max_points") or 200_001))
        compile_s = taylor.compile_seconds(model) - before
        n = model.n
        settings = {"method": self.name, "tol": tol, "steps": steps,
                    "compile_s": compile_s,
                    "integrate_s": time.perf_counter() - start - compile_s}
        return Trajectory(t, y[:n], y[n:], self.name, settings, 0, ok, message)


_FIXED_CLASSES: dict[str, type[FixedStep]] = {"RK4": RK4, "leapfrog": Leapfrog,
                                              "yoshida4": Yoshida4,
                                              "midpoint": ImplicitMidpoint}
FIXED: dict[str, type[FixedStep]] = {m: _FIXED_CLASSES[ALIASES.get(m, m)]
                                     for m in FIXED_METHODS}  # names: numerics.methods




def make_integrator(method: str, **options) -> Integrator:
    """The integrator named `method` (see the module docstring) with its options.
    IntegratorError for an unknown method, and for an option given (not None) that the
    method does not take: it would have no effect, so it is refused, saying why."""
    family = kind(method)  # the options each kind takes: mechbook.numerics.methods.OPTIONS
    if family == "scipy":
        return SciPyMethod(method, **_applicable(method, OPTIONS[family], options))
    if family in ("fixed", "midpoint"):
        return FIXED[method](**_applicable(method, OPTIONS[family], options))
    if family == "taylor":
        return TaylorMethod(**_applicable(method, OPTIONS[family], options))
    raise IntegratorError(f"unknown method {method!r}; known: {', '.join(METHODS)}")


def _applicable(method: str, allowed: tuple[str, ...], options: dict) -> dict:
    """The options `method` takes; IntegratorError naming one given that it does not."""
    for name, value in options.items():
        if value is not None and name not in allowed:
            raise IntegratorError(f"option {name!r} does not apply to method {method!r} "
                                  f"({why_not(name, method)}); it takes: "
                                  f"{', '.join(sorted(allowed))}")
    return {k: v for k, v in options.items() if k in allowed}


def integrate(model: Model, t_span: tuple[float, float], q0: Sequence[float],
              qd0: Sequence[float], method: str = "DOP853",
              t_eval: Sequence[float] | None = None, events: Sequence[Callable] | None = None,
              **options) -> Trajectory:
    """Integrate the model from (q0, q̇0) over t_span with `method` (solve_ivp-like)."""
    integ = make_integrator(method, **options)
    q0 = np.asarray(q0, float)
    qd0 = np.asarray(qd0, float)
    integ.check(model, float(t_span[0]), q0, qd0)
    return integ.solve(model, t_span, q0, qd0, t_eval=t_eval, events=events)
