"""Choosing a method and tolerance for a requested accuracy (`mechbook simulate --accuracy`).

The error measure (`state_error`): the state y = (q, q̇) at the end of the run against a
reference solution, each component divided by its own scale — the largest |y_i| along the
reference trajectory, floored at 1e-3 of the largest coordinate (or velocity) scale so a
component that stays near zero is not divided by zero — and the largest of these. It is
what `rtol` aims at, measured globally instead of per step.

How TABLE was derived (docs/performance.md has the data): `bench/work_precision.py` ran on
the BENCH_SYSTEMS problem systems that can be simulated, each from its `simulate` start
(at rest 0.1 from its stable equilibrium) over BENCH_PERIODS periods of its slowest linear
mode, with each adaptive SciPy method at rtol = atol = 1e-3, 1e-4, …, 1e-12 and the
Taylor method (heyoka) at tol = 1e-6 … 1e-16, and measured `state_error` against heyoka's
Taylor method in float128 at tol 1e-30 on the same equations (which agrees with mpmath's
Taylor-series integrator at 20 digits and with exp(At)·y0 at 30 digits to the last bit of
double). For each target 10⁻ᵏ and each method, TABLE holds the loosest tolerance at which
the method met the target on *every* system, the worst error seen there (the expected
error `mechbook simulate` prints) and the CPU time summed over the systems (the cost; for
the Taylor method with the compile of its integrator, which a single run pays). A method
is missing from a target it never met on every system; `taylor` competes only where heyoka
is installed.

The rule (`choose`): the next target at or below the accuracy asked for; there the
cheapest method for a non-stiff run, `stiffness.IMPLICIT` for a stiff one (the bench's
stiffness sweep), or the method the user forced; the method's tolerance from the table.
Longer runs: the global error of these methods grows about in proportion to the time
integrated (the phase error of an oscillation), so a run over P > BENCH_PERIODS periods
(of the slowest linear mode at the start) asks for accuracy × BENCH_PERIODS / P instead
(`tests/test_accuracy.py` checks this on a pendulum over 30 periods). Chaotic motion grows
errors exponentially: there no tolerance keeps a stated accuracy for long.

Regenerate: `python bench/work_precision.py` prints the table in this form (and writes it
to results/bench/accuracy_rule.py); paste it here when the integrators or the problems
change.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mechbook.errors import MechbookError
from mechbook.numerics.stiffness import IMPLICIT
from mechbook.numerics.taylor import available

BENCH_PERIODS = 3  # the bench integrates this many periods of the slowest linear mode
SCIPY = ("RK45", "DOP853", "Radau", "LSODA")
ADAPTIVE = (*SCIPY, "taylor")  # methods with a tolerance (taylor: heyoka, when installed)

# target: {method: (rtol = atol, worst error over the bench systems, seconds summed)}
# measured on 2026-11-26 on the 2-core development machine by bench/work_precision.py
# (CPU seconds; taylor's include the compile of its integrators)
BENCH_SYSTEMS = 47
TABLE: dict[float, dict[str, tuple[float, float, float]]] = {
    1e-03: {
        'RK45': (1e-07, 2.2e-04, 0.00924),
        'DOP853': (1e-06, 5.1e-04, 0.00556),
        'Radau': (1e-05, 6.0e-04, 1.02),
        'LSODA': (1e-07, 1.2e-04, 0.132),
        'taylor': (1e-07, 4.0e-05, 3.42),
    },
    1e-04: {
        'RK45': (1e-08, 2.3e-05, 0.0131),
        'DOP853': (1e-07, 1.1e-05, 0.00649),
        'Radau': (1e-06, 3.5e-05, 1.7),
        'LSODA': (1e-08, 6.0e-05, 0.157),
        'taylor': (1e-07, 4.0e-05, 3.42),
    },
    1e-05: {
        'RK45': (1e-09, 2.4e-06, 0.0201),
        'DOP853': (1e-09, 3.3e-06, 0.00985),
        'Radau': (1e-07, 2.0e-06, 2.79),
        'LSODA': (1e-09, 1.9e-06, 0.194),
        'taylor': (1e-08, 9.4e-06, 4.02),
    },
    1e-06: {
        'RK45': (1e-10, 2.4e-07, 0.031),
        'DOP853': (1e-10, 8.6e-08, 0.0122),
        'Radau': (1e-08, 1.1e-07, 4.71),
        'LSODA': (1e-10, 3.1e-07, 0.223),
        'taylor': (1e-09, 5.8e-07, 4.66),
    },
    1e-07: {
        'RK45': (1e-11, 2.5e-08, 0.047),
        'DOP853': (1e-10, 8.6e-08, 0.0122),
        'Radau': (1e-09, 6.3e-09, 8.11),
        'LSODA': (1e-11, 5.0e-08, 0.277),
        'taylor': (1e-11, 9.3e-09, 6.26),
    },
    1e-08: {
        'RK45': (1e-12, 2.5e-09, 0.0767),
        'DOP853': (1e-11, 8.6e-09, 0.0155),
        'Radau': (1e-09, 6.3e-09, 8.11),
        'taylor': (1e-11, 9.3e-09, 6.26),
    },
    1e-09: {
        'Radau': (1e-10, 3.0e-10, 14.3),
        'taylor': (1e-13, 1.1e-10, 8.2),
    },
    1e-10: {
        'taylor': (1e-14, 1.7e-12, 10.6),
    },
    1e-11: {
        'taylor': (1e-14, 1.7e-12, 10.6),
    },
    1e-12: {
        'taylor': (1e-15, 3.0e-13, 11.8),
    },
}


def state_error(y: np.ndarray, y_ref: np.ndarray, scale: np.ndarray) -> float:
    """Largest componentwise |y − y_ref| / scale (see the module docstring); inf if y is
    not finite."""
    y, y_ref = np.asarray(y, float), np.asarray(y_ref, float)
    if y.shape != y_ref.shape or not np.all(np.isfinite(y)):
        return math.inf
    return float(np.max(np.abs(y - y_ref) / scale))


def scales(y_ref_samples: np.ndarray) -> np.ndarray:
    """Per-component scales from reference samples (2n × N): max |y_i| along the run,
    floored at 1e-3 of the largest coordinate scale (coordinates) or velocity scale
    (velocities)."""
    s = np.max(np.abs(np.asarray(y_ref_samples, float)), axis=1)
    n = len(s) // 2
    out = s.copy()
    for part in (slice(0, n), slice(n, 2 * n)):
        top = float(np.max(s[part])) if len(s[part]) else 0.0
        out[part] = np.maximum(s[part], 1e-3 * top)
    out[out == 0] = 1.0  # a state at rest at the origin throughout
    return out


@dataclass
class Choice:
    """Method and tolerance chosen for a requested accuracy, with what to expect."""

    accuracy: float  # requested
    target: float  # the table's target used (≤ accuracy scaled for the run's length)
    method: str
    rtol: float
    expected: float  # worst error the bench saw at this setting over BENCH_PERIODS
    periods: float | None  # slowest-mode periods in the run (None: no linear period)
    reason: str

    @property
    def atol(self) -> float:
        return self.rtol

    def describe(self) -> str:
        horizon = f"over {BENCH_PERIODS} periods of the slowest linear mode"
        factor = 1.0
        if self.periods and self.periods > BENCH_PERIODS:
            factor = self.periods / BENCH_PERIODS
        expect = self.expected * factor
        setting = "tol" if self.method == "taylor" else "rtol = atol"
        text = (f"{self.method} with {setting} = {self.rtol:.0e} for accuracy "
                f"{self.accuracy:.0e} ({self.reason}); expected error {expect:.1e}")
        if factor > 1:
            text += (f" ({self.expected:.1e} measured {horizon}, scaled to this run's "
                     f"{self.periods:.3g} periods)")
        else:
            text += f" (the worst measured {horizon})"
        return text


def _targets() -> list[float]:
    return sorted(TABLE, reverse=True)


def choose(accuracy: float, *, method: str | None = None, stiff: bool = False,
           periods: float | None = None, taylor_available: bool | None = None) -> Choice:
    """Method and tolerance for a run that should reach `accuracy` (see the docstring).

    `method` forces the method (SciPy methods only; the tolerance comes from its column);
    `stiff` picks the implicit method when none is forced; `periods` is the run's length
    in periods of the slowest linear mode; `taylor_available` (default: whether heyoka
    imports) lets the taylor column compete."""
    if not accuracy > 0 or not math.isfinite(accuracy):
        raise MechbookError(f"--accuracy must be a positive number, got {accuracy}")
    if method is not None and method not in ADAPTIVE:
        raise MechbookError(f"--accuracy chooses a tolerance for the adaptive methods "
                            f"({', '.join(ADAPTIVE)}), not for the fixed-step {method!r}: give "
                            "--step instead")
    if not TABLE:
        raise MechbookError("no accuracy table (run bench/work_precision.py)")
    if taylor_available is None:
        taylor_available = available()
    wanted = accuracy
    if periods and periods > BENCH_PERIODS:
        wanted = accuracy * BENCH_PERIODS / periods
    usable = {t: {m: v for m, v in row.items() if m != "taylor" or taylor_available
                  or method == "taylor"} for t, row in TABLE.items()}
    usable = {t: row for t, row in usable.items() if row}
    reachable = [t for t in sorted(usable, reverse=True) if t <= wanted * (1 + 1e-9)]
    note = ""
    if not reachable:
        reachable = [min(usable)]
        note = f"; below {min(usable):.0e} the bench has no data: the tightest setting"
    target = reachable[0]
    row = usable[target]
    if method is not None:
        pick, why = method, "forced"
    elif stiff:
        pick, why = IMPLICIT, "stiff run"
    else:
        pick = min(row, key=lambda m: row[m][2])
        why = "cheapest in the bench"
    if pick not in row:  # the method never met this target on every system
        own = [t for t in sorted(usable) if pick in usable[t]]
        if not own:
            raise MechbookError(f"{pick} met no accuracy target on every bench system")
        target, row = own[0], usable[own[0]]
        note += f"; {pick} met no target below {target:.0e} on every bench system"
    rtol, worst, _ = row[pick]
    return Choice(accuracy, target, pick, rtol, worst, periods, why + note)


__all__ = ["ADAPTIVE", "BENCH_PERIODS", "TABLE", "Choice", "choose", "scales", "state_error"]
