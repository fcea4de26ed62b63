"""Linear response of a linearized system M·δq̈ + C·δq̇ + K·δq = F(t) at numeric parameters.

What a damped, gyroscopic or driven system's answers are about, beyond real normal modes:

    eigenpairs        the exponents p of solutions e^{pt}·u (roots of det(Mp² + Cp + K) = 0),
                      complex in general, and their complex mode vectors u
    decay_rates       −Re p, one per oscillating mode (a conjugate pair), one per real root
    forcing_phasor    F̂ with F(t) = Re(F̂ e^{iωt}) when the force is harmonic at ω
    harmonic_response X = (K − ω²M + iωC)⁻¹F̂: the steady state δq = Re(X e^{iωt})
    motion            the solution of the initial-value problem at given times (driven or
                      not, damped or gyroscopic): the matrix exponential without a force,
                      DOP853 at rtol 1e-13 with one
    jordan_size       the largest Jordan block of an exponent: t^(k−1)·e^{pt} terms (secular
                      growth at a multiple root)

Eigenvalues are computed in double precision and, where the matrices are ill-conditioned or
an answer asks for many digits, in mpmath at `dps` digits (`precise=True`).
"""

from __future__ import annotations

import mpmath
import numpy as np
import scipy.linalg
import sympy as sp
from scipy.integrate import solve_ivp

from mechbook.core.compile import compile_exprs
from mechbook.engine.linear import LinearSystem
from mechbook.errors import UnsupportedError

DPS = 40  # digits of the precise (mpmath) eigensolver


