"""Perturbation theory's objects, computed exactly (to many digits) so that a perturbation
formula can be judged against them as the small parameter goes to zero (Symon §12-5).

A system whose parameters include a small ε is split at ε = 0 (or at the `unperturbed`
parameter values a part names) into the unperturbed system and the rest:

    unperturbed   M, K (and C) at the unperturbed values; the unperturbed normal modes A
                  (columns, AᵀMA = 1) and squared frequencies W0 (ascending)
    W'            Aᵀ(K(ε) − K0)A: the perturbation coefficients in unperturbed normal
                  coordinates (the text's W'_jr); b = AᵀC(ε)A the friction coefficients
    exact         the eigenpairs of the perturbed system in those coordinates: W(ε) =
                  W0 + W' (symmetric), or the complex exponents of q̈ + b q̇ + W q = 0
    equilibrium   the perturbed equilibrium near the unperturbed one, and the stiffness
                  (Hessian of V) there, for perturbations whose first derivatives do not
                  vanish at the unperturbed point (Problem 12-11)

Everything is in mpmath at DPS digits: a third-order formula's error at ε = 1e-4 is near
1e-16 of the value, beyond double precision. The mass matrix must not depend on ε (the
text's perturbations are of the potential energy, or of the friction).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import mpmath
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate_mp
from mechbook.engine.linear import LinearSystem, mp_matrix, state_matrix
from mechbook.errors import UnsupportedError

DPS = 50


def _mp(A: sp.Matrix, values: dict):
    """A at `values` as an mpmath matrix (DPS digits and five guard digits)."""
    return mp_matrix(A, values, DPS + 5)


def generalized_eigh(K, M) -> tuple[list, mpmath.matrix]:
    """Eigenvalues (ascending) and M-orthonormal eigenvectors (columns) of K u = w M u."""
    with mpmath.workdps(DPS):
        L = mpmath.cholesky(M)
        Linv = mpmath.inverse(L)
        S = Linv * K * Linv.T
        S = (S + S.T) / 2
        w, V = mpmath.eigsy(S)
        order = sorted(range(len(w)), key=lambda i: w[i])
        U = Linv.T * V
        cols = mpmath.matrix(U.rows, U.cols)
        for new, old in enumerate(order):
            for i in range(U.rows):
                cols[i, new] = U[i, old]
        return [w[i] for i in order], cols


def precise_squared_frequencies(lin: LinearSystem, values: dict) -> list:
    """ω² of the linear system (no velocity terms), ascending, at DPS digits."""
    M, K = _mp(lin.M, values), _mp(lin.K, values)
    return generalized_eigh(K, M)[0]


def precise_exponents(lin: LinearSystem, values: dict) -> list:
    """The 2n exponents p of e^{pt} (state-space eigenvalues) at DPS digits."""
    if lin.first_order:
        return lin.precise_exponents(values, DPS)
    with mpmath.workdps(DPS):
        A = state_matrix(*(_mp(X, values) for X in (lin.M, lin.C, lin.K)))
        return list(mpmath.eig(A, left=False, right=False))


ZERO_MODE = mpmath.mpf(10) ** (20 - DPS)  # of the largest: a zero mode split by rounding


def precise_frequencies(lin: LinearSystem, values: dict) -> list:
    """Normal angular frequencies at DPS digits (NaN for an unstable ω² < 0); with velocity
    terms the imaginary parts of the exponents with Im p ≥ 0. A zero mode (a free
    translation, a cyclic coordinate kept), split by rounding to about 1e-50 of the
    largest ω², is exactly 0."""
    if lin.first_order:  # velocity constraints: the state matrix's own (engine.state_space)
        return lin.precise_frequencies(values, DPS)
    with mpmath.workdps(DPS):
        if not lin.gyroscopic:
            w2 = precise_squared_frequencies(lin, values)
            scale = max([abs(w) for w in w2] + [mpmath.mpf(10) ** -300])
            return [mpmath.mpf(0) if abs(w) <= ZERO_MODE * scale else
                    mpmath.sqrt(w) if w >= 0 else mpmath.nan for w in w2]
        lam = precise_exponents(lin, values)
        n = len(lin.q)
        lam = sorted(lam, key=lambda x: -mpmath.im(x))[:n]
        scale = max([abs(x) for x in lam] + [mpmath.mpf(10) ** -300])
        return sorted(mpmath.mpf(0) if abs(mpmath.im(x)) <= ZERO_MODE * scale else
                      abs(mpmath.im(x)) for x in lam)



def precise_modes(lin: LinearSystem, values: dict) -> tuple[list, mpmath.matrix]:
    """(ω² ascending, M-orthonormal modes as columns) at DPS digits (no velocity terms)."""
    if lin.gyroscopic:
        raise UnsupportedError("real normal modes of a gyroscopic or damped system")
    return generalized_eigh(_mp(lin.K, values), _mp(lin.M, values))


@dataclass
class Split:
    """A perturbed linear system in the unperturbed normal coordinates."""

    W0: list  # unperturbed squared frequencies, ascending
    A: mpmath.matrix  # unperturbed modes (columns, AᵀM0A = 1)
    Wp: mpmath.matrix  # AᵀK(ε)A − diag(W0)
    b: mpmath.matrix  # AᵀC(ε)A
    W: mpmath.matrix  # diag(W0) + W'


def split(lin: LinearSystem, values: dict, unperturbed: dict) -> Split:
    """The system at `values` seen in the normal coordinates of the system at `values`
    updated with `unperturbed` (e.g. {ε: 0})."""
    base = dict(values)
    base.update(unperturbed)
    with mpmath.workdps(DPS):
        M0, K0 = _mp(lin.M, base), _mp(lin.K, base)
        M, K, C = _mp(lin.M, values), _mp(lin.K, values), _mp(lin.C, values)
        if mpmath.mnorm(M - M0, 1) > mpmath.mpf(10) ** (-DPS + 10) * mpmath.mnorm(M0, 1):
            raise UnsupportedError("perturbation of the kinetic energy (the text's formulas "
                                   "perturb V, or the friction)")
        W0, A = generalized_eigh(K0, M0)
        W = A.T * K * A
        W = (W + W.T) / 2
        Wp = W - mpmath.diag(W0)
        b = A.T * C * A
        return Split(W0, A, Wp, b, W)


def exact_eigen(s: Split) -> tuple[list, mpmath.matrix]:
    """Eigenvalues (ascending) and unit eigenvectors (columns) of W = W0 + W'."""
    with mpmath.workdps(DPS):
        w, V = mpmath.eigsy(s.W)
        order = sorted(range(len(w)), key=lambda i: w[i])
        cols = mpmath.matrix(V.rows, V.cols)
        for new, old in enumerate(order):
            for i in range(V.rows):
                cols[i, new] = V[i, old]
        return [w[i] for i in order], cols


