"""A linear system's normal modes, and how its coordinates sit in the full nonlinear model.

What the simulated-frequency cross-check (frequencies.py) and the finite-amplitude
measurement (amplitude.py) share: the numeric matrices M, C, K at the parameter values, the
compiled nonlinear model and the reference state (an equilibrium, or a steady motion held
at its momenta by Routh's reduction or kept in full), each mode's start and its own
coordinate (uᵀM δq, or the left eigenvector's projection of the state), and the unstable
modes' growth.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import sympy as sp

from mechbook.core.backends import FEW_CALLS_BACKEND
from mechbook.core.compile import compile_exprs
from mechbook.engine.analysis import Analysis
from mechbook.engine.linear import ZERO_CLUSTER, LinearSystem
from mechbook.errors import UnsupportedError
from mechbook.numerics.rhs import Model, build_model


@dataclass
class ModalSetup:
    """The linear system of a cross-check, and how its coordinates sit in the full model."""

    model: Model
    q_star: np.ndarray  # full model's configuration at the equilibrium / steady motion
    v_star: np.ndarray  # full model's velocities there
    index: list[int]  # model index of each coordinate of the linear system
    cyclic: list[int]  # model indices of cyclic coordinates held at fixed momenta
    p_cyclic: np.ndarray  # their momenta
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    engine: np.ndarray  # the engine's numeric frequencies
    turn: np.ndarray | None = None  # uniform rates of a steady motion kept in full (per
    # model coordinate): the reference state moves, q*(t) = q_star + turn*t
    # on a constraint manifold: (q, v) ↦ (q, v) with the dependent coordinates and rates
    # moved onto the constraints (the linear system's are the independent ones)
    manifold: object = None


def _float_values(values: dict) -> dict:
    return {k: float(v) for k, v in values.items()}


def modal_setup(analysis: Analysis, lin: LinearSystem, values: dict,
                models: dict) -> ModalSetup:
    """Numeric matrices, the full nonlinear model and the reference state for `lin`."""
    sys_lin = lin.dyn.sys
    steady = sys_lin.reduced  # about a steady motion, its cyclic momenta held
    base = sys_lin.full
    if any(m.has(base.t) for m in (lin.M, lin.C, lin.K)):
        raise UnsupportedError("frequency cross-check: the linearized equations have "
                               "time-dependent coefficients (not autonomous)")
    vals = _float_values(values)
    for s in base.small_params:
        vals[s] = 0.0
    key = (base.problem.id, base.name, tuple(sorted((str(k), v) for k, v in vals.items())))
    if key not in models:
        dyn = analysis.dynamics(base.name)
        models[key] = build_model(base, dyn, {k: v for k, v in vals.items()
                                              if k in set(base.problem.values())})
    model = models[key]
    M, C, K = lin.matrices(values)
    engine = np.asarray(lin.numeric_frequencies(values), dtype=float)
    idx = [base.q.index(q) for q in lin.q]
    n = len(base.q)
    q_star = np.zeros(n)
    for q in base.q:  # every coordinate: a dependent one has its own place on a manifold
        if q in lin.q or q in lin.point:
            q_star[base.q.index(q)] = float(sp.N(sp.S(lin.point.get(q, 0)).subs(values)))
    v_star = np.zeros(n)
    cyclic: list[int] = []
    p_cyc = np.zeros(0)
    if steady:
        cyclic = [base.q.index(c) for c in sys_lin.held_momenta]
        p_cyc = np.array([float(sp.N(sp.S(p).subs(values)))
                          for p in sys_lin.held_momenta.values()])
    setup = ModalSetup(model, q_star, v_star, idx, cyclic, p_cyc, M, C, K, engine)
    if lin.embedding is not None:  # on a constraint manifold
        setup.manifold = _manifold(base, idx, vals)
    if steady:
        setup.v_star = with_cyclic_rates(setup, q_star, np.zeros(n))
    if lin.velocity:  # a steady motion kept in all its coordinates (`reduce: false`)
        turn = np.zeros(n)
        for q, rate in lin.velocity.items():
            turn[base.q.index(q)] = float(sp.N(sp.S(rate).subs(values)))
        setup.turn = turn
        setup.v_star = turn.copy()
    return setup


def _manifold(base, independent: list[int], values: dict):
    """(q, v) ↦ (q, v) on the constraints g(q) = 0, A(q)·v = 0: the dependent coordinates
    by Newton's method from where they are, their rates solved from the others'. A start
    displaced along a mode of the linear system is first order; on the constraints exactly,
    the simulated system is the one whose frequencies are compared."""
    cons = [f.subs(values) for _, f in base.constraints]
    A = sp.Matrix([[sp.diff(f, q) for q in base.q] for f in cons])
    g_num, _ = compile_exprs(base.q, cons, FEW_CALLS_BACKEND)  # a few Newton steps per start
    a_num, _ = compile_exprs(base.q, list(A), FEW_CALLS_BACKEND)
    n, m = len(base.q), len(cons)
    dep = [i for i in range(n) if i not in independent]

    def project(q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        q, v = q.copy(), v.copy()
        scale = max(1.0, float(np.max(np.abs(q))))
        for _ in range(50):
            r = np.asarray(g_num(q), float)
            if np.max(np.abs(r)) <= 1e-15 * scale:
                break
            J = np.asarray(a_num(q), float).reshape(m, n)
            q[dep] -= np.linalg.solve(J[:, dep], r)
        J = np.asarray(a_num(q), float).reshape(m, n)
        v[dep] = -np.linalg.solve(J[:, dep], J[:, independent] @ v[independent])
        return q, v

    return project


def with_cyclic_rates(s: ModalSetup, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v with the cyclic rates chosen so that the cyclic momenta equal s.p_cyclic."""
    if not s.cyclic:
        return v
    v = v.copy()
    ML, b, _ = s.model.canonical_parts(0.0, q, v)
    c = s.cyclic
    others = [i for i in range(len(v)) if i not in c]
    rhs = s.p_cyclic - b[c] - ML[np.ix_(c, others)] @ v[others]
    v[c] = np.linalg.solve(ML[np.ix_(c, c)], rhs)
    return v


