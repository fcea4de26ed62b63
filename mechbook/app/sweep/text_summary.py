"""What `mechbook sweep` prints: the run, the numbers, the accuracy, the book."""

from __future__ import annotations

import numpy as np

from mechbook.app.sweep.runner import SweepResult
from mechbook.app.sweep.spec import AMPLITUDE
from mechbook.core.words import plural
from mechbook.engine.linear_grid import STABILITY_NAMES, UNDEFINED


def summary(result: SweepResult) -> list[str]:
    """What the command prints: the run, the numbers, the accuracy, the book."""
    a = result.attrs
    lines = [f"{a['problem']}: {a['title']}",
             f"{a['quantity']} about {a['point']} [system {a['system']}"
             + (", gyroscopic" if a["gyroscopic"] else "") + "]",
             f"grid {a['axes']}: {plural(a['points'], 'point')} in "
             f"{plural(a['blocks'], 'block')} on "
             f"{a['where']}; derived and compiled in {a['build_seconds']:.2f} s, evaluated "
             f"in {a['evaluate_seconds']:.2f} s ({a['points_per_second']:.3g} points/s)"]
    if a["fixed"]:
        lines.append("fixed: " + ", ".join(f"{k}={v:g}" for k, v in a["fixed"].items()))
    if a["conditions"]:
        lines.append("conditions (points outside are undefined): " + ", ".join(a["conditions"]))
    arr = result.arrays
    if a["quantity"] == "stability":
        codes, counts = np.unique(arr["stability"], return_counts=True)
        lines.append("stability: " + ", ".join(f"{STABILITY_NAMES[int(c)]} {n}"
                                               for c, n in zip(codes, counts, strict=True)))
    if a["quantity"] == "frequencies":
        f = arr["frequencies"]
        undefined = arr["stability"] == UNDEFINED
        unstable = np.any(np.isnan(f), -1) & ~undefined
        if np.any(np.isfinite(f)):
            lines.append(f"frequencies: {np.nanmin(f):.6g} to {np.nanmax(f):.6g} rad/s; "
                         f"points with an unstable mode: {int(unstable.sum())}; undefined "
                         f"(no such point, outside the conditions, or M singular): "
                         f"{int(undefined.sum())}")
    if "relative_error" in arr:
        lines += _drift_lines(result)
    acc = a["accuracy"]
    if a["quantity"] == "drift":
        lines.append("accuracy: measured frequencies from DOP853 at rtol 1e-12 (the linear "
                     "reference below)")
    if acc["samples"]:
        what = ("eigenvalues: state-space λ" if a["gyroscopic"] else "eigenvalues: ω²") \
            if a["quantity"] == "stability" else "frequencies"
        line = (f"float64 vs 30 digits at {acc['samples']} sampled points"
                + (f" ({acc['boundary_samples']} beside the boundary)"
                   if acc.get("boundary_samples") else "")
                + f": largest relative difference {acc['max_rel_diff']:.2e} ({what})")
        if acc["disagree"]:
            line += f"; {plural(acc['disagree'], 'point')} disagree: {acc['disagree_at']}"
        lines.append(line)
    if a["ill_conditioned"]:
        lines.append(f"ill-conditioned points (float64 not trusted): {a['ill_conditioned']}, "
                     f"of which {a['precise_50_digits']} recomputed with 50 digits")
    lines += result.book.get("lines", [])
    return lines


def _drift_lines(result: SweepResult) -> list[str]:
    rel = np.abs(result.arrays["relative_error"])
    amps = result.coords[AMPLITUDE]
    out = []
    if len(result.spec.axes) != 1:
        worst = np.nanmax(rel) if np.any(np.isfinite(rel)) else float("nan")
        return [f"largest |relative error| of the linear frequency: {worst:.3g}"]
    for m in range(rel.shape[-1]):
        col = rel[..., m]
        if not np.any(np.isfinite(col)):
            continue
        bits = []
        for tol in (1e-3, 1e-2, 1e-1):
            over = np.flatnonzero(col > tol)
            bits.append(f"{tol:g} from amplitude {amps[over[0]]:.3g}" if len(over)
                        else f"{tol:g} not reached")
        out.append(f"mode {m} (ω {np.nanmedian(result.arrays['linear'][..., m]):.6g}): "
                   f"|relative error| exceeds " + ", ".join(bits))
    return out
