"""Cross-checks of steady motions and trajectory quantities by simulation.

* steady: every real steady rate the engine finds for a `steady_rates`/`steady_exists`
  part (at the default parameter values) is started as a motion of the full nonlinear
  equations (DOP853, rtol 1e-12); the coordinates that should stay put must stay within
  STEADY_TOL (relative to 1 + |value|) over three turns of the slowest rate (at most
  MAX_TURNS of the fastest). This confirms
  the steady-motion conditions (and the `hold:` relations) without the engine's algebra.
* trajectory: where a trajectory part was computed on the level set of the first
  integrals (mechbook.engine.levelset), the same quantity is measured by integrating the
  full equations (mechbook.numerics.measure) and must agree to MEASURE_RTOL (1e-7).
  Where the part was itself measured, the cross-check does not apply.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from mechbook.crosscheck.guard import guarded
from mechbook.crosscheck.partview import PartView
from mechbook.crosscheck.vouch import crosschecks_of
from mechbook.engine.analysis import Analysis
from mechbook.errors import UnsupportedError
from mechbook.numerics.measure import MEASURE_RTOL
from mechbook.numerics.rhs import build_model
from mechbook.records import CrossCheck, Status
from mechbook.verify.answers import Part

STEADY_TOL = 1e-8
STEADY_TURNS = 3
MAX_TURNS = 2000


def steady_crosscheck(analysis: Analysis, part: Part) -> CrossCheck:
    """Each real steady rate of the part, at the default values, kept by a simulation."""
    x = CrossCheck(f"steady:{part.name}", "steady", part.system or "", Status.ERROR,
                   parts=[part.name])
    with guarded(x):
        view = PartView(analysis, part)
        if "estimate" in part.data:
            raise UnsupportedError("a numeric estimate at the book's numbers")
        fam = view.steady_family()
        values = view.values()
        rates = fam.real_rates(values)
        if not rates:
            raise UnsupportedError("no steady motion at the default parameter values")
        sys = view.system
        params = {k: float(v) for k, v in values.items() if k in sys.problem.values()}
        model = build_model(sys, view.dyn, params)
        worst = max((_steady_drift(model, sys, fam, values, r) for r in rates), default=0.0)
        x.error = worst
        x.status = Status.PASS if worst < STEADY_TOL else Status.FAIL
        x.detail = (f"{len(rates)} steady rate(s) {[f'{r:.6g}' for r in rates]} simulated "
                    f"for {STEADY_TURNS} turns: the coordinates at rest drift {worst:.1g}")
    return x


def _steady_drift(model, sys, fam, values: dict, r) -> float:
    """The largest relative drift of the coordinates at rest over the steady motion at
    rate `r` (0 for a motion in which nothing turns)."""
    q0 = np.array([float(sp.N(sp.S(fam.point[q]).subs(values))) if q in fam.point else 0.0
                   for q in sys.q])
    qd0 = np.array([float(sp.N(sp.S(fam.rates.get(v, 0)).subs(values).subs(fam.x, r)))
                    for v in sys.qd])
    moving = np.abs(qd0[np.abs(qd0) > 1e-12])
    if not len(moving):
        return 0.0
    # a few turns of the slowest rate (at most MAX_TURNS of the fastest): a wrong
    # rate leaves a force that moves the coordinates at rest by far more than this
    span = min(STEADY_TURNS * 2 * math.pi / float(np.min(moving)),
               MAX_TURNS * 2 * math.pi / float(np.max(moving)))
    sol = solve_ivp(model.rhs, (0.0, span), np.concatenate((q0, qd0)),
                    method="DOP853", rtol=1e-12, atol=1e-12)
    if not sol.success:
        raise UnsupportedError(f"the steady motion could not be integrated: "
                               f"{sol.message}")
    worst = 0.0
    for q in fam.point:
        i = sys.q.index(q)
        drift = float(np.max(np.abs(sol.y[i] - q0[i]))) / (1 + abs(q0[i]))
        worst = max(worst, drift)
    return worst


def trajectory_crosscheck(analysis: Analysis, part: Part) -> CrossCheck:
    """The part's level-set quantities (turning points, period, advance) against the
    same measured by integrating the full equations."""
    x = CrossCheck(f"measured:{part.name}", "trajectory", part.system or "", Status.ERROR,
                   parts=[part.name])
    with guarded(x):
        view = PartView(analysis, part)
        motion = view.motion()
        if motion.level is None:
            raise UnsupportedError("the part is itself measured by integration")
        values = view.values()
        orbit = motion.orbit(values)
        measured = motion.measured(values)
        lo, hi = (float(v) for v in orbit.turning_points)
        pairs = [("low", lo, measured.low), ("high", hi, measured.high)]
        vouch = crosschecks_of(part.quantity)
        if "trajectory_period" in vouch:
            pairs.append(("period", float(orbit.period), measured.period()))
        if "trajectory_advance" in vouch:
            sys = view.system
            c = sys.q[sys.coord_names.index(part.data["rate"])]
            pairs.append(("advance", float(orbit.advance(c)), measured.advance(sys.q.index(c))))
        worst, what = 0.0, []
        for name, a, b in pairs:
            scale = max(abs(a), abs(hi - lo) if name in ("low", "high") else 0, 1e-300)
            rel = abs(a - b) / scale
            worst = max(worst, rel)
            what.append(f"{name} {a:.10g} vs {b:.10g}")
        x.error = worst
        x.status = Status.PASS if worst < MEASURE_RTOL else Status.FAIL
        x.detail = ("level set vs integration (DOP853 1e-12): " + "; ".join(what)
                    + f" (worst {worst:.1g})")
    return x
