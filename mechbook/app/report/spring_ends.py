"""Where a spring given by its `length:` alone is attached, found from the motion, so the
animation can draw it.

A spring declared `between:` two ends is drawn between them. One declared by `length:` (an
expression in q) names no ends; but where that length is a distance, sqrt(Σ cᵢ²), its
components c(q) are the vector from one end to the other. Along the simulated motion, an end
is a body's centre or a point of a turning body's outline (a plate's corner), or a fixed
point: the spring is drawn where one candidate point minus c stays put at every frame (a
fixed end, found so) or where two candidates differ by c throughout. A length that is no
such distance (a first-order approximation, l0 + x + sθ/2) has no ends to find, and the
spring is not drawn.
"""

from __future__ import annotations

from itertools import permutations, product

import numpy as np
import sympy as sp

from mechbook.core.compile import as_expr, compile_exprs

TOLERANCE = 1e-6  # of the drawing's span: how exactly an end must follow the motion


def components(length: sp.Expr) -> list[sp.Expr] | None:
    """c of a length written sqrt(c₁² + c₂² + ...), else None."""
    if not (isinstance(length, sp.Pow) and length.exp == sp.Rational(1, 2)):
        return None
    base = length.base
    terms = base.args if isinstance(base, sp.Add) else (base,)
    if not all(isinstance(a, sp.Pow) and a.exp == 2 for a in terms):
        return None
    return [a.base for a in terms]


def length_springs(sys, names: list[str], values: dict, args: list, idx: np.ndarray, traj,
                   xyz: np.ndarray, rots: np.ndarray, turning: list[dict],
                   axes: list[int]) -> list:
    """The ends found for every `length:` spring, flat (two per spring): ("body", name),
    ("fixed", [u, v]) or ("path", [[u, v] per frame])."""
    dims = xyz.shape[2]
    candidates = [("body", names[k], xyz[:, k, :]) for k in range(len(names))]
    for j, spec in enumerate(turning):
        k = spec["body"]
        seen: set = set()
        for line in spec["lines"]:
            for v in line:
                key = tuple(round(float(x), 9) for x in v)
                if key in seen:
                    continue
                seen.add(key)
                turned = np.einsum("fij,j->fi", rots[:, j], np.asarray(v, float))[:, :dims]
                candidates.append(("path", None, xyz[:, k, :] + turned))
    span = max(float(np.ptp(xyz.reshape(-1, dims), axis=0).max()), 1e-9)
    tol = TOLERANCE * span + 1e-12
    out = []
    for i, spring in enumerate(sys.spec.get("springs") or []):
        if not isinstance(spring, dict) or "between" in spring or "length" not in spring:
            continue
        vector = _along(sys, spring, i, values, args, idx, traj, dims)
        if vector is None:
            continue
        found = _ends(candidates, vector, tol)
        if found is not None:
            out += [_shown(end, axes) for end in found]
    return out


def _along(sys, spring: dict, i: int, values: dict, args: list, idx: np.ndarray, traj,
           dims: int) -> np.ndarray | None:
    """c(q) at every frame, (frames, dims); None where the length is no distance."""
    try:
        length = as_expr(sys.parse(spring["length"], ("springs", i, "length")))
    except Exception:  # noqa: BLE001 - the system was built from it; a drawing is optional
        return None
    comps = components(length.xreplace(values))
    if comps is None or len(comps) > dims:
        return None
    comps = comps + [sp.S.Zero] * (dims - len(comps))
    if set().union(*(c.free_symbols for c in comps)) - set(args):
        return None
    fn, _ = compile_exprs(args, comps)
    return np.array([np.asarray(fn(np.concatenate(([traj.t[f]], traj.q[:, f]))), float)
                     for f in idx]).reshape(len(idx), dims)


def _variants(c: np.ndarray) -> list[np.ndarray]:
    """c with its components in every order and of every sign: a sum of squares keeps
    neither (SymPy orders the terms of c₁² + c₂² its own way)."""
    d = c.shape[1]
    return [c[:, list(order)] * np.array(signs) for order in permutations(range(d))
            for signs in product((1.0, -1.0), repeat=d)]


def _ends(candidates: list, c: np.ndarray, tol: float) -> list | None:
    """The two ends: a candidate P with P − c fixed, or two candidates P, Q with
    P − Q = c at every frame, c in each of its orders and signs (_variants)."""
    variants = _variants(c)
    for kind, name, P in candidates:
        for v in variants:
            A = P - v
            if np.all(np.ptp(A, axis=0) <= tol):
                return [("fixed", A[0]), (kind, name if kind == "body" else P)]
    for a, (ka, na, P) in enumerate(candidates):
        for kb, nb, Q in candidates[a + 1:]:
            if any(np.all(np.abs(P - Q - v) <= tol) for v in variants):
                return [(ka, na if ka == "body" else P), (kb, nb if kb == "body" else Q)]
    return None


def _shown(end: tuple, axes: list[int]) -> tuple:
    kind, value = end
    if kind == "fixed":
        return ("fixed", np.round(np.asarray(value, float)[axes], 5).tolist())
    if kind == "path":
        return ("path", np.round(np.asarray(value, float)[:, axes], 5).tolist())
    return end
