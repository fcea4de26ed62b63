"""Cross-check: normal frequencies measured from the nonlinear motion.

For a linear system the engine derived (about an equilibrium, or a steady motion by Routh's
reduction), the *nonlinear* equations of motion are integrated (DOP853, rtol 1e-12) from a
small displacement along each normal mode, and the frequency is measured from the
trajectory: upward zero crossings of the mode's own coordinate (uᵀM δq, or the left
eigenvector's projection of the state for gyroscopic or damped systems), located on the
dense output and fitted over several periods. It must agree with the engine's linear
frequency to REL_TOL. The amplitude is halved until two runs (a, a/2) differ by less than a
tenth of the tolerance, so the nonlinear shift is known to be below it. A steady motion is
simulated in full: the cyclic rates are solved so that the conserved momenta keep their
steady values, which checks Routh's reduction too. Zero-frequency modes must stay put (their
effective frequency below REL_TOL times the highest one); unstable modes and modes of a
non-autonomous system are reported not applicable.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import sympy as sp
from scipy.integrate import solve_ivp

from mechbook.engine.analysis import Analysis
from mechbook.engine.linear import ZERO_CLUSTER
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.numerics.model import Model, build_model
from mechbook.records import CrossCheck

REL_TOL = 1e-4  # required agreement of measured and linear frequencies (and decay rates)
DECAY_FLOOR = 1e-6  # a mode decaying slower than this (relative to ω) is not damped
SHIFT_TOL = 1e-5  # the nonlinear shift must be known to be below this
START_AMPLITUDE = 1e-3
PERIODS = 4

# ---- frequencies by simulation ---------------------------------------------------------------
@dataclass
class _Setup:
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


def _setup(analysis: Analysis, lin, values: dict, models: dict) -> _Setup:
    """Numeric matrices, the full nonlinear model and the reference state for `lin`."""
    sys_lin = lin.dyn.sys
    steady = hasattr(sys_lin, "base")
    base = sys_lin.base if steady else sys_lin
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
        cyclic = [base.q.index(c) for c in sys_lin.momenta]
        p_cyc = np.array([float(sp.N(sp.S(p).subs(values)))
                          for p in sys_lin.momenta.values()])
    setup = _Setup(model, q_star, v_star, idx, cyclic, p_cyc, M, C, K, engine)
    if getattr(lin, "embedding", None) is not None:
        setup.manifold = _manifold(base, idx, vals)
    if steady:
        setup.v_star = _with_cyclic_rates(setup, q_star, np.zeros(n))
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
    from mechbook.core.compile import compile_exprs

    cons = [f.subs(values) for _, f in base.constraints]
    A = sp.Matrix([[sp.diff(f, q) for q in base.q] for f in cons])
    g_num, _ = compile_exprs(base.q, cons)
    a_num, _ = compile_exprs(base.q, list(A))
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


def _with_cyclic_rates(s: _Setup, q: np.ndarray, v: np.ndarray) -> np.ndarray:
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


def _modes(s: _Setup) -> list[dict]:
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
        elif _defective(lam, V, j, scale):  # before `unstable`: rounding splits the root
            kind = "defective"
        elif lam[j].real > 1e-8 * scale:
            kind = "unstable"
        elif abs(lam[j].imag) <= 1e-9 * scale:
            kind = "overdamped"
        out.append({"omega": float(abs(lam[j].imag)), "kind": kind, "start": start,
                    "weights": np.conj(w), "complex": True, "decay": float(-lam[j].real)})
    return out


def _defective(lam: np.ndarray, V: np.ndarray, j: int, scale: float) -> bool:
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


def _signal(s: _Setup, mode: dict):
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


def _complex_signal(s: _Setup, mode: dict):
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


def _initial(s: _Setup, mode: dict, amplitude: float) -> np.ndarray:
    n_full = len(s.q_star)
    nl = len(s.index)
    q = s.q_star.copy()
    v = s.v_star.copy()
    q[s.index] += amplitude * mode["start"][:nl]
    v[s.index] += amplitude * mode["start"][nl:]
    if s.manifold is not None:
        q, v = s.manifold(q, v)
    v = _with_cyclic_rates(s, q, v)
    y = np.empty(2 * n_full)
    y[:n_full], y[n_full:] = q, v
    return y


def _measure(s: _Setup, mode: dict, amplitude: float, period: float) -> tuple[float, int]:
    """Frequency from upward zero crossings of the mode's signal over PERIODS periods."""
    g = _signal(s, mode)
    g.direction = 1.0
    y0 = _initial(s, mode, amplitude)
    scale = np.maximum(np.abs(y0), 1.0)
    sol = solve_ivp(s.model.rhs, (0.0, (PERIODS + 1) * period), y0, method="DOP853",
                    rtol=1e-12, atol=1e-13 * amplitude * scale, events=[g])
    if not sol.success:
        raise MechbookError(f"integration failed: {sol.message}")
    times = np.asarray(sol.t_events[0])
    if len(times) < 3:
        raise MechbookError(f"only {len(times)} zero crossings in {PERIODS + 1} linear periods")
    j = np.arange(len(times))
    slope = np.polyfit(j, times, 1)[0]
    return 2 * np.pi / slope, len(times)


