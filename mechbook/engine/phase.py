"""Phase-space flow: the map Φ of a system's motion in canonical coordinates (q, p).

`PhaseFlow.map(values, q, p, t1, t0)` takes points (q, p) at time t0 to the points the motion
reaches at time t1 (t1 < t0 runs the motion backwards). It integrates the engine's own
equations M(q, t)·q̈ = f(q, q̇, t) (`Dynamics.residuals`, non-conservative forces included,
never re-derived) in (q, q̇) with DOP853 at rtol 1e-12, and converts p ↔ q̇ at both ends
through the engine's momenta p = ∂L/∂q̇: q̇ from p by Newton's method with the Jacobian
∂p/∂q̇ = ∂²L/∂q̇², which is one exact linear solve when the momenta are linear in the
velocities (T quadratic), and still converges when they are not (relativistic L).
Parameters are numbers (a sampled parameter point). Many points travel together as one
vector system, so a boundary of a thousand points costs one integration; the error norm
of solve_ivp is then the RMS over the batch, so a single point may carry up to
sqrt(batch size) times the tolerance (still ~1e-10 relative).

On the flow: the area of the image of a box of the (q, p) plane (one degree of freedom) by
the shoelace formula on its mapped boundary, Richardson-extrapolated in the number of
boundary points; and membership of points in the image of a box, decided by mapping them
back: X ∈ Φ_t(B) iff Φ_{-t}(X) ∈ B.
"""

from __future__ import annotations

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from mechbook.core.compile import as_expr, compile_batch
from mechbook.errors import UnsupportedError

RTOL = 1e-12  # tolerance of the flow's integration


