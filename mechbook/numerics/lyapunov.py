"""The largest Lyapunov exponent of a trajectory, by the tangent-map (Benettin) method.

One tangent vector is carried along the motion by the variational equations
(mechbook.numerics.tangent) and renormalized to length 1 after each of `windows` equal
windows of the run; the logarithms of its growth in each window are kept (nothing else, so
a long run needs no memory). From them:

- the estimate λ: the growth over the second half of the run divided by its length (the
  first half lets the vector turn into the most unstable direction);
- its spread: the difference between the estimates of the third and the fourth quarter,
  the run's own measure of how far it has converged;
- its resolution b = RESOLUTION / span: a regular motion, whose tangent vectors grow like a
  power of t (linearly on an invariant torus), has a second-half growth of a few times
  ln 2 with bounded oscillations; below b an exponent cannot be told from zero.

The state must stay bounded: a coordinate that is not an angle of the equations, or a
velocity, leaving BOUND times the start's size ends the run (`UnboundedMotion`). The run
keeps to a CPU budget: it times a probe of 1/PROBE of its first window, and again its
first four windows, projects its cost and stops (an `UnsupportedError` saying so) rather
than run past what a check may take.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from mechbook.errors import UnsupportedError
from mechbook.numerics.tangent import TangentFlow, angle_coordinates

WINDOWS = 64
RESOLUTION = 8.0  # b = RESOLUTION / span: what a regular motion's second half can show
BOUND = 1e4  # the state may grow to this times (1 + |start|) and no further
BUDGET_SECONDS = 60.0  # CPU seconds a run may take
PROBE = 64  # the first window starts with 1/PROBE of itself, timed
RTOL = 1e-10


class UnboundedMotion(Exception):
    """The motion left every bound: it has no Lyapunov exponent of a bounded orbit."""


@dataclass
class ExponentRun:
    """The logs of one run and what they give."""

    span: float
    logs: np.ndarray  # ln(growth) in each window
    evaluations: int
    seconds: float

    @property
    def estimate(self) -> float:
        half = len(self.logs) // 2
        return float(np.sum(self.logs[half:]) / (self.span / 2))

    @property
    def spread(self) -> float:
        w = len(self.logs)
        q3 = np.sum(self.logs[w // 2: 3 * w // 4]) / (self.span / 4)
        q4 = np.sum(self.logs[3 * w // 4:]) / (self.span / 4)
        return float(abs(q3 - q4))

    @property
    def resolution(self) -> float:
        return RESOLUTION / self.span


def largest_exponent(system, dyn, values: dict, y0: np.ndarray, span: float,
                     windows: int = WINDOWS, seed: int = 1,
                     progress: Callable[[str], None] | None = None,
                     budget: float = BUDGET_SECONDS, max_step: float = math.inf) -> ExponentRun:
    """The Benettin run from the state y0 (2n: q, q̇) over `span` time units at `values`
    (`max_step`: no longer steps, for a drive in short pulses).
    Example: `largest_exponent(sys, dyn, values, np.array([0.1, 0.0]), 500.0).estimate`."""
    if not span > 0 or not math.isfinite(span):
        raise ValueError("the span of a Lyapunov run must be a positive number")
    flow = TangentFlow(system, dyn, values, 1)
    n = flow.n
    free = [not a for a in angle_coordinates(flow.model, n)] + [True] * n
    limit = BOUND * (1.0 + float(np.max(np.abs(y0))))
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(2 * n, 1))
    v /= np.linalg.norm(v)
    y, t, dt = np.array(y0, float), 0.0, span / windows
    logs = np.empty(windows)
    start = time.process_time()
    def advance(a: float, b: float, y, v):
        try:
            with np.errstate(all="ignore"):
                return flow.flow(a, b, y, v, rtol=RTOL, max_step=max_step)
        except UnsupportedError as exc:  # the state ran away, or the steps could not go on
            t, z = flow.reach(a, b, y)
            size = float(np.max(np.abs(z[free]))) if any(free) else 0.0
            if not (np.all(np.isfinite(z)) and size <= limit):
                raise UnboundedMotion(f"the state reached {size:.3g} by t = {t:.6g}: the "
                                      "motion is unbounded") from None
            raise UnsupportedError(f"the Lyapunov run's integration failed between t = "
                                   f"{a:.6g} and {b:.6g} with the state bounded: "
                                   f"{exc.capability}") from None

    for w in range(windows):
        if w == 0:  # a probe of 1/PROBE of a window first: a run far too long stops at once
            y, v = advance(t, t + dt / PROBE, y, v)
            _within(time.process_time() - start, PROBE * windows, budget)
            y, v = advance(t + dt / PROBE, t + dt, y, v)
        else:
            y, v = advance(t, t + dt, y, v)
        t += dt
        size = float(np.max(np.abs(y[free]))) if any(free) else 0.0
        if not (np.all(np.isfinite(y)) and size <= limit):
            raise UnboundedMotion(f"the state reached {size:.3g} by t = {t:.6g} (from "
                                  f"{float(np.max(np.abs(y0))):.3g}): the motion is unbounded")
        norm = float(np.linalg.norm(v))
        if not (norm > 0 and math.isfinite(norm)):
            raise UnsupportedError("the tangent vector vanished or overflowed within a window "
                                   "(use more windows: a shorter span per window)")
        logs[w] = math.log(norm)
        v /= norm
        if w == 3:
            _within(time.process_time() - start, windows / 4, budget)
        if progress is not None and (w + 1) % 16 == 0:
            progress(f"t = {t:.4g} of {span:.4g}")
    return ExponentRun(span, logs, flow.evaluations, time.process_time() - start)


def _within(spent: float, times: float, budget: float) -> None:
    """UnsupportedError if `times` more of what took `spent` CPU seconds exceeds `budget`."""
    if spent * times > budget:
        raise UnsupportedError(f"the Lyapunov run would take about {spent * times:.0f} s, "
                               f"more than the {budget:.0f} s a part may take")


__all__ = ["BOUND", "ExponentRun", "RESOLUTION", "UnboundedMotion", "WINDOWS",
           "largest_exponent"]
