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

import numpy as np
from scipy.integrate import solve_ivp

from mechbook.crosscheck.guard import guarded
from mechbook.crosscheck.modal import (
    ModalSetup,
    complex_mode_signal,
    modal_setup,
    mode_signal,
    normal_modes,
    start_state,
    unstable_modes,
)
from mechbook.engine.analysis import Analysis
from mechbook.engine.linear import LinearSystem
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.numerics.events import solve_with_events
from mechbook.records import CrossCheck, Status

REL_TOL = 1e-4  # required agreement of measured and linear frequencies (and decay rates)
DECAY_FLOOR = 1e-6  # a mode decaying slower than this (relative to ω) is not damped
SHIFT_TOL = 1e-5  # the nonlinear shift must be known to be below this
START_AMPLITUDE = 1e-3
PERIODS = 4


def _measure(s: ModalSetup, mode: dict, amplitude: float, period: float) -> tuple[float, int]:
    """Frequency from upward zero crossings of the mode's signal over PERIODS periods
    (DOP853 in the compiled loop where there is one, the crossings located as solve_ivp
    locates them: mechbook.numerics.events); NaN with fewer than 3 crossings (no
    oscillation at this amplitude)."""
    return crossing_frequency(s.model, mode_signal(s, mode), start_state(s, mode, amplitude),
                              amplitude, period)


def crossing_frequency(model, signal, y0: np.ndarray, amplitude: float,
                       period: float) -> tuple[float, int]:
    """(frequency, crossings) of `signal(t, y)` along the nonlinear motion from y0: its
    upward zero crossings over PERIODS + 1 periods, located as solve_ivp locates events,
    fitted by least squares (DOP853 at rtol 1e-12, atol scaled to the amplitude); NaN with
    fewer than 3 crossings."""
    signal.direction = 1.0
    scale = np.maximum(np.abs(y0), 1.0)
    sol = solve_with_events(model.native, model.rhs, (0.0, (PERIODS + 1) * period), y0,
                            rtol=1e-12, atol=1e-13 * amplitude * scale, events=[signal],
                            stats=model.stats)
    if not sol.success:
        raise MechbookError(f"integration failed: {sol.message}")
    times = np.asarray(sol.t_events[0])
    if len(times) < 3:
        return float("nan"), len(times)
    j = np.arange(len(times))
    slope = np.polyfit(j, times, 1)[0]
    return 2 * np.pi / slope, len(times)


def _zero_mode(s: ModalSetup, mode: dict, amplitude: float, horizon: float) -> float:
    """Effective frequency of a zero mode: from how far it moves from rest in `horizon`
    (a mode of frequency ω would move back by 1 − cos ωT)."""
    g = mode_signal(s, mode)
    y0 = start_state(s, mode, amplitude)
    scale = np.maximum(np.abs(y0), 1.0)
    sol = solve_ivp(s.model.rhs, (0.0, horizon), y0, method="DOP853", rtol=1e-12,
                    atol=1e-13 * amplitude * scale, dense_output=True)
    if not sol.success:
        raise MechbookError(f"integration failed: {sol.message}")
    ts = np.linspace(0, horizon, 400)
    s0 = g(0.0, y0)
    moved = max(abs(g(t, sol.sol(t)) - s0) for t in ts) / max(abs(s0), 1e-300)
    return float(np.sqrt(2 * min(moved, 2.0)) / horizon)


def frequency_crosscheck(analysis: Analysis, lin: LinearSystem, values: dict, name: str,
                         models: dict | None = None) -> CrossCheck:
    """Simulate the nonlinear system along each mode of `lin` and compare frequencies."""
    out = CrossCheck(name, "frequencies", lin.dyn.sys.full.name)
    with guarded(out):
        _frequency_crosscheck(analysis, lin, values, out, models if models is not None else {})
    return out