class PhaseFlow:
    """The flow of one system in (q, p), compiled once; parameters are given per call."""

    def __init__(self, system, dyn, rtol: float = RTOL):
        if system.constraints or system.velocity_constraints:
            raise UnsupportedError("phase-space flow of a system with multiplier constraints "
                                   "(its (q, p) are not canonical coordinates)")
        if system.free_driven:
            raise UnsupportedError("phase-space flow with an arbitrary driven coordinate")
        self.system, self.rtol = system, rtol
        self.t = system.t
        self.q, self.qd, self.qdd = list(dyn.q), list(dyn.qd), list(dyn.qdd)
        self.n = n = len(self.q)
        zero = {a: 0 for a in self.qdd}
        res = list(dyn.residuals)
        mass = [sp.diff(e, a) for e in res for a in self.qdd]
        force = [-e.xreplace(zero) for e in res]
        mom = list(dyn.momenta)
        jac = [sp.diff(p, v) for p in mom for v in self.qd]
        state = {self.t, *self.q, *self.qd}
        free = set().union(*(as_expr(e).free_symbols for e in mass + force + mom + jac))
        self.params = sorted(free - state, key=lambda s: s.name)
        args = [self.t] + self.q + self.qd + self.params
        self._mf = compile_batch(args, mass + force)
        self._pj = compile_batch(args, mom + jac)
        self._sizes = (n * n, n)

    # ---- pieces --------------------------------------------------------------------------
    def _par(self, values: dict) -> list[float]:
        missing = [s.name for s in self.params if s not in values]
        if missing:
            raise UnsupportedError("phase-space flow: symbols without a value: "
                                   + ", ".join(missing))
        return [float(values[s]) for s in self.params]

    @staticmethod
    def _points(t: float, Q: np.ndarray, V: np.ndarray, par) -> np.ndarray:
        """The compiled functions' input for N states: rows (t, q, q̇, parameters)."""
        N = Q.shape[1]
        return np.column_stack([np.full(N, t), Q.T, V.T, np.tile(np.asarray(par, float),
                                                                  (N, 1))])

    def accelerations(self, t: float, Q: np.ndarray, V: np.ndarray, par) -> np.ndarray:
        """q̈ (n, N) at N states given as columns of Q, V (n, N)."""
        n, N = self.n, Q.shape[1]
        out = self._mf(self._points(t, Q, V, par)).T
        M = out[: n * n].T.reshape(N, n, n)
        f = out[n * n:].T
        if n == 1:
            return (f[:, 0] / M[:, 0, 0])[None, :]
        return np.linalg.solve(M, f[..., None])[..., 0].T

    def momenta(self, t: float, Q: np.ndarray, V: np.ndarray, par) -> tuple:
        """p (n, N) and ∂p/∂q̇ (N, n, n) at N states."""
        n, N = self.n, Q.shape[1]
        out = self._pj(self._points(t, Q, V, par)).T
        return out[:n], out[n:].T.reshape(N, n, n)

    def velocities(self, t: float, Q: np.ndarray, P: np.ndarray, par) -> np.ndarray:
        """q̇ (n, N) with ∂L/∂q̇ = P: Newton's method from q̇ = 0 (one step when the momenta
        are linear in the velocities), each point's step halved while it does not reduce
        that point's residual (p(q̇) may be defined only for |q̇| < c)."""
        V = np.zeros_like(Q)
        scale = max(float(np.abs(P).max(initial=0.0)), 1e-300)

        def residual(V):
            with np.errstate(all="ignore"):
                p, J = self.momenta(t, Q, V, par)
                r = np.abs(p - P).max(axis=0)
            return p - P, np.where(np.isfinite(r), r, np.inf), J

        r, size, J = residual(V)
        for _ in range(60):
            done = size <= 1e-13 * scale
            if done.all():
                return V
            step = np.linalg.solve(np.where(np.isfinite(J), J, 1.0),
                                   np.where(np.isfinite(r), r, 0.0).T[..., None])[..., 0].T
            lam = np.where(done, 0.0, 1.0)
            for _ in range(50):
                Vn = V - lam * step
                rn, size_n, Jn = residual(Vn)
                worse = ~done & (size_n >= size)
                if not worse.any():
                    break
                lam = np.where(worse, lam / 2, lam)
            if np.array_equal(Vn, V):
                break
            V, r, size, J = Vn, rn, size_n, Jn
        if np.all(size <= 1e-9 * scale):
            return V
        raise UnsupportedError("phase-space flow: p = ∂L/∂q̇ could not be solved for q̇")

    # ---- the flow ------------------------------------------------------------------------
    def map(self, values: dict, q, p, t1: float, t0: float = 0.0) -> tuple:
        """Φ from t0 to t1 of points (q, p), arrays of shape (N, n) (or (N,) for n = 1)."""
        par = self._par(values)
        q = np.asarray(q, dtype=float)
        p = np.asarray(p, dtype=float)
        shape = q.shape
        Q = q.reshape(len(q), -1).T.copy()
        P = p.reshape(len(p), -1).T.copy()
        if Q.shape[0] != self.n or P.shape != Q.shape:
            raise ValueError(f"expected points with {self.n} coordinates and momenta")
        t0, t1 = float(t0), float(t1)
        V = self.velocities(t0, Q, P, par)
        if t1 != t0:
            Q, V = self._integrate(Q, V, t0, t1, par)
        P1, _ = self.momenta(t1, Q, V, par)
        return Q.T.reshape(shape), P1.T.reshape(shape)

    def _integrate(self, Q, V, t0, t1, par):
        n, N = self.n, Q.shape[1]
        span = abs(t1 - t0)
        sq = np.maximum(np.abs(Q).max(axis=1), 1e-12)
        sv = np.maximum(np.abs(V).max(axis=1), sq / span)
        atol = self.rtol * np.repeat(np.concatenate((sq, sv)), N)

        def rhs(t, y):
            Y = y.reshape(2 * n, N)
            return np.concatenate((Y[n:], self.accelerations(t, Y[:n], Y[n:], par))).ravel()

        y0 = np.concatenate((Q, V)).ravel()
        with np.errstate(all="ignore"):
            sol = solve_ivp(rhs, (t0, t1), y0, method="DOP853", rtol=self.rtol, atol=atol)
        y = sol.y[:, -1] if sol.y.size else y0
        if not sol.success or not np.all(np.isfinite(y)):
            raise UnsupportedError(f"phase-space flow: integration failed ({sol.message})")
        Y = y.reshape(2 * n, N)
        return Y[:n], Y[n:]


