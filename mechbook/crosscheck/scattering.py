"""The cross-check of a scattering part: the orbit integrated far out, its asymptote fitted.

At the part's default values (its b and E), the full equations of motion (the system's
compiled model, DOP853 at rtol 1e-12, not the engine's reduction or its quadrature;
solve_ivp's steps, taken in the compiled loop where there is one) are integrated from a
start at R on the incoming branch (energy E, angular momentum b·√(2mE): ṙ < 0 and θ̇ from
them) until r is back at R, reflecting ṙ on a hard core. The velocity's turn between the
two ends, Θ(R) = ψ_in − ψ_out − Δθ (ψ the velocity's angle to the radius, Δθ the angle
swept), is the deflection up to the field's pull beyond R; it is taken at
R = 1000, 2000, … 16000 length scales and fitted by a cubic in 1/R, whose value at 1/R = 0
is the asymptote's deflection. The smallest r met is the closest approach. Both must agree
with the engine's to TOL. Where the engine has a time delay, the time from R back to R less
the free line's 2√(R² − b²)/v, fitted the same way, must agree with it to TAU_TOL. The fit
needs the plane's polar coordinates: T = m(ṙ² + r²θ̇²)/2.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from mechbook.crosscheck.guard import guarded
from mechbook.crosscheck.partview import PartView
from mechbook.engine.analysis import Analysis
from mechbook.errors import UnsupportedError
from mechbook.numerics.events import solve_with_events
from mechbook.numerics.rhs import build_model
from mechbook.records import CrossCheck, Status
from mechbook.verify.answers import Part

TAU_TOL = 1e-6  # a time of ~2R/v less another: measured 4e-11 (hard sphere), 9e-11 (−α/r²)
TOL = 1e-9  # measured: 1e-12 (Rutherford, the hard sphere) to 5e-12 (−α/r²)
RADII = (1000, 2000, 4000, 8000, 16000)  # starts, in length scales (max(b, a, 1))


def scattering_crosscheck(analysis: Analysis, part: Part) -> CrossCheck:
    """The part's deflection and closest approach at its default values, measured."""
    x = CrossCheck(f"asymptote:{part.name}", "scattering", part.system or "", Status.ERROR,
                   parts=[part.name])
    with guarded(x):
        view = PartView(analysis, part)
        beam = view.beam()
        values = view.values()
        b, E = beam.at(values)
        sc = beam.engine
        theta_engine = float(beam.value(values, b, E, lambda o: o.deflection))
        rmin_engine = float(beam.value(values, b, E, lambda o: o.r_min))
        orbit = sc.orbit(values, b, E)
        core = None if orbit.core is None else float(orbit.core)
        sys = view.system
        m, potential = _polar(view.dyn.L, sys, sc.r, sc.angle, values)
        params = {k: float(v) for k, v in values.items() if k in sys.problem.values()}
        model = build_model(sys, view.dyn, params)
        scale = max(float(b), core or 0.0, 1.0)
        b, E = float(b), float(E)
        ell = b * math.sqrt(2 * m * E)
        thetas, rmins, delays = [], [], []
        for R in (scale * k for k in RADII):
            t, r, span = _deflection_from(model, sys, sc.r, sc.angle, R, m, E, ell,
                                          potential(R), core, 10 * max(scale, rmin_engine))
            thetas.append(t)
            rmins.append(r)
            delays.append(span - 2 * math.sqrt(R * R - b * b) / math.sqrt(2 * E / m))
        inv = np.array([1 / k for k in RADII])
        fit3 = np.polyfit(inv, thetas, 3)[-1]
        fit2 = np.polyfit(inv[1:], thetas[1:], 2)[-1]
        d_theta = abs(fit3 - theta_engine) / max(1.0, abs(theta_engine))
        d_r = abs(min(rmins) - rmin_engine) / rmin_engine
        tau = _delay(beam, values, inv, delays, rmin_engine / math.sqrt(2 * E / m))
        x.error = max(d_theta, d_r)
        x.status = Status.PASS if x.error < TOL and (tau[0] is None or tau[2] < TAU_TOL) \
            else Status.FAIL
        x.detail = (f"integrated from R = {RADII[0]}..{RADII[-1]} x {scale:.3g} and fitted in "
                    f"1/R: deflection {fit3:.12g} (a quadratic fit: {fit2:.12g}) vs the "
                    f"quadrature's {theta_engine:.12g}; closest approach {min(rmins):.12g} vs "
                    f"{rmin_engine:.12g} (worst {x.error:.1g})" + (
                        "" if tau[0] is None else
                        f"; time delay {tau[1]:.10g} vs {tau[0]:.10g} ({tau[2]:.1g} of "
                        "max(|τ|, r_min/v))"))
    return x


def _delay(beam, values: dict, inv, delays: list, floor: float) -> tuple:
    """(the engine's τ or None where it has none, the fitted one, their difference relative
    to max(|τ|, r_min/v)): the time from R back to R less the free line's 2√(R² − b²)/v,
    fitted by a cubic in 1/R."""
    b, E = beam.at(values)
    try:
        tau = float(beam.value(values, b, E, lambda o: o.time_delay))
    except UnsupportedError:
        return None, None, 0.0
    fit = float(np.polyfit(inv, delays, 3)[-1])
    return tau, fit, abs(fit - tau) / max(abs(tau), floor)