def _frequency_crosscheck(analysis: Analysis, lin: LinearSystem, values: dict,
                          out: CrossCheck, models: dict) -> None:
    s = modal_setup(analysis, lin, values, models)
    d0 = _probe(s)
    modes = normal_modes(s)
    growing = unstable_modes(s)
    if growing:  # an unstable point: the simulation confirms the growth, not frequencies
        _crosscheck_growth(s, growing, out)
        return
    live = [m["omega"] for m in modes if not m["kind"] and m["omega"] > 0]
    if not live:
        kinds = sorted({m["kind"] or "?" for m in modes})
        raise UnsupportedError(f"no oscillating mode to measure ({', '.join(kinds)})")
    w_max, w_min = max(live), min(live)
    acc = d0[len(s.q_star):]
    if np.max(np.abs(acc)) > 1e-7 * w_max**2 * max(1.0, float(np.max(np.abs(s.q_star)))):
        out.status = Status.FAIL
        out.error = float("inf")
        out.detail = (f"not an equilibrium of the nonlinear equations: |q̈| = "
                      f"{np.max(np.abs(acc)):.3g} at the point")
        return
    worst, notes = 0.0, []
    for k, mode in enumerate(modes):
        entry, note = _mode_entry(s, k, mode, w_min, w_max)
        if note is not None:
            notes.append(note)
        else:
            worst = max(worst, entry["relative_error"] if "decay_error" not in entry
                        else max(entry["relative_error"], entry["decay_error"]))
        out.modes.append(entry)
    out.error = worst
    measured = [m for m in out.modes if "measured" in m and m["kind"] != "zero"]
    out.detail = "; ".join(_mode_texts(out.modes) + notes)
    failed = any(m["status"] == Status.FAIL for m in out.modes)
    out.status = Status.FAIL if failed else (Status.PASS if measured else Status.NA)


def _probe(s: ModalSetup) -> np.ndarray:
    """The state derivative at the reference state, after making sure the equations
    evaluate there and (at a displaced state) do not depend on time."""
    y_star = np.concatenate((s.q_star, s.v_star))
    with np.errstate(all="ignore"):
        d0 = s.model.rhs(0.0, y_star)
        y_probe = start_state(s, normal_modes(s)[0], START_AMPLITUDE) if s.index else y_star
        p0, p1 = s.model.rhs(0.0, y_probe), s.model.rhs(1.234567, y_probe)
    if not (np.all(np.isfinite(d0)) and np.all(np.isfinite(p0))):
        raise MechbookError("the equations of motion do not evaluate at the point")
    if not np.allclose(p0, p1, rtol=1e-12, atol=1e-12 * max(1.0, np.abs(p0).max())):
        raise UnsupportedError("frequency cross-check: the equations are not autonomous at "
                               "the default parameters (time-dependent coefficients)")
    return d0


def _mode_entry(s: ModalSetup, k: int, mode: dict, w_min: float,
                w_max: float) -> tuple[dict, str | None]:
    """(the record of mode k, a note when it is not measured: its status n.a.)."""
    entry = {"mode": k, "linear": mode["omega"], "kind": mode["kind"] or "oscillation"}
    if mode["kind"] in ("unstable", "overdamped"):
        entry["status"] = Status.NA
        return entry, f"mode {k}: {mode['kind']}, no oscillation to measure"
    if mode["kind"] == "defective":
        entry["status"] = Status.NA
        return entry, (f"mode {k}: a double exponent with one mode (secular growth at a "
                       "stability boundary), no oscillation of fixed amplitude to measure")
    if mode["kind"] == "zero":
        if mode.get("complex"):
            entry["status"] = Status.NA
            return entry, f"mode {k}: zero frequency of a gyroscopic system"
        horizon = 2 * np.pi / w_min * 2
        w_eff = _zero_mode(s, mode, START_AMPLITUDE, horizon)
        rel = w_eff / w_max
        entry.update({"measured": w_eff, "relative_error": rel,
                      "status": Status.PASS if rel < REL_TOL else Status.FAIL})
        return entry, None
    entry.update(_measure_mode(s, mode))
    ok = entry["relative_error"] < REL_TOL and entry["shift"] < SHIFT_TOL
    if mode.get("decay", 0.0) > DECAY_FLOOR * mode["omega"]:  # a damped mode
        entry.update(_measure_decay(s, mode))
        ok &= entry["decay_error"] < REL_TOL
    entry["status"] = Status.PASS if ok else Status.FAIL
    return entry, None


