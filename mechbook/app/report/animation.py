"""A simulated motion as frames of the bodies' positions, for the page's animation.

The trajectory says what the coordinates do; the animation shows what that means: each
particle and body centre where its declared position puts it (functions of q and t at the
default parameter values, compiled once), springs drawn between their ends, the rigid links
and fixed pivots the motion shows (mechbook.app.report.linkage), and each rigid body's
outline turned with it (mechbook.app.report.outlines), in the plane of the two axes along
which the bodies move most (the vertical one up). The frames are plain numbers (JSON in the
page), drawn by a small script on a canvas, offline.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.app.report.linkage import links
from mechbook.app.report.outlines import entries, outline_specs, projected, triad
from mechbook.app.report.spring_ends import length_springs
from mechbook.core.compile import as_expr, compile_exprs

MAX_FRAMES = 240
AXES = "xyz"


def frames(sys, traj, values: dict, max_frames: int = MAX_FRAMES) -> dict | None:
    """{t, bodies: [{name, mass, path: [[u, v], ...]}], springs and links: [[a, b], ...]
    (a body's index or a fixed point [u, v] at each end), pivots: [[u, v], ...], outlines:
    [{body, lines, turns}], axes, box}. A system that declares no positions (T and V given
    directly) shows each coordinate as a point moving along a line of its own."""
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
    specs = outline_specs(sys, names, values) if dims == 3 or dims == 2 else []
    turning = [s for s in specs if s["R"] is not None]
    for s in turning:
        exprs += [as_expr(e) for e in entries(s["R"])]
    args = [sys.t, *sys.q]
    if set().union(*(e.free_symbols for e in exprs)) - set(args):
        return None  # a position that needs more than (t, q): nothing to draw
    fn, _ = compile_exprs(args, exprs)
    step = max(1, len(traj.t) // max_frames)
    idx = np.arange(0, len(traj.t), step)
    raw = np.array([np.asarray(fn(np.concatenate(([traj.t[i]], traj.q[:, i]))), float)
                    for i in idx]).reshape(len(idx), -1)
    good = np.all(np.isfinite(raw), axis=1)
    raw, idx = raw[good], idx[good]
    if not len(idx):
        return None
    xyz = raw[:, :len(names) * dims].reshape(len(idx), len(names), dims)
    rots = raw[:, len(names) * dims:].reshape(len(idx), len(turning), 3, 3)
    axes = _plane(xyz, dims)
    uv = xyz[:, :, axes]
    ends = _springs(sys, names, values, dims, axes)
    flat = np.concatenate([uv.reshape(-1, 2)] + [np.array(e[1]).reshape(-1, 2)
                                                 for e in ends if e[0] == "fixed"])
    span = max(float(np.max(flat.max(axis=0) - flat.min(axis=0))), 1e-9)
    pairs, pivots = links(xyz, [np.array(p) for p in _fixed_points(sys, values, dims)],
                          {frozenset(p) for p in _body_pairs(ends, names)}, span)
    pivot_uv = [np.asarray(p, float)[axes] for _, p in pivots]
    masses = {n: _number(sys.masses.get(n), values) for n in names}
    reach = [uv[:, s["body"]] + d for s in specs for d in _reach(s["lines"])]
    ends += length_springs(sys, names, values, args, idx, traj, xyz, rots, turning, axes)
    return {"t": [round(float(traj.t[i]), 5) for i in idx],
            "bodies": [{"name": n, "mass": masses[n],
                        "path": np.round(uv[:, k, :], 5).tolist()}
                       for k, n in enumerate(names)],
            "springs": [[_end(e, names) for e in pair] for pair in _pairs(ends)],
            "links": [list(p) for p in pairs] + [[k, np.round(pivot_uv[i], 5).tolist()]
                                                  for i, (k, _) in enumerate(pivots)],
            "pivots": [{"at": np.round(p, 5).tolist(), "side": _away(uv[:, k], p)}
                       for (k, _), p in zip(pivots, pivot_uv, strict=True)],
            "outlines": _outlines(specs, rots, axes, span),
            "axes": [AXES[a] for a in axes],
            "box": _box(np.concatenate([flat, *[p.reshape(1, 2) for p in pivot_uv],
                                        *reach]))}


def _reach(lines: list) -> list[np.ndarray]:
    """How far an outline reaches from its body's centre, as the four offsets (±r, ±r)
    that keep the whole of it inside the drawing's box, whichever way it turns."""
    pts = [p for line in lines for p in line]
    if not pts:
        return []
    r = float(np.max(np.linalg.norm(np.asarray(pts, float), axis=1)))
    return [np.array([[a * r, b * r]]) for a in (-1, 1) for b in (-1, 1)]


def _away(path: np.ndarray, pivot: np.ndarray) -> list[float]:
    """The unit direction from a pivot away from the body that hangs from it (where its
    support is drawn); down when the body is right on it."""
    d = pivot - path.mean(axis=0)
    n = float(np.hypot(*d))
    return np.round(d / n, 4).tolist() if n > 0 else [0.0, -1.0]


def _box(points: np.ndarray) -> list[float]:
    lo, hi = points.min(axis=0), points.max(axis=0)
    span = max(float(np.max(hi - lo)), 1e-9)
    return [float(lo[0] - 0.1 * span), float(hi[0] + 0.1 * span),
            float(lo[1] - 0.1 * span), float(hi[1] + 0.1 * span)]


def _outlines(specs: list[dict], rots: np.ndarray, axes: list[int], span: float) -> list:
    """Each outline's lines in the body's own axes and, for a body that turns, R's two
    drawing rows per frame (None: drawn as it is, around the centre)."""
    out, k = [], 0
    for s in specs:
        turns = None
        lines = s["lines"] or triad(0.12 * span)
        if s["R"] is not None:
            turns = projected(rots[:, k], axes)
            k += 1
        out.append({"body": s["body"],
                    "lines": [np.round(np.asarray(line, float), 5).tolist() for line in lines],
                    "turns": turns, "axes": bool(s["triad"])})
    return out


def _fixed_points(sys, values: dict, dims: int) -> list[list[float]]:
    """The fixed ends of the springs, full coordinates (candidate pivots)."""
    out = []
    for spring in sys.spec.get("springs") or []:
        for end in (spring.get("between") or []) if isinstance(spring, dict) else []:
            if isinstance(end, list):
                try:
                    point = [float(sys.parse(c, ("springs",)).xreplace(values)) for c in end]
                except Exception:  # noqa: BLE001 - a fixed end that does not evaluate
                    continue
                out.append(point + [0.0] * (dims - len(point)))
    return out


def _body_pairs(ends: list, names: list[str]) -> list[tuple[int, int]]:
    return [(names.index(a[1]), names.index(b[1])) for a, b in _pairs(ends)
            if a[0] == "body" and b[0] == "body"]


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
                    point = [float(sys.parse(c, ("springs",)).xreplace(values)) for c in end]
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
    if kind == "path":  # a point of a body that is not its centre (a plate's corner)
        return {"path": value}
    return names.index(value) if kind == "body" else value


def _number(expr, values: dict) -> float:
    try:
        return float(as_expr(expr).xreplace(values))
    except (TypeError, ValueError):
        return 1.0
