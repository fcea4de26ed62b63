"""A sweep's accuracy statement: the float64 results at sampled grid points against the
30-digit path (the symbolic matrices substituted at 30 digits, not through the compiled
function; the eigenproblem in mpmath). A stability map samples a third of its points
beside the boundary, where the classification is most delicate."""

from __future__ import annotations

import numpy as np

from mechbook.app.options import SWEEP_SAMPLES
from mechbook.engine.linear_grid import UNDEFINED


def sample_accuracy(sweeper, arrays: dict[str, np.ndarray], samples: int = SWEEP_SAMPLES,
                    seed: int = 0) -> dict:
    """The float64 results at sampled points against the 30-digit path (the matrices
    substituted symbolically, the eigenproblem in mpmath)."""
    rng = np.random.default_rng(seed)
    shape = sweeper.grid.shape
    defined, edge = _candidates(sweeper, arrays)
    if not len(defined):
        return {"samples": 0, "max_rel_diff": float("nan"), "disagree": 0}
    chosen = list(rng.choice(edge, min(len(edge), samples // 3), replace=False)) \
        if len(edge) else []
    rest = points_left(defined, np.asarray(chosen, dtype=defined.dtype))
    chosen += list(rng.choice(rest, min(len(rest), samples - len(chosen)), replace=False))
    worst, disagree, worst_at = 0.0, [], None
    for flat in sorted(int(c) for c in chosen):
        values = {s: v for s, v in sweeper.grid.values_at(flat).items()
                  if s is not sweeper.amplitude}
        idx = np.unravel_index(flat, shape)
        where = {a.name: float(v) for a, v in
                 zip(sweeper.grid.axes, (sweeper.grid.coords()[a.name][i] for a, i in
                                      zip(sweeper.grid.axes, idx, strict=True)), strict=True)}
        try:
            rel = _relative_difference(sweeper, arrays, values, idx)
        except (ValueError, ZeroDivisionError, TypeError, ArithmeticError) as exc:
            disagree.append({**where, "error": str(exc)[:80]})
            continue
        if rel is None:
            disagree.append(where)
        elif rel >= worst:
            worst, worst_at = rel, where
    return {"samples": len(chosen), "boundary_samples": min(len(edge), samples // 3),
            "max_rel_diff": worst, "worst_at": worst_at, "disagree": len(disagree),
            "disagree_at": disagree[:5]}


def points_left(defined: np.ndarray, taken: np.ndarray) -> np.ndarray:
    """`defined` (sorted, unique) less the points `taken` from it: `np.setdiff1d`'s result,
    found by bisection instead of sorting every grid point again (on a 3000 × 3000 map
    that sort took seconds in one C call, where Ctrl-C could not stop it)."""
    keep = np.ones(defined.size, dtype=bool)
    at = np.searchsorted(defined, taken)
    inside = at < defined.size
    at = at[inside][defined[at[inside]] == taken[inside]]
    keep[at] = False
    return defined[keep]


def _candidates(sweeper, arrays: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(flat indices where the result is defined, those beside a stability boundary)."""
    if sweeper.spec.quantity == "stability":
        codes = arrays["stability"]
        return np.flatnonzero(codes.reshape(-1) != UNDEFINED), _boundary(codes)
    name = "frequencies" if sweeper.spec.quantity == "frequencies" else "linear"
    defined = np.flatnonzero(np.any(np.isfinite(arrays[name]), axis=-1).reshape(-1))
    return defined, np.zeros(0, dtype=int)


def _relative_difference(sweeper, arrays: dict[str, np.ndarray], values: dict,
                         idx: tuple) -> float | None:
    """The float64 result at one point against the 30-digit one, relative to its scale;
    None where the two disagree in kind (a stability class, which frequencies exist)."""
    if sweeper.spec.quantity == "stability":
        code, ref = sweeper.linear.precise_stability(values)
        if code != arrays["stability"][idx]:
            return None
        X = np.array([[values[s] for s in sweeper.linear.symbols]])
        got = sweeper.linear.spectrum(X)[0]
        scale = float(np.max(np.abs(ref))) or 1.0
        # each exact eigenvalue against the nearest float64 one
        return float(np.max(np.min(np.abs(ref[:, None] - got[None, :]), axis=1))) / scale
    ref = sweeper.linear.precise_frequencies(values)
    name = "frequencies" if sweeper.spec.quantity == "frequencies" else "linear"
    got = arrays[name][idx]
    if not np.array_equal(np.isfinite(ref), np.isfinite(got)):
        return None
    scale = float(np.nanmax(np.abs(ref))) if np.any(np.isfinite(ref)) else 1.0
    diff = np.abs(np.nan_to_num(got) - np.nan_to_num(ref))
    return float(np.max(diff)) / scale if scale > 0 and np.any(diff) else 0.0


def _boundary(codes: np.ndarray) -> np.ndarray:
    """Flat indices of grid points whose stability differs from a neighbour's."""
    mark = np.zeros(codes.shape, dtype=bool)
    for ax in range(codes.ndim):
        if codes.shape[ax] < 2:
            continue
        a = np.swapaxes(codes, 0, ax)
        m = np.swapaxes(mark, 0, ax)
        diff = (a[1:] != a[:-1]) & (a[1:] != UNDEFINED) & (a[:-1] != UNDEFINED)
        m[1:] |= diff
        m[:-1] |= diff
    return np.flatnonzero(mark.reshape(-1))