def _zero_mode(s: _Setup, mode: dict, amplitude: float, horizon: float) -> float:
    """Effective frequency of a zero mode: from how far it moves from rest in `horizon`
    (a mode of frequency ω would move back by 1 − cos ωT)."""
    g = _signal(s, mode)
    y0 = _initial(s, mode, amplitude)
    scale = np.maximum(np.abs(y0), 1.0)
    sol = solve_ivp(s.model.rhs, (0.0, horizon), y0, method="DOP853", rtol=1e-12,
                    atol=1e-13 * amplitude * scale, dense_output=True)
    if not sol.success:
        raise MechbookError(f"integration failed: {sol.message}")
    ts = np.linspace(0, horizon, 400)
    s0 = g(0.0, y0)
    moved = max(abs(g(t, sol.sol(t)) - s0) for t in ts) / max(abs(s0), 1e-300)
    return float(np.sqrt(2 * min(moved, 2.0)) / horizon)


def frequency_crosscheck(analysis: Analysis, lin, values: dict, name: str,
                         models: dict | None = None) -> CrossCheck:
    """Simulate the nonlinear system along each mode of `lin` and compare frequencies."""
    start = time.perf_counter()
    system_name = getattr(getattr(lin.dyn.sys, "base", lin.dyn.sys), "name", "main")
    out = CrossCheck(name, "frequencies", system_name)
    try:
        _frequency_crosscheck(analysis, lin, values, out, models if models is not None else {})
    except UnsupportedError as exc:
        out.status, out.detail = "n.a.", exc.capability
    except (MechbookError, np.linalg.LinAlgError, ValueError, TypeError,
            ZeroDivisionError) as exc:
        out.status, out.detail = "error", f"{type(exc).__name__}: {exc}"
    out.seconds = time.perf_counter() - start
    return out


