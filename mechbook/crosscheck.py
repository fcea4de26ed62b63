"""Independent cross-checks of the engine, run beside the answer key's checks.

Two checks, neither of which looks at the book's answers:

* **Frequencies by simulation.** For every small-oscillation result — each linear system an
  answer part refers to (`frequencies`, `period`, `normal_modes`, …) and each stable
  equilibrium the engine derives — the *nonlinear* equations of motion are integrated
  (DOP853, rtol 1e-12) from a small displacement along each normal mode, and the frequency
  is measured from the trajectory: upward zero crossings of the mode's own coordinate
  (uᵀM δq, or the left eigenvector's projection of the state for gyroscopic or damped
  systems), located on the dense output and fitted over several periods. It must agree
  with the engine's linear frequency to REL_TOL at the default parameter values (the
  answer key's symbols and `assume:` honoured as in the checks; parameters flagged
  `small` set to zero). The amplitude is halved until two runs (a, a/2) differ by less
  than a tenth of the tolerance, so the nonlinear shift is known to be below it. A
  steady motion is simulated in full: the cyclic rates are solved so that the conserved
  momenta keep their steady values, which checks Routh's reduction too. Zero-frequency
  modes must stay put (their effective frequency below REL_TOL times the highest one);
  unstable modes and modes of a non-autonomous system are reported not applicable.

* **Newton's second law.** For a system built from particles and rigid bodies, the
  engine's Lagrange expressions E_i must equal Σ (∂r/∂q_i)·(m r̈ − F) over particles (F:
  gravity and two-ended springs, as Cartesian forces) plus, for rigid bodies, the Euler
  terms (∂ω/∂q̇_i)·(I ω̇ + ω × Iω); whatever the file gives other than as particles and
  bodies (`kinetic`, `potential`, `lagrangian`, `velocity_potential`, springs given by
  `length`, `forces`) enters through its own Lagrange expression, read from the file
  again. Compared at random states and accelerations (off-shell, so constraint forces do
  not enter) and perturbed parameters, to 1e-9 relative.

Outcomes: pass · fail · n.a. (does not apply, with the reason) · error (the check itself
could not run: counts as a fail).
"""

from __future__ import annotations

import time
import traceback
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import sympy as sp
from scipy.integrate import solve_ivp

from .analysis import Analysis
from .answers import AnswerKey
from .bodies import euler_body_rates, shape_inertia
from .errors import MechbookError, UnsupportedError
from .records import CrossCheck
from .simulate.rhs import Model, build_model, compile_exprs

REL_TOL = 1e-4  # required agreement of measured and linear frequencies
SHIFT_TOL = 1e-5  # the nonlinear shift must be known to be below this
NEWTON_TOL = 1e-9
START_AMPLITUDE = 1e-3
PERIODS = 4
FREQUENCY_QUANTITIES = ("frequencies", "period", "normal_modes", "normal_coordinates",
                        "mode_node")
EQUATION_QUANTITIES = ("lagrangian", "eom", "conserved", "constraint_force")
LOOSE_BUDGET = 3.0  # seconds for the engine's own closed-form equilibria (no part asks)


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
    for q in lin.q:
        q_star[base.q.index(q)] = float(sp.N(sp.S(lin.point.get(q, 0)).subs(values)))
    v_star = np.zeros(n)
    cyclic: list[int] = []
    p_cyc = np.zeros(0)
    if steady:
        cyclic = [base.q.index(c) for c in sys_lin.momenta]
        p_cyc = np.array([float(sp.N(sp.S(p).subs(values)))
                          for p in sys_lin.momenta.values()])
    setup = _Setup(model, q_star, v_star, idx, cyclic, p_cyc, M, C, K, engine)
    if steady:
        setup.v_star = _with_cyclic_rates(setup, q_star, np.zeros(n))
    return setup


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
        if abs(lam[j]) <= 1e-9 * scale:
            kind = "zero"
        elif lam[j].real > 1e-8 * scale:
            kind = "unstable"
        elif abs(lam[j].imag) <= 1e-9 * scale:
            kind = "overdamped"
        out.append({"omega": float(abs(lam[j].imag)), "kind": kind, "start": start,
                    "weights": np.conj(w), "complex": True})
    return out


