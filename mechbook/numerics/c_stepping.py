"""The compiled loops of `loops.c` called once per run (fixed steps, DOP853, RK45).

Why: one Python call per step (or per right-hand side inside solve_ivp) costs far more
than the step's arithmetic; here the whole run is one C call, and the records come back as
arrays. Each function mirrors its Python reference (`fixed_step.py`; scipy's solve_ivp for
DOP853 and RK45) step for step, so the numbers agree to rounding (tests/test_native.py).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from mechbook.numerics.c_library import NativeModel, address

BIG = 2**62  # "no budget" for the evaluation limit
FIXED_CODES = {0: "", 1: "non-finite", 2: "budget", 3: "newton"}


def _limit(stats, nat: NativeModel) -> int:
    limit = getattr(stats, "limit", math.inf)
    if not math.isfinite(limit):
        return BIG
    return nat.nfev() + max(0, int(limit - stats["rhs_calls"]))


def fixed(nat: NativeModel, stats, method: str, t0: float, h: float, steps: int,
          start: np.ndarray, want: np.ndarray, weights=(1.0,), tol: float = 1e-14,
          max_iter: int = 50) -> tuple[np.ndarray, np.ndarray, str, int, int]:
    """Run a fixed-step method: (t of the records, rows (q, q̇) of the records, failure
    kind ('' / 'non-finite' / 'budget' / 'newton'), the step it happened in, evaluations).

    `start` is (q0, q̇0) for RK4 and leapfrog, (q0, p0) for the midpoint rule."""
    lib = nat.lib
    n2 = 2 * nat.n
    want = np.ascontiguousarray(want, dtype=np.int64)
    rec = np.empty((len(want), n2))
    failed = np.zeros(2, dtype=np.int64)
    start = np.ascontiguousarray(start, dtype=float)
    before = nat.nfev()
    limit = _limit(stats, nat)
    if method == "RK4":
        rows = lib.mb_rk4(nat.ptr, t0, h, steps, address(start), address(want), len(want),
                          address(rec), address(failed), limit)
    elif method == "leapfrog":
        w = np.ascontiguousarray(weights, dtype=float)
        q0, v0 = start[: nat.n].copy(), start[nat.n:].copy()
        rows = lib.mb_leapfrog(nat.ptr, t0, h, steps, address(w), len(w), address(q0),
                               address(v0), address(want), len(want), address(rec),
                               address(failed), limit)
    elif method == "midpoint":
        rows = lib.mb_midpoint(nat.ptr, t0, h, steps, address(start), tol, max_iter,
                               address(want), len(want), address(rec), address(failed), limit)
    else:
        raise ValueError(method)
    evals = nat.nfev() - before
    return (t0 + want[:rows] * h, rec[:rows], FIXED_CODES[int(failed[0])], int(failed[1]),
            evals)


def _tableau(method: str):
    from scipy.integrate._ivp import dop853_coefficients as d853
    from scipy.integrate._ivp import rk

    if method == "DOP853":
        return 8, d853.A, d853.B, d853.C, d853.E3, d853.E5, d853.D
    r = rk.RK45
    square = np.zeros((r.n_stages, r.n_stages))  # loops.c reads A with n_stages columns
    square[:, : r.A.shape[1]] = r.A
    return 5, square, r.B, r.C, np.zeros(1), r.E, r.P


MESSAGES = {0: "The solver successfully reached the end of the integration interval.",
            -1: "Required step size is less than spacing between numbers.",
            -2: "evaluation budget spent", -3: "more steps than max_points"}


class Run(NamedTuple):
    """A run of `adaptive`: the records, its status (0 finished, negative failed:
    MESSAGES), the right-hand-side evaluations it cost, and the step size it would try
    next from its last record (with status -3, the record full, a run from there with
    first_step=next_step goes on exactly as this one would have)."""

    t: np.ndarray
    y: np.ndarray  # 2n × N
    status: int
    message: str
    evaluations: int
    next_step: float


def tolerances(atol, size: int) -> np.ndarray:
    """atol as solve_ivp takes it (a number, or one per component) as a contiguous array of
    `size` floats, the compiled loop's form."""
    a = np.asarray(atol, dtype=float)
    if a.ndim == 0:
        a = np.full(size, float(a))
    elif a.shape != (size,):
        raise ValueError(f"atol has shape {a.shape}: a number or {size} values wanted")
    if not np.all(a >= 0):
        raise ValueError("atol must be positive")
    return np.ascontiguousarray(a)


def adaptive(nat: NativeModel, stats, method: str, t_span, y0: np.ndarray, rtol: float,
             atol, max_step: float = math.inf, first_step: float | None = None,
             t_eval=None, max_points: int = 200_001) -> Run:
    """DOP853 or RK45 as solve_ivp runs them (atol a number or one per component of y0)."""
    kind, *table = _tableau(method)
    A, B, C, E3, E5, D = (np.ascontiguousarray(x, dtype=float) for x in table)
    t0, t1 = map(float, t_span)
    y0 = np.ascontiguousarray(y0, dtype=float)
    n2 = len(y0)
    tol = tolerances(atol, n2)
    if t_eval is not None:
        te = np.ascontiguousarray(t_eval, dtype=float)
        neval, rows_cap = len(te), len(te)
    else:
        te, neval, rows_cap = np.zeros(1), -int(max_points), int(max_points)
    rec = np.empty((rows_cap, n2))
    tout = np.empty(rows_cap)
    status = np.zeros(1, dtype=np.int32)
    h_next = np.zeros(1)
    before = nat.nfev()
    rows = nat.lib.mb_rk_adaptive(
        nat.ptr, int(kind), t0, t1, address(y0), float(rtol), address(tol),
        float(max_step), float(first_step or 0.0), address(A), address(B), address(C),
        address(E3), address(E5), address(D), address(te), neval, address(rec),
        address(tout), address(status), address(h_next), _limit(stats, nat))
    code = int(status[0])
    return Run(tout[:rows], rec[:rows].T, code, MESSAGES[code], nat.nfev() - before,
               float(h_next[0]))


__all__ = ["Run", "adaptive", "fixed", "tolerances"]