def exact_damped(s: Split, mode: int) -> tuple:
    """The exponent p of q̈ + b q̇ + W q = 0 nearest i·sqrt(W0[mode]) and its eigenvector
    (in unperturbed normal coordinates), scaled so its `mode` component is 1."""
    with mpmath.workdps(DPS):
        n = s.W.rows
        A = mpmath.zeros(2 * n, 2 * n)
        for i in range(n):
            A[i, n + i] = 1
            for j in range(n):
                A[n + i, j], A[n + i, n + j] = -s.W[i, j], -s.b[i, j]
        lam, V = mpmath.eig(A)
        target = mpmath.mpc(0, mpmath.sqrt(s.W0[mode]))
        k = min(range(2 * n), key=lambda i: abs(lam[i] - target))
        vec = [V[i, k] / V[mode, k] for i in range(n)]
        return lam[k], vec


def perturbed_equilibrium(V: sp.Expr, q: list, values: dict, start: dict) -> list:
    """The equilibrium of V (at `values`) found by Newton's method from `start`, at DPS
    digits (SymPy evaluates the gradient: the systems are small)."""
    x = [sp.Float(sp.N(sp.S(start.get(v, 0)).subs(values), DPS), DPS) for v in q]
    try:
        return _newton_mp(*potential_derivatives(V, tuple(q)), q, x, values)
    except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError):
        pass  # a function numeval does not know: SymPy evaluates
    grad = [sp.diff(V, x).subs(values) for x in q]
    hess = sp.Matrix(grad).jacobian(q)
    for _ in range(60):
        at = dict(zip(q, x, strict=True))
        g = sp.Matrix([sp.N(e.subs(at), DPS) for e in grad])
        H = hess.subs(at).evalf(DPS)
        step = H.LUsolve(g)
        x = [sp.Float(xi - si, DPS) for xi, si in zip(x, step, strict=True)]
        if max(abs(si) for si in step) < sp.Float(10) ** (-DPS + 10):
            break
    else:
        raise UnsupportedError("perturbed equilibrium: Newton's method did not converge")
    return [mpmath.mpf(xi._mpf_) for xi in x]


@lru_cache(maxsize=32)
def potential_derivatives(V: sp.Expr, q: tuple) -> tuple[list, sp.Matrix]:
    """∇V and its Hessian, symbolic (once per potential: a walk along a parameter evaluates
    them at many parameter values)."""
    grad = [sp.diff(V, x) for x in q]
    return grad, sp.Matrix(grad).jacobian(list(q))


@lru_cache(maxsize=32)
def third_derivatives(V: sp.Expr, q: tuple) -> list:
    """∂³V/∂q_k∂q_m∂q_i as nested lists [k][m][i], from the kept Hessian (once per
    potential, as `potential_derivatives`)."""
    hess = potential_derivatives(V, q)[1]
    n = len(q)
    return [[[sp.diff(hess[k, m], x) for x in q] for m in range(n)] for k in range(n)]


def _newton_mp(grad: list, hess: sp.Matrix, q: list, x: list, values: dict) -> list:
    """`perturbed_equilibrium`'s Newton iteration with the gradient and Hessian evaluated
    by numeval's one pass over each expression (mpmath at DPS digits) instead of SymPy's
    subs and evalf: the same steps at the same precision, ten times sooner."""
    n = len(q)
    with mpmath.workdps(DPS):
        xs = [mpmath.mpf(xi._mpf_) for xi in x]
        tol = mpmath.mpf(10) ** (-DPS + 10)
        for _ in range(60):
            at = dict(values)
            at.update(zip(q, xs, strict=True))
            g = mpmath.matrix([evaluate_mp(e, at, DPS) for e in grad])
            H = mpmath.matrix([[evaluate_mp(hess[i, j], at, DPS) for j in range(n)]
                               for i in range(n)])
            if any(mpmath.im(v) != 0 for v in list(g) + list(H)):
                raise ValueError("complex values")
            step = mpmath.lu_solve(H, g)
            xs = [xi - si for xi, si in zip(xs, step, strict=True)]
            if max(abs(si) for si in step) < tol:
                return xs
    raise UnsupportedError("perturbed equilibrium: Newton's method did not converge")