def state_matrix(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray:
    """A of ẏ = A·y, y = (δq, δq̇)."""
    n = M.shape[0]
    return np.block([[np.zeros((n, n)), np.eye(n)],
                     [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])


def eigenpairs(lin: LinearSystem, values: dict, precise: bool = False,
               dps: int = DPS) -> tuple[np.ndarray, np.ndarray]:
    """All 2n exponents p (complex, sorted by imaginary then real part) and the displacement
    parts of their eigenvectors (columns, each scaled to unit norm)."""
    n = len(lin.q)
    if precise:
        with mpmath.workdps(dps):
            A = lin.mp_state_matrix(values, dps)
            lam, V = mpmath.eig(A)
            lam = np.array([complex(x) for x in lam])
            V = np.array([[complex(V[i, j]) for j in range(2 * n)] for i in range(2 * n)])
    else:
        M, C, K = lin.matrices(values)
        lam, V = scipy.linalg.eig(state_matrix(M, C, K))
    order = np.lexsort((lam.real, -lam.imag))
    lam, U = lam[order], V[:n, order]
    norms = np.linalg.norm(U, axis=0)
    U = U / np.where(norms > 0, norms, 1.0)
    return lam, U


def exponents(lin: LinearSystem, values: dict, precise: bool = False) -> np.ndarray:
    """The 2n exponents p of e^{pt} solutions (a first-order system's: one per state)."""
    if lin.first_order:
        return lin.exponents(values, precise)
    return eigenpairs(lin, values, precise)[0]


def decay_rates(lin: LinearSystem, values: dict) -> np.ndarray:
    """−Re p: one per complex-conjugate pair (Im p > 0), one per real root."""
    lam = exponents(lin, values)
    scale = max(1e-300, float(np.max(np.abs(lam))))
    keep = [x for x in lam if x.imag >= -1e-9 * scale]
    pairs = [x for x in keep if x.imag > 1e-9 * scale]
    real = [x for x in keep if abs(x.imag) <= 1e-9 * scale]
    return np.sort(np.array([-x.real for x in pairs + real]))


def forcing_phasor(lin: LinearSystem, values: dict, omega: float) -> np.ndarray:
    """F̂ with F(t) = Re(F̂ e^{iωt}), read from F at t = 0 and a quarter period, and
    confirmed at two more times (UnsupportedError if F is not harmonic at ω)."""
    t = lin.dyn.sys.t
    F = [f.subs(values) for f in lin.F]

    def at(tv: float) -> np.ndarray:
        return np.array([complex(sp.N(f.subs(t, tv), 30)) for f in F]).real

    quarter = np.pi / (2 * omega)
    a, b = at(0.0), at(quarter)
    phasor = a - 1j * b
    for tv in (0.37 / omega, 2.9 / omega):
        expect = (phasor * np.exp(1j * omega * tv)).real
        if np.max(np.abs(at(tv) - expect)) > 1e-9 * max(1e-300, float(np.max(np.abs(phasor)))):
            raise UnsupportedError("steady response: the force is not harmonic at the given "
                                   "driving frequency")
    return phasor


def harmonic_response(lin: LinearSystem, values: dict, omega: float) -> np.ndarray:
    """X with the steady state δq = Re(X e^{iωt}) for F(t) = Re(F̂ e^{iωt})."""
    M, C, K = lin.matrices(values)
    H = K - omega**2 * M + 1j * omega * C
    return np.linalg.solve(H, forcing_phasor(lin, values, omega))


def motion(lin: LinearSystem, values: dict, q0: np.ndarray, v0: np.ndarray,
           times: list[float]) -> np.ndarray:
    """δq at `times` (rows) from δq(0) = q0, δq̇(0) = v0, for the full linear system."""
    if any(x.has(lin.dyn.sys.t) for A in (lin.M, lin.C, lin.K) for x in A):
        raise UnsupportedError("initial-value solution with time-dependent coefficients")
    M, C, K = lin.matrices(values)
    n = M.shape[0]
    A = state_matrix(M, C, K)
    y0 = np.concatenate((q0, v0))
    if not lin.driven:
        return np.array([(scipy.linalg.expm(A * tv) @ y0)[:n] for tv in times])
    t = lin.dyn.sys.t
    force, _ = compile_exprs([t], [sp.N(f.subs(values), 30) for f in lin.F])
    Minv = np.linalg.inv(M)

    def rhs(tv, y):
        acc = Minv @ np.asarray(force(np.array([tv])), float)
        return A @ y + np.concatenate((np.zeros(n), acc))

    scale = max(1e-300, float(np.max(np.abs(y0))) if np.any(y0) else 0.0,
                float(np.max(np.abs(Minv @ np.asarray(force(np.array([0.0])), float)))))
    sol = solve_ivp(rhs, (0.0, max(times)), y0, method="DOP853", rtol=1e-13,
                    atol=1e-16 * scale, t_eval=sorted(times), dense_output=False)
    if not sol.success:
        raise UnsupportedError(f"integrating the linear system: {sol.message}")
    by_time = {tv: sol.y[:n, i] for i, tv in enumerate(sol.t)}
    return np.array([by_time[tv] for tv in times])


def jordan_size(lin: LinearSystem, values: dict, p: complex, dps: int = DPS) -> int:
    """The size of the largest Jordan block of the state matrix at the exponent `p`
    (1: plain e^{pt}; k: terms up to t^(k−1)·e^{pt}: secular growth). The exponents within
    10^(−dps/4) of p are one cluster (a multiple root split by rounding); with p their mean,
    the ranks of (A − pI)^j, a singular value below 10^(−dps/3) of the largest counting as
    zero, fall to 2n − (multiplicity) after as many steps as the largest block is long."""
    with mpmath.workdps(dps):
        A = lin.mp_state_matrix(values, dps)
        lam = mpmath.eig(A, left=False, right=False)
        near = [x for x in lam if abs(x - p) <= mpmath.mpf(10) ** (-dps // 4) * max(1, abs(p))]
        if not near:
            raise ValueError(f"{p} is not an exponent of the system")
        mult = len(near)
        N = A - (sum(near) / mult) * mpmath.eye(A.rows)
        power = mpmath.eye(A.rows)
        for j in range(1, mult + 1):
            power = power * N
            if _rank(power, dps) <= A.rows - mult:
                return j
        return mult


def _rank(A, dps: int) -> int:
    s = mpmath.svd(A, compute_uv=False)
    big = max(abs(x) for x in s)
    if big == 0:
        return 0
    tol = big * mpmath.mpf(10) ** (-dps // 3)
    return sum(1 for x in s if abs(x) > tol)


def commutator_residual(lin: LinearSystem, values: dict) -> float:
    """‖K M⁻¹ C − C M⁻¹ K‖ relative to its terms: zero exactly when M, C and K can be
    diagonalized by one congruence (Caughey and O'Kelly's condition; C symmetric)."""
    M, C, K = lin.matrices(values)
    if np.max(np.abs(C - C.T)) > 1e-12 * max(1e-300, float(np.max(np.abs(C)))):
        return float("inf")  # a gyroscopic (antisymmetric) part: no real congruence helps
    Minv = np.linalg.inv(M)
    a, b = K @ Minv @ C, C @ Minv @ K
    scale = np.linalg.norm(a) + np.linalg.norm(b)
    return float(np.linalg.norm(a - b) / scale) if scale > 0 else 0.0
