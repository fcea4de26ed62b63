"""The rigid links of a simulated motion: which bodies a rod (or a taut string, or a hoop's
radius) joins, and the fixed pivots they turn about — found in the motion itself.

A problem file declares positions, not rods: a pendulum's bob is at (l sin θ, −l cos θ),
and nothing says "a rod from the origin". What makes it a rod is that the distance stays
the same while the direction turns. So two bodies are linked when their distance stays
constant along the whole simulated motion (to 1e-6 of the scene's size) while the line
between them turns (by more than a milliradian: a pair that only translates side by side
proves nothing), and a body hangs from a fixed pivot when its distance to a fixed point
stays constant so: the origin, a fixed spring end, or (in the plane) the centre of the
circle its path lies on, if that is near the scene). Pairs a declared spring joins are
springs, not links.
"""

from __future__ import annotations

import numpy as np

RTOL = 1e-6  # of the scene's size: how constant a link's length must stay
TURN = 1e-3  # rad: how far the link's direction must turn


def _constant(d: np.ndarray, scale: float) -> bool:
    return bool(d.mean() > 1e-3 * scale and np.ptp(d) <= RTOL * max(d.mean(), scale))


def _turns(v: np.ndarray) -> bool:
    """Does the direction of v (frames × dims) turn?"""
    n = np.linalg.norm(v, axis=1)
    if np.any(n == 0):
        return False
    u = v / n[:, None]
    return bool(np.max(np.arccos(np.clip(u @ u[0], -1.0, 1.0))) > TURN)


def _circle_centre(path: np.ndarray) -> np.ndarray | None:
    """The centre of the circle through a planar path (least squares), or None."""
    if path.shape[1] != 2 or len(path) < 3:
        return None
    A = np.column_stack([2 * path, np.ones(len(path))])
    b = (path**2).sum(axis=1)
    sol, _, rank, _ = np.linalg.lstsq(A, b, rcond=None)
    return sol[:2] if rank == 3 else None


def links(xyz: np.ndarray, fixed: list[np.ndarray], sprung: set,
          scale: float) -> tuple[list[tuple[int, int]], list[tuple[int, np.ndarray]]]:
    """(pairs of body indices joined by a rigid link, (body, pivot point) pairs), from the
    bodies' positions xyz (frames × bodies × dims), candidate fixed points, the pairs
    springs join, and the scene's size."""
    nb = xyz.shape[1]
    pairs = []
    for a in range(nb):
        for b in range(a + 1, nb):
            if frozenset((a, b)) in sprung:
                continue
            v = xyz[:, a] - xyz[:, b]
            if _constant(np.linalg.norm(v, axis=1), scale) and _turns(v):
                pairs.append((a, b))
    pivots = []
    for a in range(nb):
        path = xyz[:, a]
        candidates = [np.zeros(xyz.shape[2]), *fixed]
        centre = _circle_centre(path)
        if centre is not None:
            candidates.append(centre)
        for point in candidates:
            v = path - point
            d = np.linalg.norm(v, axis=1)
            if d.mean() <= 3 * scale and _constant(d, scale) and _turns(v):
                pivots.append((a, point))
                break
    return pairs, pivots