def _frequency_crosscheck(analysis, lin, values, out: CrossCheck, models: dict) -> None:
    s = _setup(analysis, lin, values, models)
    model = s.model
    n_full = len(s.q_star)
    y_star = np.concatenate((s.q_star, s.v_star))
    with np.errstate(all="ignore"):
        d0 = model.rhs(0.0, y_star)
        y_probe = _initial(s, _modes(s)[0], START_AMPLITUDE) if s.index else y_star
        p0, p1 = model.rhs(0.0, y_probe), model.rhs(1.234567, y_probe)
    if not (np.all(np.isfinite(d0)) and np.all(np.isfinite(p0))):
        raise MechbookError("the equations of motion do not evaluate at the point")
    if not np.allclose(p0, p1, rtol=1e-12, atol=1e-12 * max(1.0, np.abs(p0).max())):
        raise UnsupportedError("frequency cross-check: the equations are not autonomous at "
                               "the default parameters (time-dependent coefficients)")
    modes = _modes(s)
    growing = _unstable_modes(s)
    if growing:  # an unstable point: the simulation confirms the growth, not frequencies
        _crosscheck_growth(s, growing, out)
        return
    live = [m["omega"] for m in modes if not m["kind"] and m["omega"] > 0]
    if not live:
        kinds = sorted({m["kind"] or "?" for m in modes})
        raise UnsupportedError(f"no oscillating mode to measure ({', '.join(kinds)})")
    w_max, w_min = max(live), min(live)
    acc = d0[n_full:]
    if np.max(np.abs(acc)) > 1e-7 * w_max**2 * max(1.0, float(np.max(np.abs(s.q_star)))):
        out.status = "fail"
        out.error = float("inf")
        out.detail = (f"not an equilibrium of the nonlinear equations: |q̈| = "
                      f"{np.max(np.abs(acc)):.3g} at the point")
        return
    worst, notes, failed = 0.0, [], False
    for k, mode in enumerate(modes):
        entry = {"mode": k, "linear": mode["omega"], "kind": mode["kind"] or "oscillation"}
        if mode["kind"] in ("unstable", "overdamped"):
            entry["status"] = "n.a."
            notes.append(f"mode {k}: {mode['kind']}, no oscillation to measure")
        elif mode["kind"] == "defective":
            entry["status"] = "n.a."
            notes.append(f"mode {k}: a double exponent with one mode (secular growth at a "
                         "stability boundary), no oscillation of fixed amplitude to measure")
        elif mode["kind"] == "zero":
            if mode.get("complex"):
                entry["status"] = "n.a."
                notes.append(f"mode {k}: zero frequency of a gyroscopic system")
            else:
                horizon = 2 * np.pi / w_min * 2
                w_eff = _zero_mode(s, mode, START_AMPLITUDE, horizon)
                rel = w_eff / w_max
                entry.update({"measured": w_eff, "relative_error": rel,
                              "status": "pass" if rel < REL_TOL else "fail"})
                failed |= rel >= REL_TOL
                worst = max(worst, rel)
        else:
            entry.update(_measure_mode(s, mode))
            rel = entry["relative_error"]
            ok = rel < REL_TOL and entry["shift"] < SHIFT_TOL
            if mode.get("decay", 0.0) > DECAY_FLOOR * mode["omega"]:  # a damped mode
                entry.update(_measure_decay(s, mode))
                ok &= entry["decay_error"] < REL_TOL
                rel = max(rel, entry["decay_error"])
            entry["status"] = "pass" if ok else "fail"
            failed |= not ok
            worst = max(worst, rel)
        out.modes.append(entry)
    out.error = worst
    measured = [m for m in out.modes if "measured" in m and m["kind"] != "zero"]
    zeros = [m for m in out.modes if m["kind"] == "zero" and "measured" in m]
    bits = [f"ω {m['engine']:.6g}: measured {m['measured']:.10g} (rel {m['relative_error']:.1e},"
            f" amplitude {m['amplitude']:.0e}, shift {m['shift']:.0e}, extrapolated rel "
            f"{m['extrapolated_error']:.0e})"
            + (f", decay rate {m['decay']:.6g}: measured {m['decay_measured']:.10g} (rel "
               f"{m['decay_error']:.1e})" if "decay_measured" in m else "")
            for m in measured]
    bits += [f"zero mode stays (ω_eff/ω_max {m['relative_error']:.0e})" for m in zeros]
    out.detail = "; ".join(bits + notes)
    out.status = "fail" if failed else ("pass" if measured else "n.a.")