# ---- regions of the phase plane ------------------------------------------------------------
def box_boundary(lo, hi, per_side: int) -> tuple[np.ndarray, np.ndarray]:
    """The boundary of [lo_q, hi_q] × [lo_p, hi_p], counterclockwise in the (q, p) plane,
    `per_side` points per side starting at each corner (the start is not repeated)."""
    s = np.arange(per_side) / per_side
    (q0, p0), (q1, p1) = lo, hi
    q = np.concatenate((q0 + (q1 - q0) * s, np.full(per_side, q1), q1 - (q1 - q0) * s,
                        np.full(per_side, q0)))
    p = np.concatenate((np.full(per_side, p0), p0 + (p1 - p0) * s, np.full(per_side, p1),
                        p1 - (p1 - p0) * s))
    return q, p


def shoelace(x: np.ndarray, y: np.ndarray) -> float:
    """Signed area of the closed polygon (x_i, y_i) (positive when counterclockwise)."""
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def image_area(flow: PhaseFlow, values: dict, lo, hi, t: float, per_side: int = 200,
               t0: float = 0.0, max_per_side: int = 3200) -> tuple[float, float]:
    """Signed area of Φ_{t0→t}(box) for one degree of freedom, and an estimate of its error.

    The box boundary (`per_side` points per side, a multiple of 4) is mapped once, and the
    shoelace areas A_N, A_{N/2}, A_{N/4} of all, every second and every fourth point are
    Romberg-extrapolated: a polygon inscribed in smooth arcs errs by c₂N⁻² + c₄N⁻⁴ + …, so
    R = (4A_N − A_{N/2})/3 and R' = (4A_{N/2} − A_{N/4})/3 err by O(N⁻⁴) and
    (16R − R')/15 by O(N⁻⁶); |R − R'|/15 estimates the error left. The boundary is refined
    (doubled) until that estimate is below 1e-9 of the area; for a linear flow (a
    parallelogram) the first pass is exact to rounding."""
    if flow.n != 1:
        raise UnsupportedError("phase-space area of more than one degree of freedom")
    per_side = 4 * max(1, per_side // 4)
    while True:
        q, p = box_boundary(lo, hi, per_side)
        Q, P = flow.map(values, q, p, t, t0)
        a1, a2, a4 = (shoelace(Q[::k], P[::k]) for k in (1, 2, 4))
        r1, r2 = (4 * a1 - a2) / 3, (4 * a2 - a4) / 3
        area, err = (16 * r1 - r2) / 15, abs(r1 - r2) / 15
        if err <= 1e-9 * abs(area) or per_side >= max_per_side:
            return area, err
        per_side *= 2


def box_surface(lo, hi, count: int, rng: np.random.Generator) -> np.ndarray:
    """Points on the surface of a box in (q, p) space (2n dimensions): all corners (up to
    64) and `count` random points, each with one random coordinate pinned to a face."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    d = len(lo)
    pts = [lo + (hi - lo) * rng.uniform(size=d) for _ in range(count)]
    for x in pts:
        k = rng.integers(d)
        x[k] = lo[k] if rng.uniform() < 0.5 else hi[k]
    if d <= 6:
        for bits in range(2 ** d):
            pts.append(np.where([(bits >> k) & 1 for k in range(d)], hi, lo))
    return np.array(pts)


def image_bounds(flow: PhaseFlow, values: dict, lo, hi, t: float, t0: float = 0.0,
                 seed: int = 7) -> tuple[np.ndarray, np.ndarray]:
    """Bounding box of Φ_{t0→t}(box): the image of its boundary's bounding box (a flow maps
    boundary to boundary), from 200 points per side (n = 1) or 4000 surface points."""
    n = flow.n
    if n == 1:
        q, p = box_boundary(lo, hi, 200)
        X = np.column_stack((q, p))
    else:
        X = box_surface(lo, hi, 4000, np.random.default_rng(seed))
    Q, P = flow.map(values, X[:, :n], X[:, n:], t, t0)
    Y = np.column_stack((Q.reshape(len(X), n), P.reshape(len(X), n)))
    return Y.min(axis=0), Y.max(axis=0)


def in_box(X: np.ndarray, lo, hi, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """For points X (N, d): inside the open box, and within `margin` (a fraction of each
    side) of its boundary."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    tol = margin * (hi - lo)
    inside = np.all((X > lo) & (X < hi), axis=1)
    near = np.any((np.abs(X - lo) <= tol) | (np.abs(X - hi) <= tol), axis=1)
    return inside, near