def _signal(s: _Setup, mode: dict):
    """w·(y − y*) on the linear system's coordinates, as a function of the model state."""
    n_full = len(s.q_star)
    idx = np.array(s.index)
    weights = mode["weights"]
    nl = len(idx)
    wq, wv = weights[:nl], weights[nl:]
    q_star, v_star = s.q_star[idx], s.v_star[idx]

    def g(t, y):
        val = np.dot(wq, y[idx] - q_star) + np.dot(wv, y[n_full + idx] - v_star)
        return float(np.real(val))

    return g


def _initial(s: _Setup, mode: dict, amplitude: float) -> np.ndarray:
    n_full = len(s.q_star)
    nl = len(s.index)
    q = s.q_star.copy()
    v = s.v_star.copy()
    q[s.index] += amplitude * mode["start"][:nl]
    v[s.index] += amplitude * mode["start"][nl:]
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
            entry["status"] = "pass" if ok else "fail"
            failed |= not ok
            worst = max(worst, rel)
        out.modes.append(entry)
    out.error = worst
    measured = [m for m in out.modes if "measured" in m and m["kind"] != "zero"]
    zeros = [m for m in out.modes if m["kind"] == "zero" and "measured" in m]
    bits = [f"ω {m['engine']:.6g}: measured {m['measured']:.10g} (rel {m['relative_error']:.1e},"
            f" amplitude {m['amplitude']:.0e}, shift {m['shift']:.0e}, extrapolated rel "
            f"{m['extrapolated_error']:.0e})" for m in measured]
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


# ---- Newton's second law -----------------------------------------------------------------------
def newton_crosscheck(analysis: Analysis, system_name: str | None = None,
                      samples: int = 6) -> CrossCheck:
    """Lagrange's equations of the engine against Newton's (and Euler's) in Cartesian form."""
    start = time.perf_counter()
    sys = analysis.system(system_name)
    out = CrossCheck(f"newton:{sys.name}", "newton", sys.name)
    try:
        _newton(analysis, sys, out, samples)
    except UnsupportedError as exc:
        out.status, out.detail = "n.a.", exc.capability
    except (MechbookError, ValueError, TypeError, np.linalg.LinAlgError) as exc:
        out.status, out.detail = "error", f"{type(exc).__name__}: {exc}"
    out.seconds = time.perf_counter() - start
    return out


def _newton_residual(sys) -> list[sp.Expr]:
    """Σ J·(m r̈ − F) + rigid-body Euler terms + the Lagrange expressions of everything the
    file gives other than particles and bodies − Q."""
    spec = sys.spec
    if "approximation" in spec:
        raise UnsupportedError("Newton cross-check: the Lagrangian is an approximation "
                               "(Newton's law holds for the exact one)")
    particles = dict(spec.get("particles") or {})
    bodies = dict(spec.get("rigid_bodies") or {})
    if not particles and not bodies:
        raise UnsupportedError("Newton cross-check: no particle or body positions (T and V "
                               "are given directly)")
    parse = sys._parse  # the system's own safe parser, at the file's paths
    q, qd = sys.q, sys.qd
    n = len(q)
    forces: dict[str, sp.Matrix] = {}
    positions = {name: sys.positions[name] for name in list(particles) + list(bodies)}
    masses = {name: sys.masses[name] for name in positions}
    for name, r in positions.items():
        forces[name] = sp.zeros(r.rows, 1)
    if "gravity" in spec:
        grav = spec["gravity"] or {}
        g = parse(grav["g"], ("gravity", "g")) if "g" in grav else sys.params["g"].symbol
        for name, r in positions.items():
            up = (sp.Matrix([parse(x, ("gravity", "up", i)) for i, x in enumerate(grav["up"])])
                  if "up" in grav else sp.Matrix([0] * (r.rows - 1) + [1]))
            forces[name] += -masses[name] * g * up
    rest = sp.S.Zero  # Lagrangian terms not given as particles or bodies
    for i, spring in enumerate(spec.get("springs") or []):
        k = parse(spring["k"], ("springs", i, "k"))
        natural = (parse(spring["natural_length"], ("springs", i, "natural_length"))
                   if "natural_length" in spring else sp.S.Zero)
        if "length" in spring:
            length = parse(spring["length"], ("springs", i, "length"))
            rest -= k * (length - natural) ** 2 / 2
            continue
        ends = []
        for j, end in enumerate(spring["between"]):
            ends.append((end, positions[end]) if isinstance(end, str) else
                        (None, sp.Matrix([parse(x, ("springs", i, "between", j, m))
                                          for m, x in enumerate(end)])))
        d = ends[0][1] - ends[1][1]
        length = sp.sqrt(d.dot(d))
        pull = -k * (length - natural) / length * d  # force on the first end
        if ends[0][0] is not None:
            forces[ends[0][0]] += pull
        if ends[1][0] is not None:
            forces[ends[1][0]] -= pull
    for key in ("kinetic", "lagrangian"):
        if key in spec:
            rest += parse(spec[key], (key,))
    for key in ("potential", "velocity_potential"):
        if key in spec:
            rest -= parse(spec[key], (key,))
    res = [sp.S.Zero] * n
    for name, r in positions.items():
        acc = sys.dt(sys.dt(r))
        net = masses[name] * acc - forces[name]
        for i in range(n):
            res[i] += sp.diff(r, q[i]).dot(net)
    for name, b in bodies.items():
        rot = _euler_terms(sys, name, b, masses[name], parse)
        for i in range(n):
            res[i] += rot[i]
    for i in range(n):
        res[i] += sys.dt(sp.diff(rest, qd[i])) - sp.diff(rest, q[i]) - sys.forces[i]
    return res