def _mode_texts(entries: list[dict]) -> list[str]:
    """The detail's words for each measured mode."""
    measured = [m for m in entries if "measured" in m and m["kind"] != "zero"]
    zeros = [m for m in entries if m["kind"] == "zero" and "measured" in m]
    bits = [f"ω {m['engine']:.6g}: measured {m['measured']:.10g} (rel {m['relative_error']:.1e},"
            f" amplitude {m['amplitude']:.0e}, shift {m['shift']:.0e}, extrapolated rel "
            f"{m['extrapolated_error']:.0e})"
            + (f", decay rate {m['decay']:.6g}: measured {m['decay_measured']:.10g} (rel "
               f"{m['decay_error']:.1e})" if "decay_measured" in m else "")
            for m in measured]
    bits += [f"zero mode stays (ω_eff/ω_max {m['relative_error']:.0e})" for m in zeros]
    return bits


def _measure_mode(s: ModalSetup, mode: dict) -> dict:
    """Measure at amplitudes a and a/2, shrinking a until the two agree (nonlinear shift)."""
    omega = mode["omega"]
    period = 2 * np.pi / omega
    nearest = float(s.engine[np.argmin(np.abs(s.engine - omega))]) if len(s.engine) else omega
    a = START_AMPLITUDE
    for _ in range(8):
        w1, few = _measure(s, mode, a, period)
        w2, crossings = _measure(s, mode, a / 2, period)
        if np.isnan(w1) or np.isnan(w2):  # no oscillation: the swing left a small well
            a /= 4  # (another equilibrium close by), or the mode does not oscillate
            continue
        shift = abs(w1 - w2) / omega / 3  # ω(a) − ω0 ∝ a²: the shift left at a/2
        if shift < SHIFT_TOL / 10:
            break
        a /= 4
    if np.isnan(w1) or np.isnan(w2):
        raise MechbookError(f"only {min(few, crossings)} zero crossings in {PERIODS + 1} "
                            f"linear periods, down to amplitude {4 * a:.0e}")
    extrapolated = w2 - (w1 - w2) / 3  # Richardson: remove the a² shift
    return {"measured": w2, "engine": nearest, "relative_error": abs(w2 - nearest) / nearest,
            "amplitude": a / 2, "shift": shift, "crossings": crossings,
            "extrapolated": extrapolated,
            "extrapolated_error": abs(extrapolated - nearest) / nearest}


def _measure_decay(s: ModalSetup, mode: dict) -> dict:
    """The decay rate of a damped mode measured from the nonlinear motion: the modulus of
    the complex modal amplitude w·(y − y*) along the trajectory started in the mode, fitted
    as log|z| = log|z0| − γt over PERIODS periods (at two amplitudes, a and a/2, like the
    frequency: the nonlinear part of the decay is known to be below their difference)."""
    gamma = mode["decay"]
    period = 2 * np.pi / mode["omega"]
    horizon = min(PERIODS * period, 3.0 / gamma)  # a few e-foldings at most
    z = complex_mode_signal(s, mode)
    rates = []
    for a in (START_AMPLITUDE, START_AMPLITUDE / 2):
        y0 = start_state(s, mode, a)
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


def _crosscheck_growth(s: ModalSetup, growing: list[dict], out: CrossCheck) -> None:
    """Each unstable mode's growth rate measured from the nonlinear motion started in it:
    log|w·(y − y*)| fitted over three e-foldings (small amplitude: the growth stays linear)."""
    worst, bits = 0.0, []
    for k, mode in enumerate(growing):
        gamma = mode["growth"]
        z = complex_mode_signal(s, mode)
        horizon = 3.0 / gamma
        a = START_AMPLITUDE / 10
        y0 = start_state(s, mode, a)
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
                          "status": Status.PASS if rel < REL_TOL * 10 else Status.FAIL})
        bits.append(f"growth rate {gamma:.6g}: measured {rate:.10g} (rel {rel:.1e})")
    out.error = worst
    out.status = Status.PASS if worst < REL_TOL * 10 else Status.FAIL
    out.detail = "unstable: " + "; ".join(bits) + " (oscillating modes not measured: the " \
        "motion leaves the point)"
