"""Trajectory quantities measured by integrating the full equations of motion.

From an initial state, the engine's equations are integrated (DOP853, rtol = atol = 1e-12,
the integrator behind `mechbook simulate`) until a signal — a coordinate, or any function
of the state — has passed several turning points, located as events where its time
derivative (on the motion) changes sign. From them: the turning values, the period (time
between successive maxima), and how far each coordinate advanced over that period (so its
mean rate). Measured this way on the pendulum and the heavy top against closed forms, the
values agree to better than 1e-9 relative; checks compare at MEASURE_RTOL = 1e-7, the
accuracy stated for these measurements (tests/test_trajectory.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from mechbook.core.compile import compile_exprs
from mechbook.errors import UnsupportedError
from mechbook.numerics import taylor
from mechbook.numerics.rhs import Model

MEASURE_RTOL = 1e-7
TOLERANCE = 1e-12
# DOP853 by default: in `mechbook check` the measurements take ~0.1 s in all (five
# problems), less than importing heyoka (0.3 s per worker) and compiling each system
# (docs/performance.md); "taylor" is the choice for long or many measurements
METHOD = "DOP853"
EXTREMES = 5  # turning points to collect (two full periods and one more)


@dataclass
class Measured:
    """Turning points of a signal along a trajectory and what happened between them."""

    times: np.ndarray  # event times
    values: np.ndarray  # the signal there
    kinds: np.ndarray  # +1 at a maximum, -1 at a minimum
    states: np.ndarray  # (2n, k): the state at each event
    nfev: int

    @property
    def low(self) -> float:
        return float(np.min(self.values[self.kinds < 0])) if np.any(self.kinds < 0) \
            else float("nan")

    @property
    def high(self) -> float:
        return float(np.max(self.values[self.kinds > 0])) if np.any(self.kinds > 0) \
            else float("nan")

    def period(self) -> float:
        """Mean time between successive maxima (and between minima)."""
        gaps = []
        for kind in (+1, -1):
            t = self.times[self.kinds == kind]
            if len(t) >= 2:
                gaps.append((t[-1] - t[0]) / (len(t) - 1))
        if not gaps:
            raise UnsupportedError("measurement: fewer than two maxima or minima of the signal")
        return float(np.mean(gaps))

    def advance(self, index: int) -> float:
        """How far coordinate `index` moved between the first and the last maximum, per
        period."""
        idx = np.flatnonzero(self.kinds == +1)
        if len(idx) < 2:
            raise UnsupportedError("measurement: fewer than two maxima of the signal")
        i, j = idx[0], idx[-1]
        return float(self.states[index, j] - self.states[index, i]) / (len(idx) - 1)


def signal_functions(system, dyn, values: dict, of: sp.Expr):
    """Compiled (signal, its time derivative on the motion) in (t, q, q̇)."""
    sub = {k: sp.Float(float(v), 17) for k, v in values.items()}
    acc = dict(zip(dyn.qdd, dyn.accelerations, strict=True))
    rate = system.dt(of).xreplace(acc)
    args = [system.t, *system.q, *system.qd]
    exprs = [of.xreplace(sub), rate.xreplace(sub)]
    fn, _ = compile_exprs(args, exprs)
    return Signal(fn, exprs)


class Signal:
    """A compiled (signal, rate) in x = (t, q, q̇), with the expressions it came from (the
    Taylor backend's events are built from those)."""

    def __init__(self, fn, exprs: list[sp.Expr]):
        self.fn, self.exprs = fn, exprs

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return self.fn(x)


def _integrator(model: Model):
    """solve_ivp over (t_span, y0, events) for the model: DOP853 at TOLERANCE, through stick
    and slip where the system has frictional contacts (mechbook.numerics.friction)."""
    factory = getattr(model, "phases", None)
    if factory is not None:
        phases = getattr(model, "built_phases", None)
        if phases is None:  # built once per model (its equations are compiled then)
            phases = model.built_phases = factory()
        return lambda span, y, events: phases.solve_ivp(span, y, events, rtol=TOLERANCE,
                                                        atol=TOLERANCE)
    return lambda span, y, events: solve_ivp(model.rhs, span, y, method="DOP853",
                                             rtol=TOLERANCE, atol=TOLERANCE, events=events)


def measure(model: Model, fn, q0: np.ndarray, qd0: np.ndarray, time_scale: float,
            extremes: int = EXTREMES, max_chunks: int = 400,
            method: str = METHOD) -> Measured:
    """Integrate from (q0, q̇0) until `extremes` turning points of the signal are found.

    `fn(x)` with x = (t, q, q̇) returns (signal, d signal/dt); `time_scale` is the length
    of the first integration chunk (a guess at the period); a chunk without a turning point
    makes the next one half as long again, so a poor guess costs a few chunks only.
    `method` "taylor" finds the turning points as heyoka events (`fn` a `Signal`)."""
    n = model.n
    if method == "taylor":
        return _measure_taylor(model, fn, q0, qd0, time_scale, extremes, max_chunks)

    def rate(t, y):
        return fn(np.concatenate(([t], y)))[1]

    t0, y = 0.0, np.concatenate((q0, qd0))
    times, values, kinds, states = [], [], [], []
    nfev = 0
    integrate = _integrator(model)
    for _ in range(max_chunks):
        sol = integrate((t0, t0 + time_scale), y, [rate])
        nfev += sol.nfev
        if sol.status < 0:
            raise UnsupportedError(f"measurement: the integration failed: {sol.message}")
        for te, ye in zip(sol.t_events[0], sol.y_events[0], strict=True):
            if te <= t0 + 1e-12 * max(1.0, abs(t0)):
                continue  # the starting point itself (a start at rest)
            sig = fn(np.concatenate(([te], ye)))
            acc = model.accelerations(te, ye[:n], ye[n:])
            h = 1e-6 * time_scale  # which way the derivative turns: a max or a min
            later = fn(np.concatenate(([te + h], ye + h * np.concatenate((ye[n:], acc)))))[1]
            times.append(te)
            values.append(sig[0])
            kinds.append(-1 if later > 0 else +1)
            states.append(ye)
        found = len(sol.t_events[0])
        t0, y = sol.t[-1], sol.y[:, -1]
        if len(times) >= extremes:
            break
        if not found:
            time_scale *= 1.5
    else:
        raise UnsupportedError(f"measurement: fewer than {extremes} turning points in "
                               f"{max_chunks} chunks of {time_scale:.3g}")
    return Measured(np.array(times), np.array(values), np.array(kinds),
                    np.array(states).T, nfev)


def _measure_taylor(model, fn, q0, qd0, time_scale, extremes, max_chunks) -> Measured:
    y0 = np.concatenate((q0, qd0))
    hits = taylor.turning_points(model, fn.exprs[1], y0, time_scale, extremes, TOLERANCE,
                                 max_chunks)
    n = model.n
    times, values, kinds, states = [], [], [], []
    for te, ye, direction in hits:
        sig = fn(np.concatenate(([te], ye)))
        if direction:
            kind = +1 if direction < 0 else -1  # the rate falls through zero: a maximum
        else:
            acc = model.accelerations(te, ye[:n], ye[n:])
            h = 1e-6 * time_scale
            later = fn(np.concatenate(([te + h], ye + h * np.concatenate((ye[n:], acc)))))[1]
            kind = -1 if later > 0 else +1
        times.append(te)
        values.append(sig[0])
        kinds.append(kind)
        states.append(ye)
    return Measured(np.array(times), np.array(values), np.array(kinds),
                    np.array(states).T, 0)


def first_event(model: Model, fn, q0: np.ndarray, qd0: np.ndarray, time_scale: float,
                max_chunks: int = 400, method: str = METHOD) -> tuple[float, np.ndarray]:
    """(t, state) at the first t > 0 where the compiled `fn(x)[0]` (x = (t, q, q̇)) changes
    sign, integrating chunk by chunk (each half as long again as the last); with `method`
    "taylor" as a terminal heyoka event."""
    if method == "taylor":
        return taylor.first_crossing(model, fn.exprs[0], np.concatenate((q0, qd0)),
                                     time_scale, TOLERANCE, max_chunks)
    def event(t, y):
        return fn(np.concatenate(([t], y)))[0]

    t0, y = 0.0, np.concatenate((q0, qd0))
    # an event function that is zero at the start (a height measured from the launch point)
    # would stop every chunk where it begins: then the chunks run to their ends instead
    event.terminal = bool(event(t0, y) != 0)
    integrate = _integrator(model)
    for _ in range(max_chunks):
        sol = integrate((t0, t0 + time_scale), y, [event])
        if sol.status < 0:
            raise UnsupportedError(f"measurement: the integration failed: {sol.message}")
        hits = [(te, ye) for te, ye in zip(sol.t_events[0], sol.y_events[0], strict=True)
                if te > 1e-12 * max(1.0, time_scale)]
        if hits:
            return float(hits[0][0]), np.asarray(hits[0][1])
        t0, y = sol.t[-1], sol.y[:, -1]
        time_scale *= 1.5
    raise UnsupportedError(f"measurement: the event did not happen in {max_chunks} chunks")