def _euler_terms(sys, name: str, b: dict, m, parse) -> list[sp.Expr]:
    """(∂ω/∂q̇_i)·(I ω̇ + ω × Iω) (3-D, body axes) or (∂ω/∂q̇_i) I ω̇ (planar)."""
    sub = ("rigid_bodies", name)
    planar = len(b["position"]) == 2
    inertia = b["inertia"]
    if isinstance(inertia, dict):
        dims = {k: parse(v, sub + ("inertia", k)) for k, v in inertia.items()
                if k in ("radius", "length")}
        if "sides" in inertia:
            dims["sides"] = [parse(v, sub + ("inertia", "sides", i))
                             for i, v in enumerate(inertia["sides"])]
        tensor = shape_inertia(inertia["shape"], m, dims)
    elif isinstance(inertia, list):
        tensor = sp.Matrix([[parse(x, sub + ("inertia", i, j)) for j, x in enumerate(row)]
                            for i, row in enumerate(inertia)])
    else:
        tensor = parse(inertia, sub + ("inertia",))
    if planar:
        moment = tensor[2, 2] if isinstance(tensor, sp.MatrixBase) else tensor
        omega = parse(b["angular_velocity"], sub + ("angular_velocity",))
        return [sp.diff(omega, v) * moment * sys.dt(omega) for v in sys.qd]
    if "euler_angles" in b:
        angles = [parse(x, sub + ("euler_angles", i)) for i, x in enumerate(b["euler_angles"])]
        omega = euler_body_rates(angles, sys.dt)
    else:
        omega = sp.Matrix([parse(x, sub + ("angular_velocity", i))
                           for i, x in enumerate(b["angular_velocity"])])
    torque = tensor * sys.dt(omega) + omega.cross(tensor * omega)
    return [sp.diff(omega, v).dot(torque) for v in sys.qd]


