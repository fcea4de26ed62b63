"""A simulated motion as frames of the bodies' positions, for the page's animation.

The trajectory says what the coordinates do; the animation shows what that means: each
particle and body centre where its declared position puts it (functions of q and t at the
default parameter values, compiled once), springs drawn between their ends, in the plane of
the two axes along which the bodies move most (the vertical one up). The frames are plain
numbers (JSON in the page), drawn by a small script on a canvas, offline.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.core.compile import as_expr, compile_exprs

MAX_FRAMES = 240
AXES = "xyz"


def frames(sys, traj, values: dict, max_frames: int = MAX_FRAMES) -> dict | None:
    """{t, bodies: [{name, mass, path: [[u, v], ...]}], springs: [[a, b], ...], axes, box}.
    A system that declares no positions (T and V given directly) shows each coordinate as
    a point moving along a line of its own."""
    positions = getattr(sys, "positions", {})
    if not len(traj.t):
        return None
    if not positions:
        return _coordinates(sys, traj, max_frames)
    names = list(positions)
    dims = max(len(positions[n]) for n in names)
    values = {k: sp.Float(v) for k, v in values.items()}  # xreplace keeps SymPy objects
    exprs = []
    for name in names:
        r = list(positions[name]) + [sp.S.Zero] * (dims - len(positions[name]))
        exprs += [as_expr(c).xreplace(values) for c in r]
    args = [sys.t, *sys.q]
    if set().union(*(e.free_symbols for e in exprs)) - set(args):
        return None  # a position that needs more than (t, q): nothing to draw
    fn, _ = compile_exprs(args, exprs)
    step = max(1, len(traj.t) // max_frames)
    idx = np.arange(0, len(traj.t), step)
    xyz = np.array([np.asarray(fn(np.concatenate(([traj.t[i]], traj.q[:, i]))), float)
                    for i in idx]).reshape(len(idx), len(names), dims)
    if not np.all(np.isfinite(xyz)):
        good = np.all(np.isfinite(xyz), axis=(1, 2))
        xyz, idx = xyz[good], idx[good]
        if not len(idx):
            return None
    axes = _plane(xyz, dims)
    uv = xyz[:, :, axes]
    ends = _springs(sys, names, values, dims, axes)
    flat = np.concatenate([uv.reshape(-1, 2)] + [np.array(e[1]).reshape(-1, 2)
                                                 for e in ends if e[0] == "fixed"])
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    span = max(float(np.max(hi - lo)), 1e-9)
    box = [float(lo[0] - 0.1 * span), float(hi[0] + 0.1 * span),
           float(lo[1] - 0.1 * span), float(hi[1] + 0.1 * span)]
    masses = {n: _number(sys.masses.get(n), values) for n in names}
    return {"t": [round(float(traj.t[i]), 5) for i in idx],
            "bodies": [{"name": n, "mass": masses[n],
                        "path": np.round(uv[:, k, :], 5).tolist()}
                       for k, n in enumerate(names)],
            "springs": [[_end(e, names) for e in pair] for pair in _pairs(ends)],
            "axes": [AXES[a] for a in axes], "box": box}


def _coordinates(sys, traj, max_frames: int) -> dict:
    """Each coordinate as a point on its own horizontal line (no geometry is declared)."""
    step = max(1, len(traj.t) // max_frames)
    idx = np.arange(0, len(traj.t), step)
    n = len(sys.q)
    q = traj.q[:, idx]
    finite = q[np.isfinite(q)]
    lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (-1.0, 1.0)
    span = max(hi - lo, 1e-9)
    gap = span / max(n, 1)
    bodies = [{"name": name, "mass": 1.0,
               "path": [[round(float(x), 5), round(-k * gap, 5)] for x in q[k]]}
              for k, name in enumerate(sys.coord_names)]
    return {"t": [round(float(traj.t[i]), 5) for i in idx], "bodies": bodies, "springs": [],
            "axes": ["q", ""],
            "box": [lo - 0.1 * span, hi + 0.1 * span, -(n - 1) * gap - 0.6 * span,
                    0.6 * span]}


def _plane(xyz: np.ndarray, dims: int) -> list[int]:
    """The two axes along which the bodies move (or sit) most, in order: the last one
    (the vertical, for gravity's default 'up') drawn upwards."""
    if dims <= 2:
        return [0, 1][:dims] if dims == 2 else [0, 0]
    spread = xyz.max(axis=(0, 1)) - xyz.min(axis=(0, 1))
    keep = sorted(np.argsort(-spread)[:2].tolist())
    return keep


def _springs(sys, names: list[str], values: dict, dims: int, axes: list[int]) -> list:
    """Spring ends as ("body", name) or ("fixed", [u, v]), in the order declared (pairs)."""
    out = []
    for spring in sys.spec.get("springs") or []:
        between = spring.get("between") if isinstance(spring, dict) else None
        if not between or len(between) != 2:
            continue
        for end in between:
            if isinstance(end, str) and end in names:
                out.append(("body", end))
            elif isinstance(end, list):
                try:
                    point = [float(sys._parse(c, ("springs",)).xreplace(values)) for c in end]
                except Exception:  # noqa: BLE001 - a fixed end that does not evaluate
                    out.append(("none", None))
                    continue
                point += [0.0] * (dims - len(point))
                out.append(("fixed", [point[a] for a in axes]))
            else:
                out.append(("none", None))
    return out


def _pairs(ends: list) -> list:
    pairs = [ends[i:i + 2] for i in range(0, len(ends) - 1, 2)]
    return [p for p in pairs if all(e[0] != "none" for e in p)]


def _end(end: tuple, names: list[str]):
    kind, value = end
    return names.index(value) if kind == "body" else value


def _number(expr, values: dict) -> float:
    try:
        return float(as_expr(expr).xreplace(values))
    except (TypeError, ValueError):
        return 1.0
