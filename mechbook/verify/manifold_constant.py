"""Two functions of the state equal up to a constant on a constrained system's manifold.

A rolling disk's energy is 3mẋ²/4 only where ẋ = Rφ̇: off the constraint manifold the
book's expression and the engine's energy function differ, and their gradients in the full
space of coordinates and velocities do not vanish. What a book claims is that the
difference d is constant on the manifold (the states the motion can reach). At states
sampled on it (the sampler moves each onto it) d's gradient in (q, q̇, t) must lie in the
span of the gradients of the constraints that define it — the holonomic g, their ġ and the
velocity constraints — which is what "constant along every tangent direction" means. What
is left after the least-squares projection onto that span (SVD, 40 digits) is judged
against the size of the two functions' gradients: rounding leaves ~1e-28, a coefficient
wrong by 1e-12 leaves 1e-12.
"""

from __future__ import annotations

import mpmath
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate_mp
from mechbook.verify.compare import POINTS, Sampler, Verdict

WORK = 40  # digits of the projection
RTOL = 1e-24  # what may be left of the gradient, relative to the functions' gradients
RANK_TOL = 1e-25  # a singular value below this fraction of the largest is zero


def constant_on_manifold(book: sp.Expr, engine: sp.Expr, system, sampler: Sampler) -> Verdict:
    """Is book − engine constant on `system`'s constraint manifold (`sampler.manifold`)?

    Parameters: the two expressions in the system's coordinates, velocities and t; the
    system (its q, q̇, t, constraints); a sampler that moves its states onto the manifold.
    Returns a Verdict naming the worst point (a fail names the point that contradicted).
    Example: a disk rolling with ẋ = Rφ̇, book 3mẋ²/4, engine mẋ²/2 + mR²φ̇²/4: passes."""
    manifold = sampler.manifold
    z = list(system.q) + list(system.qd) + [system.t]
    rows = (list(manifold.position) + [system.dt(g) for g in manifold.position]
            + list(manifold.velocity))
    diff = book - engine
    grads = [[sp.diff(f, x) for x in z] for f in (diff, book, engine)]
    jac = [[sp.diff(c, x) for x in z] for c in rows]
    variables = sorted((diff.free_symbols | set().union(*(c.free_symbols for c in rows)))
                       - set(sampler.base), key=lambda s: s.name)
    worst, valid, where = 0.0, 0, ""
    for _ in range(POINTS * 3):
        if valid >= POINTS:
            break
        pt = sampler.draw(variables)
        pt.setdefault(system.t, sp.Float(0))
        got = _left_over(grads, jac, pt)
        if got is None:
            continue
        valid += 1
        if got >= worst:
            worst, where = got, _show(pt)
        if got > RTOL:
            return Verdict(False, f"numeric({valid} points, on the constraint manifold)",
                           f"its gradient along the constraint manifold is {got:.3g} of the "
                           f"energies' at {where}: not constant there")
    if valid == 0:
        return Verdict(False, "numeric", "the expressions do not evaluate at any state "
                       "sampled on the constraint manifold")
    return Verdict(True, f"numeric({valid} points, on the constraint manifold)",
                   f"worst relative {worst:.2g} at {where}",
                   power=f"{valid} states on the constraint manifold at 30 digits: what is "
                         f"left of the difference's gradient along it ≤ {RTOL:g} of the "
                         "energies' gradients")


def _left_over(grads: list, jac: list, pt: dict) -> float | None:
    """|(1 − P)∇d| / max(|∇book|, |∇engine|) at pt, P the projection onto the span of the
    constraints' gradients; None where something does not evaluate."""
    with mpmath.workdps(WORK):
        try:
            g, gb, ge = ([_real(evaluate_mp(x, pt, WORK)) if x != 0 else mpmath.mpf(0)
                          for x in row] for row in grads)
            rows = [[_real(evaluate_mp(x, pt, WORK)) if x != 0 else mpmath.mpf(0)
                     for x in row] for row in jac]
        except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError):
            return None
        scale = max(mpmath.norm(mpmath.matrix(gb)), mpmath.norm(mpmath.matrix(ge)))
        v = mpmath.matrix(g)
        if rows:
            U, S, _ = mpmath.svd_r(mpmath.matrix(rows).T)  # columns: the constraints' ∇
            top = max([abs(x) for x in S] + [mpmath.mpf(0)])
            for k in range(len(S)):
                if top > 0 and S[k] > RANK_TOL * top:
                    u = U[:, k]
                    v -= u * (u.T * v)[0]
        if scale == 0:
            return 0.0 if mpmath.norm(v) == 0 else None
        return float(mpmath.norm(v) / scale)


def _real(v):
    if not mpmath.isfinite(v):
        raise ValueError("not finite")
    return mpmath.re(v)


def _show(pt: dict) -> str:
    items = sorted(pt.items(), key=lambda kv: kv[0].name)[:8]
    return "{" + ", ".join(f"{k}={float(v):.4g}" for k, v in items) + "}"