def _newton(analysis: Analysis, sys, out: CrossCheck, samples: int) -> None:
    dyn = analysis.dynamics(sys.name)
    newton = _newton_residual(sys)
    engine = list(dyn.residuals)
    params = [p.symbol for p in sys.params.values()]
    free = [s for trio in sys.free_driven for s in trio]
    args = [sys.t, *sys.q, *sys.qd, *sys.qdd, *free, *params]
    exprs = engine + newton
    stray = set().union(*(e.free_symbols for e in exprs)) - set(args)
    if stray:
        raise UnsupportedError("Newton cross-check: symbols without values: "
                               + ", ".join(sorted(map(str, stray))))
    fn, _ = compile_exprs(args, exprs)
    n = len(sys.q)
    rng = np.random.default_rng(20261123)
    base = np.array([p.value for p in sys.params.values()])
    positive = np.array([p.positive for p in sys.params.values()])
    worst, used = 0.0, 0
    for _ in range(40 * samples):
        if used >= samples:
            break
        pv = np.where(positive, base * np.exp(rng.uniform(-0.3, 0.3, len(base))),
                      base + rng.uniform(-0.3, 0.3, len(base)))
        x = np.concatenate(([rng.uniform(0, 1)], rng.uniform(0.05, 0.6, n),
                            rng.uniform(-1, 1, 2 * n), rng.uniform(-1, 1, len(free)), pv))
        with np.errstate(all="ignore"):
            val = fn(x)
        if not np.all(np.isfinite(val)):
            continue
        e, nw = val[:n], val[n:]
        scale = max(float(np.max(np.abs(e))), float(np.max(np.abs(nw))), 1e-300)
        worst = max(worst, float(np.max(np.abs(e - nw))) / scale)
        used += 1
    if used < 3:
        raise MechbookError("Newton cross-check: the equations do not evaluate at random "
                            "states")
    out.error = worst
    out.status = "pass" if worst < NEWTON_TOL else "fail"
    what = []
    spec = sys.spec
    if spec.get("particles"):
        what.append("particles")
    if spec.get("rigid_bodies"):
        what.append("rigid bodies (Euler)")
    other = [k for k in ("kinetic", "potential", "lagrangian", "velocity_potential", "forces")
             if k in spec]
    if any("length" in s for s in spec.get("springs") or []):
        other.append("length springs")
    out.detail = (f"E = Jᵀ(m r̈ − F) over {' and '.join(what)} at {used} random states, "
                  f"max relative difference {worst:.1e}"
                  + (f"; as generalized forces: {', '.join(other)}" if other else ""))


# ---- one problem -------------------------------------------------------------------------------
def _numeric_key(lin, values: dict, params: set) -> tuple:
    """What makes two cross-checks the same: system, steady or not, the point and the
    parameter values, numerically (so `pi - acos(x)` and `acos(-x)` coincide)."""
    sys_lin = lin.dyn.sys
    steady = tuple(sorted(map(str, sys_lin.momenta))) if hasattr(sys_lin, "base") else ()
    point = []
    for q in lin.q:
        try:
            point.append(round(float(sp.N(sp.S(lin.point.get(q, 0)).subs(values))), 9))
        except (TypeError, ValueError):
            point.append(str(lin.point.get(q, 0)))
    pv = tuple(sorted((str(k), round(float(v), 12)) for k, v in values.items() if k in params))
    return (steady, tuple(point), pv)


def _point_label(lin) -> str:
    sys_lin = lin.dyn.sys
    pt = ", ".join(f"{q}: {sp.sstr(lin.point.get(q, 0))}" for q in lin.q)
    if hasattr(sys_lin, "base"):
        cyc = ", ".join(f"p_{c}" for c in sys_lin.momenta)
        return f"{{{pt}}} steady ({cyc} fixed)"
    return "{" + pt + "}"