def _measure_mode(s: _Setup, mode: dict) -> dict:
    """Measure at amplitudes a and a/2, shrinking a until the two agree (nonlinear shift)."""
    omega = mode["omega"]
    period = 2 * np.pi / omega
    nearest = float(s.engine[np.argmin(np.abs(s.engine - omega))]) if len(s.engine) else omega
    a = START_AMPLITUDE
    for _ in range(8):
        w1, _ = _measure(s, mode, a, period)
        w2, crossings = _measure(s, mode, a / 2, period)
        shift = abs(w1 - w2) / omega / 3  # ω(a) − ω0 ∝ a²: the shift left at a/2
        if shift < SHIFT_TOL / 10:
            break
        a /= 4
    extrapolated = w2 - (w1 - w2) / 3  # Richardson: remove the a² shift
    return {"measured": w2, "engine": nearest, "relative_error": abs(w2 - nearest) / nearest,
            "amplitude": a / 2, "shift": shift, "crossings": crossings,
            "extrapolated": extrapolated,
            "extrapolated_error": abs(extrapolated - nearest) / nearest}


def _measure_decay(s: _Setup, mode: dict) -> dict:
    """The decay rate of a damped mode measured from the nonlinear motion: the modulus of
    the complex modal amplitude w·(y − y*) along the trajectory started in the mode, fitted
    as log|z| = log|z0| − γt over PERIODS periods (at two amplitudes, a and a/2, like the
    frequency: the nonlinear part of the decay is known to be below their difference)."""
    gamma = mode["decay"]
    period = 2 * np.pi / mode["omega"]
    horizon = min(PERIODS * period, 3.0 / gamma)  # a few e-foldings at most
    z = _complex_signal(s, mode)
    rates = []
    for a in (START_AMPLITUDE, START_AMPLITUDE / 2):
        y0 = _initial(s, mode, a)
        scale = np.maximum(np.abs(y0), 1.0)
        sol = solve_ivp(s.model.rhs, (0.0, horizon), y0, method="DOP853", rtol=1e-12,
                        atol=1e-13 * a * scale, dense_output=True)
        if not sol.success:
            raise MechbookError(f"integration failed: {sol.message}")
        ts = np.linspace(0.0, horizon, 200)
        logs = np.log([abs(z(t, sol.sol(t))) for t in ts])
        rates.append(-float(np.polyfit(ts, logs, 1)[0]))
    return {"decay": gamma, "decay_measured": rates[1],
            "decay_error": abs(rates[1] - gamma) / max(gamma, 1e-300),
            "decay_shift": abs(rates[0] - rates[1]) / max(gamma, 1e-300)}


def _unstable_modes(s: _Setup) -> list[dict]:
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


def _crosscheck_growth(s: _Setup, growing: list[dict], out: CrossCheck) -> None:
    """Each unstable mode's growth rate measured from the nonlinear motion started in it:
    log|w·(y − y*)| fitted over three e-foldings (small amplitude: the growth stays linear)."""
    worst, bits = 0.0, []
    for k, mode in enumerate(growing):
        gamma = mode["growth"]
        z = _complex_signal(s, mode)
        horizon = 3.0 / gamma
        a = START_AMPLITUDE / 10
        y0 = _initial(s, mode, a)
        sol = solve_ivp(s.model.rhs, (0.0, horizon), y0, method="DOP853", rtol=1e-12,
                        atol=1e-13 * a * np.maximum(np.abs(y0), 1.0), dense_output=True)
        if not sol.success:
            raise MechbookError(f"integration failed: {sol.message}")
        ts = np.linspace(0.0, horizon, 200)
        rate = float(np.polyfit(ts, np.log([abs(z(t, sol.sol(t))) for t in ts]), 1)[0])
        rel = abs(rate - gamma) / gamma
        worst = max(worst, rel)
        out.modes.append({"mode": k, "kind": "unstable", "growth": gamma,
                          "growth_measured": rate, "relative_error": rel,
                          "status": "pass" if rel < REL_TOL * 10 else "fail"})
        bits.append(f"growth rate {gamma:.6g}: measured {rate:.10g} (rel {rel:.1e})")
    out.error = worst
    out.status = "pass" if worst < REL_TOL * 10 else "fail"
    out.detail = "unstable: " + "; ".join(bits) + " (oscillating modes not measured: the " \
        "motion leaves the point)"
