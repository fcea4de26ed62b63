"""Cross-check: a steady-state amplitude measured from the driven nonlinear motion.

For a part that states the steady response to a harmonic force (`steady_amplitude`), the
full nonlinear equations of motion are integrated (DOP853, rtol 1e-12) with the driving
amplitudes (the parameters declared `small`) scaled down until the response is about
1e-4 of the problem's scale, starting from the engine's steady state; each coordinate's
motion q(t) − q* is then fitted over several driving periods by least squares on
cos(ωt), sin(ωt) and, to absorb any free motion the start or the nonlinear terms excite,
the cos and sin of every normal frequency (times its decay for damped modes). The fitted
complex amplitude at the driving frequency must agree with the engine's
X = (K − ω²M + iωC)⁻¹F̂ to REL_TOL. Nothing here looks at the book's value.
"""

from __future__ import annotations

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from mechbook.crosscheck.guard import guarded
from mechbook.crosscheck.partview import PartView
from mechbook.engine import response
from mechbook.engine.analysis import Analysis
from mechbook.engine.linear import LinearSystem
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.numerics.rhs import build_model
from mechbook.records import CrossCheck, Status

REL_TOL = 1e-4
TARGET = 1e-4  # response amplitude aimed at, relative to the problem's length scale
PERIODS = 12


def response_part(analysis: Analysis, view: PartView, lin: LinearSystem, values: dict,
                  models: dict) -> CrossCheck:
    """The driven simulation of a steady-amplitude part, at the part's driving frequency."""
    part = view.part
    x = CrossCheck(f"response:{part.name}", "response", part.system or "", Status.ERROR)
    with guarded(x, unsupported=Status.ERROR):  # the part's frequency does not read
        omega = view.number("frequency", values)
        x = response_crosscheck(analysis, lin, values, omega, f"response:{part.name}", models)
    x.parts.append(part.name)
    return x


def response_crosscheck(analysis: Analysis, lin: LinearSystem, values: dict, omega: float,
                        name: str, models: dict | None = None) -> CrossCheck:
    """Simulate the driven nonlinear system and compare the measured amplitude."""
    out = CrossCheck(name, "response", lin.dyn.sys.name)
    with guarded(out):
        _crosscheck(analysis, lin, values, omega, out, models if models is not None else {})
    return out


def _crosscheck(analysis, lin, values, omega, out: CrossCheck, models: dict) -> None:
    sys = lin.dyn.sys
    if sys.reduced or lin.velocity:
        raise UnsupportedError("steady response about a steady motion (not simulated here)")
    if not sys.small_params:
        raise UnsupportedError("no driving amplitude declared `small` to scale down")
    X = response.harmonic_response(lin, values, omega)
    q_star = np.array([float(sp.N(sp.S(lin.point.get(q, 0)).subs(values))) for q in lin.q])
    length = max(1.0, float(np.max(np.abs(q_star))))
    scale = TARGET * length / max(float(np.max(np.abs(X))), 1e-300)
    vals = {k: float(v) for k, v in values.items()}
    for s in sys.small_params:
        vals[s] = vals.get(s, 0.0) * scale
    key = (sys.problem.id, sys.name, "driven", tuple(sorted((str(k), v) for k, v in
                                                              vals.items())))
    if key not in models:
        models[key] = build_model(sys, analysis.dynamics(sys.name),
                                  {k: v for k, v in vals.items()
                                   if k in set(sys.problem.values())})
    model = models[key]
    Xs = X * scale  # the engine's amplitude at the scaled drive
    n = len(lin.q)
    y0 = np.concatenate((q_star + Xs.real, (1j * omega * Xs).real))
    period = 2 * np.pi / omega
    horizon = PERIODS * period
    sol = solve_ivp(model.rhs, (0.0, horizon), y0, method="DOP853", rtol=1e-12,
                    atol=1e-15 * length, dense_output=True)
    if not sol.success:
        raise MechbookError(f"integration failed: {sol.message}")
    ts = np.linspace(0.0, horizon, 40 * PERIODS)
    Y = sol.sol(ts)[:n] - q_star[:, None]
    basis = [np.cos(omega * ts), np.sin(omega * ts)]
    lam = response.exponents(lin, {k: sp.Float(v, 30) for k, v in values.items()})
    for p in lam:  # free motion at the normal frequencies (and decays)
        if p.imag > 1e-9 * abs(omega) and abs(p.imag - omega) > 1e-6 * omega:
            env = np.exp(p.real * ts)
            basis += [env * np.cos(p.imag * ts), env * np.sin(p.imag * ts)]
        elif abs(p.imag) <= 1e-9 * abs(omega):
            basis.append(np.exp(p.real * ts))
    B = np.array(basis).T
    measured = np.empty(n, dtype=complex)
    for k in range(n):
        coef, *_ = np.linalg.lstsq(B, Y[k], rcond=None)
        measured[k] = coef[0] - 1j * coef[1]  # a cos + b sin = Re((a - i b) e^{iωt})
    big = float(np.max(np.abs(Xs)))
    err = np.abs(measured - Xs) / big
    worst = float(np.max(err))
    out.error = worst
    out.status = Status.PASS if worst < REL_TOL else Status.FAIL
    names = [q.name for q in lin.q]
    shown = "; ".join(f"{nm}: engine {_c(x / scale)}, measured {_c(m / scale)}"
                      for nm, x, m in zip(names, Xs, measured, strict=True)
                      if abs(x) > 1e-3 * big or abs(m) > 1e-3 * big)
    out.detail = (f"ω = {omega:.6g}, driving amplitudes scaled by {scale:.2g}, {PERIODS} "
                  f"periods fitted: {shown} (largest difference {worst:.1e} of the largest "
                  "amplitude)")


def _c(z: complex) -> str:
    return f"{z.real:.8g}" if abs(z.imag) < 1e-9 * max(1e-300, abs(z)) else f"{z:.6g}"