def crosscheck_problem(analysis: Analysis, key: AnswerKey | None = None,
                       stage=lambda text: None) -> list[CrossCheck]:
    """Every cross-check of a problem: Newton per system, frequencies per linear system the
    answer key refers to and per stable equilibrium the engine derives. `stage` is told
    which check is running (a batch reports it if the problem runs out of time)."""
    from .checks import Context  # the answer parts' own reading of `about`/`steady`/`assume`

    problem = analysis.problem
    out: list[CrossCheck] = []
    newton: dict[str, CrossCheck] = {}
    for name in problem.systems:
        stage(f"cross-check newton:{name}")
        try:
            newton[name] = newton_crosscheck(analysis, name)
        except Exception as exc:  # a fault here must not hide the other checks
            newton[name] = CrossCheck(f"newton:{name}", "newton", name, "error",
                                      detail=_fault(exc))
    only = next(iter(problem.systems)) if len(problem.systems) == 1 else None
    freq: dict[tuple, CrossCheck] = {}
    models: dict = {}
    params = set(problem.values())
    for part in (key.parts if key else []):
        if "unsupported" in part.data:
            continue
        sname = part.system or only
        if part.quantity in EQUATION_QUANTITIES and sname in newton:
            newton[sname].parts.append(part.name)
        if part.quantity in ("conserved", "expression"):
            stage(f"cross-check conserved:{part.name}")
            x = _guarded_conserved(analysis, part, models)
            if x is not None:
                out.append(x)
        if part.quantity not in FREQUENCY_QUANTITIES:
            continue
        try:
            ctx = Context(analysis, part)
            lin = ctx.linear()
            values = ctx.sampler.default()
        except UnsupportedError as exc:
            tag = (sname, "n.a.", part.name)
            freq[tag] = CrossCheck(f"modes:{sname}", "frequencies", sname or "", "n.a.",
                                   detail=f"no linear system: {exc.capability}")
            freq[tag].parts.append(part.name)
            continue
        except Exception as exc:  # noqa: BLE001 - the part's own check reports it too
            tag = (sname, "error", part.name)
            freq[tag] = CrossCheck(f"modes:{sname}", "frequencies", sname or "", "error",
                                   detail=_fault(exc))
            freq[tag].parts.append(part.name)
            continue
        label = _point_label(lin)
        tag = (sname, *_numeric_key(lin, values, params))
        if tag not in freq:
            stage(f"cross-check modes:{sname}@{label}")
            freq[tag] = _guarded_frequency(analysis, lin, values, f"modes:{sname}@{label}",
                                           models)
        freq[tag].parts.append(part.name)
    for name in problem.systems:  # the engine's own stable equilibria
        stage(f"cross-check: the engine's own equilibria of {name}")
        try:
            engine_systems = _engine_linear_systems(analysis, name)
        except Exception as exc:  # noqa: BLE001 - reported, never hidden
            freq[(name, "engine-error")] = CrossCheck(f"modes:{name}", "frequencies", name,
                                                      "error", detail=_fault(exc))
            continue
        for lin, label in engine_systems:
            values = dict(problem.values())
            tag = (name, *_numeric_key(lin, values, params))
            if tag not in freq:
                stage(f"cross-check modes:{name}@{label}")
                freq[tag] = _guarded_frequency(analysis, lin, values, f"modes:{name}@{label}",
                                               models)
    out += list(newton.values()) + list(freq.values())
    return out


def _guarded_conserved(analysis: Analysis, part, models: dict) -> CrossCheck | None:
    """The simulation cross-check of a part's first integral (None: the part states none)."""
    from .checks import Context
    from .crosscheck_conserved import book_integrals, conserved_crosscheck

    start = time.perf_counter()
    x = CrossCheck(f"conserved:{part.name}", "conserved", part.system or "", "error",
                   parts=[part.name])
    try:
        ctx = Context(analysis, part)
        exprs = book_integrals(ctx)
        if not exprs:
            return None
        x.status, x.error, x.detail = conserved_crosscheck(analysis, ctx, exprs, models)
    except UnsupportedError as exc:
        x.status, x.detail = "n.a.", exc.capability
    except Exception as exc:  # noqa: BLE001 - reported, never hidden
        x.detail = _fault(exc)
    x.seconds = time.perf_counter() - start
    return x


def _fault(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc} [{traceback.format_exc(limit=-1).strip()}]"


def _guarded_frequency(analysis, lin, values, name, models) -> CrossCheck:
    try:
        return frequency_crosscheck(analysis, lin, values, name, models)
    except Exception as exc:  # a fault here must not hide the other checks
        return CrossCheck(name, "frequencies", "", "error", detail=_fault(exc))


def _engine_linear_systems(analysis: Analysis, name: str) -> list[tuple]:
    """Linear systems about the closed-form equilibria the engine derives for `name` (when
    the system asks for small oscillations), stable at the default values."""
    sys = analysis.system(name)
    compute = sys.spec.get("compute")
    if compute is not None and "small_oscillations" not in compute:
        return []
    out = []
    try:
        points = analysis.equilibria(name).within(LOOSE_BUDGET)
    except UnsupportedError:
        return []
    values = analysis.problem.values()
    for point in points:
        try:
            lin = analysis.linear(name, point)
            if lin.numeric_stability(values) != "stable" and not _marginal_ok(lin, values):
                continue
        except (UnsupportedError, TypeError, ValueError):
            continue
        out.append((lin, _point_label(lin)))
    return out


def _marginal_ok(lin, values) -> bool:
    """A marginal point (zero modes, e.g. a free translation) with the rest oscillating."""
    try:
        return lin.numeric_stability(values) == "marginal"
    except (TypeError, ValueError):
        return False