def normal_modes(s: ModalSetup) -> list[dict]:
    """Each mode: frequency, the initial displacement of the linear system's state
    (δq, δq̇) per unit amplitude, and the weights of the signal w·(δq, δq̇)."""
    n = len(s.index)
    out = []
    if not np.any(s.C):
        w2, U = scipy.linalg.eigh(s.K, s.M)
        scale = max(1e-300, float(np.max(np.abs(w2))))
        for k in range(n):
            u = U[:, k] / np.max(np.abs(U[:, k]))
            kind = "zero" if abs(w2[k]) <= 1e-9 * scale else ("unstable" if w2[k] < 0 else "")
            out.append({"omega": float(np.sqrt(max(w2[k], 0.0))), "kind": kind,
                        "start": np.concatenate((u, np.zeros(n))),
                        "weights": np.concatenate((s.M @ u, np.zeros(n)))})
        return out
    Minv = np.linalg.inv(s.M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ s.K, -Minv @ s.C]])
    lam, W, V = scipy.linalg.eig(A, left=True, right=True)
    scale = max(1e-300, float(np.max(np.abs(lam))))
    used = []
    for j in np.argsort(-lam.imag):
        if len(used) == n:
            break
        if lam[j].imag < -1e-9 * scale:
            continue
        used.append(j)
        v = V[:, j]
        big = int(np.argmax(np.abs(v[:n])))
        v = v * np.exp(-1j * np.angle(v[big]))  # phase: largest displacement real, > 0
        w = W[:, j] / np.conj(np.vdot(W[:, j], v))  # left eigenvector with wᴴv = 1
        start = v.real / max(1e-300, float(np.max(np.abs(v.real[:n]))))
        kind = ""
        if abs(lam[j]) <= ZERO_CLUSTER * scale:  # a zero exponent split by rounding
            kind = "zero"
        elif defective(lam, V, j, scale):  # before `unstable`: rounding splits the root
            kind = "defective"
        elif lam[j].real > 1e-8 * scale:
            kind = "unstable"
        elif abs(lam[j].imag) <= 1e-9 * scale:
            kind = "overdamped"
        out.append({"omega": float(abs(lam[j].imag)), "kind": kind, "start": start,
                    "weights": np.conj(w), "complex": True, "decay": float(-lam[j].real)})
    return out