def _polar(L, sys, r, angle, values: dict):
    """(m, V(r) as a float function): the plane's polar coordinates are required, T =
    m(ṙ² + r²θ̇²)/2 with a constant m."""
    rd, ad = sys.qd[sys.q.index(r)], sys.qd[sys.q.index(angle)]
    at_rest = L.subs({rd: 0, ad: 0})
    m = sp.diff(L, rd, 2)
    if m.has(r) or m.has(rd) or m.has(ad) or \
            sp.simplify(L - at_rest - m * (rd ** 2 + r ** 2 * ad ** 2) / 2) != 0:
        raise UnsupportedError("the asymptote is fitted in the plane's polar coordinates: "
                               "T is not m(rdot**2 + r**2*thetadot**2)/2 here")
    sub = {k: v for k, v in values.items()}
    mass = float(m.subs(sub))
    V = sp.lambdify(r, (-at_rest).subs(sub), "math")
    return mass, lambda x: float(V(x))


class _Flight:
    """The full equations integrated along one orbit: DOP853 at rtol 1e-12, every end state
    that of a step ending there (re-integrated to an event's time), not an interpolant's."""

    def __init__(self, model, ir: int, n: int, R: float, speed: float, inner: float):
        self.model, self.ir, self.n, self.R, self.speed = model, ir, n, R, speed
        self.atol = np.full(2 * n, 1e-20)  # the relative 1e-12 rules (θ̇ is ~1e-9 far out)
        self.atol[ir] = 1e-12 * inner

    def crossing(self, level: float, direction: int):
        def event(t, y):
            return y[self.ir] - level
        event.terminal, event.direction = True, direction
        return event

    def run(self, t, y, events, max_step=np.inf, span=None):
        """((t, y, which event) at the first terminal event or None, the solution: every
        step's end in y, as solve_ivp's). The steps are solve_ivp's, taken in the compiled
        loop where there is one (mechbook.numerics.events)."""
        span = span if span is not None else 40 * self.R / self.speed
        native = self.model.native
        sol = solve_with_events(native, self.model.rhs, (t, t + span), y, rtol=1e-12,
                                atol=self.atol, events=events, max_step=max_step, steps=True,
                                stats=self.model.stats)
        if not sol.success:
            raise UnsupportedError(f"the orbit could not be integrated: {sol.message}")
        hits = [(float(te[0]), i) for i, te in enumerate(sol.t_events) if te.size and
                getattr(events[i], "terminal", False)]
        if not hits:
            return None, sol
        t_hit, i = min(hits)
        end = solve_with_events(native, self.model.rhs, (t, t_hit), y, rtol=1e-12,
                                atol=self.atol, max_step=max_step, stats=self.model.stats)
        if not end.success:
            raise UnsupportedError(f"the orbit could not be integrated: {end.message}")
        return (t_hit, end.y[:, -1].copy(), i), sol


def _deflection_from(model, sys, r, angle, R: float, m: float, E: float, ell: float,
                     V_R: float, core: float | None, inner: float) -> tuple:
    """(Θ(R), the least r, the time from R back to R) of the orbit started at R inward and
    followed back out to R: free steps beyond `inner`, steps of at most inner/1000 of the
    time scale inside it (where the turning point, the least r and a reflection on the core
    are located)."""
    ir, ia = sys.q.index(r), sys.q.index(angle)
    n = len(sys.q)
    adot = ell / (m * R ** 2)
    rr = 2 * (E - V_R) / m - (R * adot) ** 2
    if rr <= 0:
        raise UnsupportedError(f"the orbit cannot be started at r = {R:.3g}")
    y = np.zeros(2 * n)
    y[ir], y[n + ir], y[n + ia] = R, -math.sqrt(rr), adot
    psi_in = math.atan2(R * adot, y[n + ir])
    fly = _Flight(model, ir, n, R, math.sqrt(2 * E / m), inner)
    fine = inner / fly.speed / 1000

    def turning(t, y):
        return y[n + ir]
    turning.direction = 1

    hit, _ = fly.run(0.0, y, [fly.crossing(inner, -1)])
    if hit is None:
        raise UnsupportedError("the orbit from far out never came near the centre")
    t, y, _ = hit
    least = float(y[ir])
    for _ in range(3):  # inside: to the way out (a reflection on the core restarts)
        events = [fly.crossing(inner, 1), turning] + ([fly.crossing(core, -1)] if core else [])
        hit, sol = fly.run(t, y, events, max_step=fine, span=1e6 * fine)
        if hit is None:
            raise UnsupportedError("the orbit did not come back out (captured, or too slow)")
        if sol.t_events[1].size:
            least = min(least, float(np.min(sol.y_events[1][:, ir])))
        least = min(least, float(np.min(sol.y[ir])))
        t, y, which = hit
        if which != 2:
            break
        y[n + ir] = -y[n + ir]  # the specular reflection on the hard core
        least = min(least, core)
    else:
        raise UnsupportedError("the orbit did not come back out")
    hit, _ = fly.run(t, y, [fly.crossing(R, 1)])
    if hit is None:
        raise UnsupportedError("the orbit did not reach the start's radius again")
    t_out, y, _ = hit
    psi_out = math.atan2(y[ir] * y[n + ia], y[n + ir])
    return psi_in - psi_out - float(y[ia]), least, t_out
