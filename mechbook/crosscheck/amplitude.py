"""Where the linear answer stops being good: the frequency measured from the nonlinear
motion at a finite amplitude, against the small-oscillation frequency.

The same measurement as the frequency cross-check (mechbook.crosscheck.frequencies: the full
equations integrated with DOP853 at rtol 1e-12 from a displacement along one normal mode,
the frequency fitted to the upward zero crossings of the mode's own coordinate), but at the
amplitude asked for instead of a vanishing one. The amplitude is the largest coordinate
displacement of the start (the mode shape scaled so its largest component is `amplitude`,
in the coordinates' own units: radians for an angle). The run lasts until PERIODS + 1
crossings or MAX_PERIODS linear periods, so a mode that slows down at large amplitude is
still measured; one that never comes back (it left the well) is reported as NaN.
"""

from __future__ import annotations

import numpy as np

from mechbook.crosscheck.modal import modal_setup, mode_signal, normal_modes, start_state
from mechbook.engine.analysis import Analysis
from mechbook.engine.linear import LinearSystem
from mechbook.errors import UnsupportedError
from mechbook.numerics import taylor
from mechbook.numerics.events import solve_with_events

PERIODS = 4
MAX_PERIODS = 40
RTOL = 1e-12


def amplitude_response(analysis: Analysis, lin: LinearSystem, values: dict,
                       amplitudes, models: dict | None = None, method: str = "DOP853"
                       ) -> tuple[np.ndarray, np.ndarray]:
    """(linear frequencies (n,), measured frequencies (len(amplitudes), n)) at `values`.

    A mode that does not oscillate (unstable, zero, overdamped) is NaN in both; `models`
    caches the compiled nonlinear model per parameter point across calls. `method`
    "taylor" measures all the amplitudes of a mode at once in heyoka's batch mode (the
    crossings as Taylor events; docs/performance.md has the cost of each)."""
    s = modal_setup(analysis, lin, values, models if models is not None else {})
    modes = normal_modes(s)
    linear = np.array([m["omega"] if not m["kind"] and m["omega"] > 0 else np.nan
                       for m in modes])
    order = np.argsort(linear)  # ascending, like the engine's frequencies; NaN last
    linear = linear[order]
    amplitudes = np.atleast_1d(np.asarray(amplitudes, dtype=float))
    out = np.full((len(amplitudes), len(modes)), np.nan)
    for col, k in enumerate(order):
        if not np.isfinite(linear[col]):
            continue
        period = 2 * np.pi / linear[col]
        if method == "taylor":
            out[:, col] = _measure_batch(s, modes[k], amplitudes, period)
            continue
        for row, a in enumerate(amplitudes):
            out[row, col] = _measure(s, modes[k], a, period)
    return linear, out


def _measure_batch(s, mode: dict, amplitudes: np.ndarray, period: float) -> np.ndarray:
    """The frequencies at every amplitude from one Taylor batch run (same fit as _measure:
    the first PERIODS + 1 upward crossings, within MAX_PERIODS linear periods)."""
    if not np.all(amplitudes > 0):
        raise UnsupportedError("a finite-amplitude frequency needs an amplitude > 0")
    n_full = len(s.q_star)
    idx = np.array(s.index)
    nl = len(idx)
    weights = np.real(mode["weights"])
    c = np.zeros(2 * n_full)
    c[idx] = weights[:nl]
    c[n_full + idx] = weights[nl:]
    turn = s.turn[idx] if s.turn is not None else np.zeros(nl)
    a0 = float(weights[:nl] @ s.q_star[idx] + weights[nl:] @ s.v_star[idx])
    b0 = float(weights[:nl] @ turn)
    starts = np.array([start_state(s, mode, a) for a in amplitudes])
    with np.errstate(all="ignore"):
        hits = taylor.crossings_batch(s.model, c, (a0, b0), starts, MAX_PERIODS * period)
    out = np.full(len(amplitudes), np.nan)
    for i, times in enumerate(hits):
        times = times[: PERIODS + 1]
        if len(times) >= 3:
            out[i] = 2 * np.pi / np.polyfit(np.arange(len(times)), times, 1)[0]
    return out


def _measure(s, mode: dict, amplitude: float, period: float) -> float:
    if not amplitude > 0:
        raise UnsupportedError("a finite-amplitude frequency needs an amplitude > 0")
    g = mode_signal(s, mode)
    g.direction = 1.0
    g.terminal = PERIODS + 1
    y0 = start_state(s, mode, amplitude)
    scale = np.maximum(np.abs(y0), 1.0)
    with np.errstate(all="ignore"):
        sol = solve_with_events(s.model.native, s.model.rhs, (0.0, MAX_PERIODS * period),
                                y0, rtol=RTOL, atol=1e-13 * amplitude * scale, events=[g],
                                stats=s.model.stats)
    times = np.asarray(sol.t_events[0])
    if not sol.success or len(times) < 3:
        return float("nan")
    slope = np.polyfit(np.arange(len(times)), times, 1)[0]
    return float(2 * np.pi / slope)
