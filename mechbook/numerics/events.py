"""DOP853 with events in the compiled loop, answered as scipy's solve_ivp answers.

Why: solve_ivp(fun, ..., method="DOP853", events=...) spends its time stepping in Python
(~100 µs a step against a few µs of arithmetic), while the compiled loop
(mechbook.numerics.c_stepping.adaptive) takes the very same steps in C but knows nothing of
events. Here the loop records every step; the events are evaluated at the recorded steps
with solve_ivp's rule for a sign change (find_active_events), and only a step in which one
changes sign is taken again, by SciPy on `fun`: from the same state, with the same length
(first_step), so that SciPy's dense output over it is the one a whole run of solve_ivp has
there, and the events are located on it as solve_ivp locates them (brentq to 4 ε). A
terminal event ends the run there; after any other the recorded steps go on, untouched (an
event does not change the trajectory of a whole run either). A full record is continued
from its last step with the step size the loop would have tried next, so the steps stay
solve_ivp's over any number of records.

`native` and `fun` must be the same equations (the NativeModel of a Model and its `rhs`);
without `native` (no compiler, another backend) it is solve_ivp itself.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from types import SimpleNamespace

import numpy as np
from scipy.integrate import solve_ivp

from mechbook.numerics.c_library import NativeModel
from mechbook.numerics.c_stepping import adaptive

ROWS = 4096  # steps recorded per call of the compiled loop (at most)
FIRST_ROWS = 64  # the first call's record when a terminal event may end the run early


def solve_with_events(native: NativeModel | None,
                      fun: Callable[[float, np.ndarray], np.ndarray], t_span, y0: np.ndarray,
                      *, rtol: float, atol, events: Sequence[Callable] = (), rows: int = ROWS,
                      stats: dict | None = None, max_step: float = np.inf,
                      steps: bool = False) -> SimpleNamespace:
    """solve_ivp(fun, t_span, y0, method="DOP853", rtol=rtol, atol=atol, events=events,
    max_step=max_step), run in the compiled loop of `native` (a NativeModel, or None: then
    in SciPy).

    The answer is solve_ivp's for the end state only: t (one time), y (2n × 1), t_events,
    y_events (events × 2n), status (0 finished, 1 a terminal event, -1 failed), message,
    success, nfev; with `steps`, t and y hold every step's end as solve_ivp's do (the start
    first; at a terminal event its state last). `stats` (a Model's) is charged the compiled
    evaluations and holds the evaluation budget; `rows` is the largest record of one
    compiled call (any size works: the steps are the same)."""
    events = list(events)
    if native is None:
        sol = solve_ivp(fun, t_span, y0, method="DOP853", rtol=rtol, atol=atol,
                        events=events or None, max_step=max_step)
        path = (sol.t, sol.y) if steps else None
        return _answer(float(sol.t[-1]), sol.y[:, -1], [list(x) for x in sol.t_events or []],
                       [list(x) for x in sol.y_events or []], sol.status, sol.message,
                       sol.nfev, path)
    if rows < 2:
        raise ValueError("rows: a record holds its start and at least one step")
    stats = stats if stats is not None else {"rhs_calls": 0}
    limits = [_max_events(ev) for ev in events]
    t, t_end = map(float, t_span)
    y = np.asarray(y0, float)
    t_events: list[list] = [[] for _ in events]
    y_events: list[list] = [[] for _ in events]
    nfev, first, before = 0, None, None
    path_t: list = [np.array([t])] if steps else []  # every step's end, with `steps`
    path_y: list = [y[:, None]] if steps else []
    # with a terminal event the run may end early: records of 64 steps, then twice as many
    # each time up to `rows`, so the loop does not run far past the end (the steps are the
    # same whatever the size: a record goes on exactly where the last one stopped)
    size = min(rows, FIRST_ROWS) if any(x < np.inf for x in limits) else rows
    while True:
        run = adaptive(native, stats, "DOP853", (t, t_end), y, rtol, atol, max_step=max_step,
                       first_step=first, max_points=size)
        size = min(2 * size, rows)
        nfev += run.evaluations
        stats["rhs_calls"] += run.evaluations
        times, states = run.t, run.y
        if before is None:
            before = [ev(times[0], states[:, 0]) for ev in events]
        for k in range(1, len(times)):
            after = [ev(times[k], states[:, k]) for ev in events]
            if _active(before, after, events):
                sub = _step_again(fun, times[k - 1], times[k], states[:, k - 1], rtol, atol,
                                  events, limits, t_events, max_step)
                nfev += sub.nfev
                for e in range(len(events)):
                    t_events[e] += list(sub.t_events[e])
                    y_events[e] += list(sub.y_events[e])
                if sub.status != 0:  # a terminal event, or SciPy failed in the step
                    if steps:
                        path_t += [times[1:k], sub.t[1:]]
                        path_y += [states[:, 1:k], sub.y[:, 1:]]
                    return _answer(float(sub.t[-1]), sub.y[:, -1], t_events, y_events,
                                   sub.status, sub.message, nfev, _joined(path_t, path_y))
            before = after
        if steps:
            path_t.append(times[1:])
            path_y.append(states[:, 1:])
        t, y = float(times[-1]), states[:, -1]
        if run.status == -3:  # the record is full: on from its last step, as it would go
            first = run.next_step
            continue
        return _answer(t, y, t_events, y_events, 0 if run.status == 0 else -1, run.message,
                       nfev, _joined(path_t, path_y))


def _joined(times: list, states: list) -> tuple | None:
    """The recorded steps as one (t, y) pair (None: none were kept)."""
    if not times:
        return None
    return np.concatenate(times), np.concatenate(states, axis=1)


def _step_again(fun, t_old: float, t_new: float, y_old: np.ndarray, rtol: float, atol,
                events: list, limits: list, found: list, max_step: float = np.inf):
    """The recorded step t_old → t_new taken again by solve_ivp with its events: first_step
    is its length, so SciPy takes the same step (it is accepted again: the same error
    estimate, to rounding) and locates the events on its dense output. A terminal event
    that may occur k times is passed on as one that may occur as often as it has not yet."""
    h = abs(float(t_new) - float(t_old))
    passed = [ev if limit == np.inf or limit == 1 else _Remaining(ev, limit - len(done))
              for ev, limit, done in zip(events, limits, found, strict=True)]
    return solve_ivp(fun, (float(t_old), float(t_new)), y_old, method="DOP853", rtol=rtol,
                     atol=atol, events=passed, first_step=h, max_step=max_step)


class _Remaining:
    """An event with the number of occurrences left before it terminates the run."""

    def __init__(self, event: Callable, terminal: int):
        self.event, self.terminal = event, int(terminal)
        self.direction = getattr(event, "direction", 0)

    def __call__(self, t: float, y: np.ndarray) -> float:
        return self.event(t, y)


def _max_events(event) -> float:
    """How many occurrences end the run: solve_ivp's reading of `terminal` (False, None or
    0: never; True: the first; an integer k: the k-th)."""
    terminal = getattr(event, "terminal", None)
    if terminal is None or terminal == 0:
        return np.inf
    if int(terminal) == terminal and terminal > 0:
        return float(terminal)
    raise ValueError("The `terminal` attribute of each event must be a boolean or positive "
                     "integer.")


def _answer(t: float, y: np.ndarray, t_events: list, y_events: list, status: int,
            message: str, nfev: int = 0, path: tuple | None = None) -> SimpleNamespace:
    """The end of a run as solve_ivp answers (the end state, the events found on the way;
    `path`: every step's (t, y) instead of the end's alone)."""
    times, states = path if path is not None else (np.array([t]),
                                                   np.asarray(y, float)[:, None])
    return SimpleNamespace(t=np.asarray(times, float), y=np.asarray(states, float),
                           t_events=[np.array(x, dtype=float) for x in t_events],
                           y_events=[np.array(x, dtype=float).reshape(len(x), len(y))
                                     for x in y_events],
                           status=status, message=message, success=status >= 0, nfev=nfev)


def _active(g: Sequence[float], g_new: Sequence[float], events: Sequence) -> bool:
    """solve_ivp's rule: an event is active in a step if its value goes from ≤ 0 to ≥ 0
    (direction > 0), from ≥ 0 to ≤ 0 (direction < 0), or either (direction 0)."""
    for a, b, ev in zip(g, g_new, events, strict=True):
        direction = getattr(ev, "direction", 0)
        up, down = a <= 0 <= b, a >= 0 >= b
        if (up and direction > 0) or (down and direction < 0) or \
                ((up or down) and direction == 0):
            return True
    return False


__all__ = ["ROWS", "solve_with_events"]
