"""Equilibria, linearization and small oscillations.

The equations of motion E(q, q̇, q̈, t) = 0 are expanded to first order about a point q* with
q̇ = q̈ = 0, counting parameters declared `small` (a driving amplitude, say) as first-order too:
    M·δq̈ + C·δq̇ + K·δq = F(t),    δq = q − q*.
C holds gyroscopic (antisymmetric) and damping (symmetric) terms. With C = 0 the normal
frequencies are the roots of det(K − ω²M) = 0 and numerically `scipy.linalg.eigh(K, M)`; with
gyroscopic terms they are the roots of det(K − ω²M + iωC) = 0 and numerically the imaginary
parts of the state-space eigenvalues.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg
import scipy.optimize
import sympy as sp

from .errors import NotEquilibriumError, UnsupportedError
from .expansion import EPS, expand_lagrangian
from .lagrange import Dynamics
from .numeval import NotNumeric, evaluate, is_zero, without_absent
from .timeout import Timeout, time_limit, try_simplify

ZERO_TOL = 1e-9


@dataclass
class LinearSystem:
    """M·δq̈ + C·δq̇ + K·δq = F(t) about `point`."""

    dyn: Dynamics
    point: dict
    M: sp.Matrix
    C: sp.Matrix
    K: sp.Matrix
    F: sp.Matrix

    @property
    def q(self):
        return self.dyn.q

    def displacement(self) -> sp.Matrix:
        return sp.Matrix([q - self.point.get(q, 0) for q in self.q])

    def equations(self) -> list[sp.Expr]:
        """Linear equations (each = 0) in the original coordinate symbols."""
        dq = self.displacement()
        lhs = self.M * sp.Matrix(self.dyn.qdd) + self.C * sp.Matrix(self.dyn.qd) + self.K * dq
        return [sp.expand(e) for e in lhs - self.F]

    @cached_property
    def gyroscopic(self) -> bool:
        """C ≠ 0 (velocity terms: gyroscopic or damping), decided numerically."""
        return not all(is_zero(c) for c in self.C)

    @cached_property
    def driven(self) -> bool:
        """F(t) ≠ 0 (a force that does not depend on the displacements)."""
        return not all(is_zero(f) for f in self.F)

    # ---- symbolic frequencies ------------------------------------------------------------
    @cached_property
    def squared_frequencies(self) -> list[sp.Expr]:
        """Roots w = ω² of det(K − w M) = 0 with multiplicity (no gyroscopic terms)."""
        if self.gyroscopic:
            raise UnsupportedError("ω² roots of a gyroscopic system (use `frequencies`)")
        w = sp.Symbol("w")
        poly = sp.Poly(sp.factor((self.K - w * self.M).det()), w)
        try:
            with time_limit(30):
                roots = sp.roots(poly, w)
        except Timeout:
            roots = {}
        if sum(roots.values()) != poly.degree():
            raise UnsupportedError("closed-form roots of the secular equation")
        out = []
        for r, mult in roots.items():
            out += [try_simplify(r, 5)] * mult
        return out

    @cached_property
    def frequencies(self) -> list[sp.Expr]:
        """Symbolic normal angular frequencies ω ≥ 0 (with multiplicity)."""
        if not self.gyroscopic:
            return [try_simplify(sp.sqrt(r), 5) for r in self.squared_frequencies]
        om = sp.Symbol("omega_root", positive=True)
        det = sp.expand((self.K - om**2 * self.M + sp.I * om * self.C).det())
        n = len(self.q)
        try:
            with time_limit(30):
                roots = sp.roots(sp.Poly(det, om), om)
        except Timeout:
            roots = {}
        # keep the n roots that are real and non-negative at the default parameters
        values = self.dyn.sys.numeric_values()
        keep = []
        for r, mult in roots.items():
            v = complex(r.evalf(subs=values))
            if abs(v.imag) < 1e-9 * (1 + abs(v)) and v.real >= -1e-12:
                keep += [try_simplify(r, 5)] * mult
        if len(keep) != n:
            raise UnsupportedError("closed-form frequencies of a gyroscopic system")
        return keep

    # ---- numeric -------------------------------------------------------------------------
    def matrices(self, values: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        def num(A):
            return np.array(A.evalf(30, subs=values).tolist(), dtype=complex).real.astype(float)

        return num(self.M), num(self.C), num(self.K)

    def numeric_modes(self, values: dict) -> tuple[np.ndarray, np.ndarray]:
        """(ω², modes as columns) by the generalized symmetric eigensolver, M-normalized."""
        M, C, K = self.matrices(values)
        if np.any(C):
            raise UnsupportedError("real normal modes of a gyroscopic or damped system")
        w2, vecs = scipy.linalg.eigh(K, M)
        return w2, vecs

    def numeric_frequencies(self, values: dict) -> np.ndarray:
        """Normal angular frequencies at `values` (NaN marks an unstable, imaginary one).

        `scipy.linalg.eigh(K, M)` in double precision, after a diagonal scaling that makes
        M's diagonal one; when the problem is ill-conditioned there (cond(M) or the spread
        of the eigenvalues beyond 1e6, or gyroscopic terms spanning many decades) the
        eigenvalues are recomputed with 50-digit mpmath arithmetic (bench/extremes.py).
        """
        M, C, K = self.matrices(values)
        n = M.shape[0]
        if not np.any(C):
            d = 1.0 / np.sqrt(np.abs(np.diag(M)))
            Ms, Ks = M * np.outer(d, d), K * np.outer(d, d)
            w2 = scipy.linalg.eigh(Ks, Ms, eigvals_only=True)
            if _ill_conditioned(Ms, w2):
                w2 = self._precise_squared(values)
            scale = max(1e-300, float(np.max(np.abs(w2))))
            w2 = np.where(np.abs(w2) < ZERO_TOL * scale, 0.0, w2)
            return np.where(w2 >= 0, np.sqrt(np.abs(w2)), np.nan)
        Minv = np.linalg.inv(M)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
        lam = np.linalg.eigvals(A)
        mags = np.abs(lam[np.abs(lam) > 0])
        if np.linalg.cond(M) > 1e6 or (len(mags) and mags.max() > 1e6 * mags.min()):
            lam = self._precise_state_eigenvalues(values)
        lam = lam[np.argsort(-lam.imag)]
        return np.sort(np.abs(lam.imag[:n]))

    def _mp_matrices(self, values: dict, dps: int = 50):
        import mpmath

        def conv(A):
            return mpmath.matrix([[mpmath.mpf(str(sp.re(sp.N(x, dps)))) for x in row]
                                  for row in A.evalf(dps, subs=values).tolist()])

        return conv(self.M), conv(self.C), conv(self.K)

    def _precise_squared(self, values: dict, dps: int = 50) -> np.ndarray:
        """ω² by Cholesky reduction and a symmetric eigensolver in mpmath."""
        import mpmath

        with mpmath.workdps(dps):
            M, _, K = self._mp_matrices(values, dps)
            L = mpmath.cholesky(M)
            Linv = mpmath.inverse(L)
            A = Linv * K * Linv.T
            A = (A + A.T) / 2
            w2 = mpmath.eigsy(A, eigvals_only=True)
            return np.sort(np.array([float(x) for x in w2]))

    def _precise_state_eigenvalues(self, values: dict, dps: int = 50) -> np.ndarray:
        """Eigenvalues of the first-order (state-space) form in mpmath."""
        import mpmath

        with mpmath.workdps(dps):
            M, C, K = self._mp_matrices(values, dps)
            n = M.rows
            Minv = mpmath.inverse(M)
            A = mpmath.zeros(2 * n, 2 * n)
            MK, MC = -Minv * K, -Minv * C
            for i in range(n):
                A[i, n + i] = 1
                for j in range(n):
                    A[n + i, j] = MK[i, j]
                    A[n + i, n + j] = MC[i, j]
            lam = mpmath.eig(A, left=False, right=False)
            return np.array([complex(x) for x in lam])

    def numeric_stability(self, values: dict) -> str:
        """'stable', 'unstable' or 'marginal' from the linearized system at `values`."""
        M, C, K = self.matrices(values)
        n = M.shape[0]
        if not np.any(C):
            w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
            scale = max(1.0, float(np.max(np.abs(w2))))
            if np.any(w2 < -ZERO_TOL * scale):
                return "unstable"
            return "marginal" if np.any(np.abs(w2) <= ZERO_TOL * scale) else "stable"
        A = np.block([[np.zeros((n, n)), np.eye(n)],
                      [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
        re = np.linalg.eigvals(A).real
        scale = max(1.0, float(np.max(np.abs(np.linalg.eigvals(A)))))
        if np.any(re > 1e-8 * scale):
            return "unstable"
        return "stable"

    @cached_property
    def stability_condition(self) -> sp.Basic:
        """Sufficient and (without gyroscopic terms) necessary condition: K positive definite."""
        if self.gyroscopic:
            raise UnsupportedError("symbolic stability condition with gyroscopic terms")
        K = self.K
        minors = [try_simplify(K[:k, :k].det(), 5) for k in range(1, K.rows + 1)]
        return sp.And(*[mi > 0 for mi in minors])


def _ill_conditioned(M: np.ndarray, w2: np.ndarray) -> bool:
    nonzero = np.abs(w2[np.abs(w2) > 0])
    spread = nonzero.max() / nonzero.min() if len(nonzero) else 1.0
    return bool(np.linalg.cond(M) > 1e6 or spread > 1e6)


class Equilibria:
    """Static equilibria of a system (autonomous equations, q̇ = 0) and linearization."""

    def __init__(self, dyn: Dynamics):
        self.dyn = dyn
        self.sys = dyn.sys
        self._solved: list[dict] | None = None
        self._gave_up_at: float | None = None

    @cached_property
    def conditions(self) -> list[sp.Expr]:
        """E_i(q, 0, 0) with small parameters switched off: zero at an equilibrium."""
        if self.sys.constraints:
            raise UnsupportedError("equilibria of a system with multiplier constraints")
        zero = {v: 0 for v in self.dyn.qd + self.dyn.qdd}
        zero.update({s: 0 for s in self.sys.small_params})
        conds = [without_absent(e.subs(zero), [self.sys.t]) for e in self.dyn.residuals]
        if any(c.has(self.sys.t) for c in conds):
            raise UnsupportedError("static equilibria of a non-autonomous system")
        free = {s for syms in self.sys.free_driven for s in syms}
        if any(c.free_symbols & free for c in conds):
            raise UnsupportedError("static equilibria with an arbitrary driven coordinate")
        return conds

    SIMPLIFY_SECONDS = 5.0  # per condition, before solving
    SOLVE_SECONDS = 10.0

    @property
    def symbolic(self) -> list[dict]:
        """Equilibria SymPy can find in closed form (possibly incomplete for trig equations),
        with the full time limits: what an answer part asks for."""
        return self.within(None)

    def within(self, budget: float | None) -> list[dict]:
        """`symbolic`, but giving up (returning []) once `budget` seconds are spent on
        simplifying and solving: for searches no part asked for (the loose cross-checks).
        A result found once is kept; a search cut short is tried again with more time."""
        if self._solved is not None:
            return self._solved
        if budget is not None and self._gave_up_at is not None and budget <= self._gave_up_at:
            return []
        deadline = None if budget is None else time.monotonic() + budget

        def limit(cap: float) -> float:
            return cap if deadline is None else min(cap, deadline - time.monotonic())

        conds = []
        for c in self.conditions:  # simplified first: solve finds more this way
            seconds = limit(self.SIMPLIFY_SECONDS)
            if seconds <= 0:
                self._gave_up_at = budget
                return []
            conds.append(try_simplify(c, seconds))
        try:
            seconds = limit(self.SOLVE_SECONDS)
            if seconds <= 0:
                raise Timeout("no time left")
            with time_limit(seconds):
                sols = sp.solve(conds, self.dyn.q, dict=True)
        except (Timeout, NotImplementedError):
            if deadline is not None and time.monotonic() >= deadline - 1e-3:
                self._gave_up_at = budget  # cut short by the budget: may retry with more
                return []
            self._solved = []
            return []
        self._solved = [s for s in sols if len(s) == len(self.dyn.q)
                        and all(v.is_real is not False for v in s.values())]
        return self._solved

    def numeric(self, values: dict, search: dict | None = None,
                starts: int = 7) -> list[np.ndarray]:
        """Equilibria at `values` by root finding from a grid of starting points."""
        q = self.dyn.q
        conds = [c.subs(values) for c in self.conditions]
        F = sp.Matrix(conds)
        J = F.jacobian(q)
        f_num = sp.lambdify([q], list(F), modules="numpy")
        j_num = sp.lambdify([q], J.tolist(), modules="numpy")
        ranges = [search.get(v, (-np.pi, np.pi)) if search else (-np.pi, np.pi) for v in q]
        grids = [np.linspace(lo, hi, starts) for lo, hi in ranges]
        found: list[np.ndarray] = []
        mesh = np.array(np.meshgrid(*grids, indexing="ij")).reshape(len(q), -1).T
        if len(mesh) > 2000:
            mesh = mesh[np.random.default_rng(0).choice(len(mesh), 2000, replace=False)]
        for x0 in mesh:
            sol = scipy.optimize.root(lambda x: np.asarray(f_num(x), float), x0,
                                      jac=lambda x: np.asarray(j_num(x), float))
            if np.all(np.isfinite(sol.x)) and np.max(np.abs(f_num(sol.x))) < 1e-10:
                if not any(np.allclose(sol.x, f, atol=1e-7) for f in found):
                    found.append(sol.x)
        return found

    def quadratic_lagrangian(self, point: dict) -> sp.Expr:
        """L expanded to second order about `point` (see mechbook.expansion)."""
        dyn = self.dyn
        return expand_lagrangian(dyn.L, dyn.q, dyn.qd, point, self.sys.small_params, 2)

    def residual(self, point: dict) -> list[sp.Expr]:
        return [c.subs(point) for c in self.conditions]

    def linearize(self, point: dict) -> LinearSystem:
        """First-order expansion of the equations of motion about `point` (q̇ = 0)."""
        dyn = self.dyn
        sub = {}
        for q in dyn.q:
            sub[q] = point.get(q, sp.S.Zero) + EPS * q
        sub.update({v: EPS * v for v in dyn.qd + dyn.qdd})
        sub.update({s: EPS * s for s in self.sys.small_params})
        lin = []
        zeroth = []
        for e in dyn.residuals:
            e_sub = e.subs(sub, simultaneous=True)
            zeroth.append(e_sub.subs(EPS, 0))
            lin.append(sp.diff(e_sub, EPS).subs(EPS, 0))
        bad = [z for z in zeroth if not _is_zero(z, self.sys.numeric_values())]
        if bad:
            raise NotEquilibriumError(f"the point {_show(point)} is not an equilibrium (or steady "
                                      f"motion): a generalized force {sp.sstr(bad[0])[:120]} "
                                      "is left there")
        n = len(dyn.q)
        raw = {name: sp.Matrix(n, n, lambda i, j, v=v: sp.diff(lin[i], v[j]))
               for name, v in (("M", dyn.qdd), ("C", dyn.qd), ("K", dyn.q))}
        rest = sp.Matrix([lin[i] - sum((raw["M"][i, j] * dyn.qdd[j] + raw["C"][i, j] * dyn.qd[j]
                                        + raw["K"][i, j] * dyn.q[j]) for j in range(n))
                          for i in range(n)])
        t = [self.sys.t]
        state = t + dyn.q + dyn.qd + dyn.qdd  # F depends on t only, once terms cancel
        if dyn.simplify:
            def simp(x, absent=t):
                return try_simplify(without_absent(x, absent), 5)
        else:
            def simp(x, absent=t):
                return without_absent(x, absent)
        M, C, K = (raw[k].applyfunc(simp) for k in ("M", "C", "K"))
        F = (-rest).applyfunc(lambda x: simp(sp.expand(x), state))
        bad = set().union(*(x.free_symbols for x in F)) & set(dyn.q + dyn.qd + dyn.qdd)
        if bad:
            raise UnsupportedError("linearization: nonlinear remainder")  # pragma: no cover
        return LinearSystem(dyn, dict(point), M, C, K, F)


def _is_zero(expr: sp.Expr, values: dict, points: int = 5) -> bool:
    """Zero symbolically, or (when SymPy cannot tell) to 25 digits at random points around
    the default values; a residual left by a numerically found point is zero to 1e-9."""
    if expr == 0:
        return True
    if _numerically_zero(expr, values):
        return True
    rng = np.random.default_rng(7)
    for _ in range(points):
        env = {}
        for sym in expr.free_symbols:
            base = values.get(sym, 1.0)
            factor = float(np.exp(rng.uniform(-0.3, 0.3)))
            env[sym] = sp.Float(base * factor if sym.is_positive or sym not in values
                                else base + rng.uniform(-0.3, 0.3), 40)
        try:
            v, scale = evaluate(expr, env, 40)
        except (NotNumeric, TypeError, ValueError, ZeroDivisionError, OverflowError):
            return False
        if not abs(v) <= 1e-25 * max(scale, 1e-300):
            return False
    return True


def _numerically_zero(expr: sp.Expr, values: dict) -> bool:
    """A residual left by a numerically found point (floats), zero to rounding."""
    if not expr.has(sp.Float):
        return False
    try:
        return abs(evaluate(expr, {k: sp.Float(v, 30) for k, v in values.items()})[0]) < 1e-9
    except (NotNumeric, TypeError, ValueError, ZeroDivisionError, OverflowError):
        return False


def _show(point: dict) -> str:
    return "{" + ", ".join(f"{k} = {sp.sstr(v)}" for k, v in point.items()) + "}"