def defective(lam: np.ndarray, V: np.ndarray, j: int, scale: float) -> bool:
    """Is exponent j a multiple root with a single eigenvector (a Jordan block: a stability
    boundary, where solutions grow like t·e^{pt})? Rounding splits the root by about the
    square root of the machine precision and leaves the two computed eigenvectors parallel
    to the same order; an oscillation of fixed amplitude does not exist there to measure."""
    v = V[:, j] / np.linalg.norm(V[:, j])
    for i in range(len(lam)):
        if i != j and abs(lam[i] - lam[j]) <= 1e-6 * scale:
            u = V[:, i] / np.linalg.norm(V[:, i])
            if abs(np.vdot(u, v)) >= 1 - 1e-6:
                return True
    return False


def mode_signal(s: ModalSetup, mode: dict) -> Callable[[float, np.ndarray], float]:
    """w·(y − y*) on the linear system's coordinates, as a function of the model state."""
    n_full = len(s.q_star)
    idx = np.array(s.index)
    weights = mode["weights"]
    nl = len(idx)
    wq, wv = weights[:nl], weights[nl:]
    q_star, v_star = s.q_star[idx], s.v_star[idx]
    turn = s.turn[idx] if s.turn is not None else np.zeros(nl)

    def g(t, y):
        val = np.dot(wq, y[idx] - q_star - turn * t) + np.dot(wv, y[n_full + idx] - v_star)
        return float(np.real(val))

    return g


def complex_mode_signal(s: ModalSetup,
                        mode: dict) -> Callable[[float, np.ndarray], complex]:
    """The complex modal amplitude w·(y − y*(t)) (its modulus decays like e^{Re p t})."""
    n_full = len(s.q_star)
    idx = np.array(s.index)
    nl = len(idx)
    wq, wv = mode["weights"][:nl], mode["weights"][nl:]
    turn = s.turn[idx] if s.turn is not None else np.zeros(nl)

    def z(t, y):
        return complex(np.dot(wq, y[idx] - s.q_star[idx] - turn * t)
                       + np.dot(wv, y[n_full + idx] - s.v_star[idx]))

    return z


def start_state(s: ModalSetup, mode: dict, amplitude: float) -> np.ndarray:
    n_full = len(s.q_star)
    nl = len(s.index)
    q = s.q_star.copy()
    v = s.v_star.copy()
    q[s.index] += amplitude * mode["start"][:nl]
    v[s.index] += amplitude * mode["start"][nl:]
    if s.manifold is not None:
        q, v = s.manifold(q, v)
    v = with_cyclic_rates(s, q, v)
    y = np.empty(2 * n_full)
    y[:n_full], y[n_full:] = q, v
    return y


def unstable_modes(s: ModalSetup) -> list[dict]:
    """The exponents with a positive real part (one per conjugate pair) and their modes,
    from the state-space eigenproblem (left eigenvectors give each mode's amplitude)."""
    n = len(s.index)
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-np.linalg.solve(s.M, s.K), -np.linalg.solve(s.M, s.C)]])
    lam, W, V = scipy.linalg.eig(A, left=True, right=True)
    scale = max(1e-300, float(np.max(np.abs(lam))))
    out = []
    for j in range(2 * n):
        if lam[j].real <= 1e-8 * scale or lam[j].imag < -1e-9 * scale:
            continue
        if abs(lam[j]) <= ZERO_CLUSTER * scale:
            continue
        v = V[:, j]
        big = int(np.argmax(np.abs(v[:n])))
        v = v * np.exp(-1j * np.angle(v[big]))
        w = W[:, j] / np.conj(np.vdot(W[:, j], v))
        start = v.real / max(1e-300, float(np.max(np.abs(v.real[:n]))))
        out.append({"omega": float(abs(lam[j].imag)), "growth": float(lam[j].real),
                    "kind": "unstable", "start": start, "weights": np.conj(w)})
    return out
