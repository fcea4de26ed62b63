"""Cross-check of first integrals by simulation: the book's conserved quantity, evaluated
along a numerically integrated trajectory of the full nonlinear equations, stays constant.

This is independent of the symbolic check (which differentiates the book's expression and
substitutes the engine's accelerations): here the engine's equations are integrated by
DOP853 at tight tolerance and the book's expression is only *evaluated* along the result.
It covers `conserved` parts and, for autonomous systems, the Hamiltonian and the energy
function given as `expression` parts (the Hamiltonian with the engine's momenta put in for
p). Problems without a printed answer (Symon's even problems) are verified this way too.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.core.numeval import evaluate
from mechbook.crosscheck.guard import guarded
from mechbook.crosscheck.partview import PartView, split_named
from mechbook.crosscheck.vouch import crosschecks_of
from mechbook.engine.analysis import Analysis
from mechbook.engine.screen import screen
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.model.manifold import manifold_of
from mechbook.numerics.integrators import integrate
from mechbook.numerics.rhs import build_model
from mechbook.numerics.simulate import FALLBACK_OFFSET, initial_state
from mechbook.records import CrossCheck, Status
from mechbook.verify.answers import Part

DRIFT_TOL = 1e-7  # largest relative change allowed along the run (DOP853 at rtol 1e-12)
T_END = 3.0  # time units; long enough for the state to change, short enough to be cheap
SAMPLES = 25


def conserved_part(analysis: Analysis, part: Part, models: dict) -> CrossCheck | None:
    """The simulation cross-check of a part's first integral (None: the part states none)."""
    x = CrossCheck(f"conserved:{part.name}", "conserved", part.system or "", Status.ERROR,
                   parts=[part.name])
    with guarded(x):
        view = PartView(analysis, part)
        exprs = book_integrals(view)
        if not exprs:
            return None
        x.status, x.error, x.detail = conserved_crosscheck(analysis, view, exprs, models)
    return x


def book_integrals(ctx: PartView) -> list[sp.Expr]:
    """The part's conserved expressions in (q, q̇, t), or [] when it states none."""
    part, data = ctx.part, ctx.part.data
    if "about" in data or "steady" in data or "at" in data or "erratum" in data:
        return []
    val = data.get("book")
    vouch = crosschecks_of(part.quantity)
    if "first_integrals" in vouch:  # a named one (`p_psi = ...`): its value
        vals = val if isinstance(val, list) else [val]
        return [ctx.parse(split_named(v)[1], ("book", i) if isinstance(val, list) else ("book",))
                for i, v in enumerate(vals)]
    if "energy_integral" in vouch and data.get("of") in ("hamiltonian", "energy_function"):
        if ctx.system.lagrangian.has(ctx.system.t) or any(f != 0 for f in ctx.system.forces):
            return []  # h is conserved only for an autonomous, conservative system
        e = ctx.parse(val, ("book",))
        if data["of"] == "hamiltonian":
            e = e.subs({ctx.names["p_" + c]: p for c, p in
                        zip(ctx.system.coord_names, ctx.dyn.momenta, strict=True)})
        return [e]
    return []


def _start(analysis, sys, params: dict, rng) -> tuple[np.ndarray, np.ndarray]:
    """The problem's `initial:` state; else rest FALLBACK_OFFSET from the stable equilibrium
    a root finder sees first at the default values (mechbook.engine.screen: no closed form
    is needed to start near it); else a generic state."""
    n = len(sys.q)
    if sys.spec.get("initial"):
        try:
            q0, qd0, _ = initial_state(analysis, sys.name, {}, params)
            return q0, qd0
        except MechbookError:
            return rng.uniform(0.4, 1.2, n), np.zeros(n)
    try:
        found = screen(analysis.equilibria(sys.name), params).found
    except UnsupportedError:
        found = []
    stable = [f.point for f in found if f.isolated and f.stability == "stable"]
    if stable:
        return stable[0] + FALLBACK_OFFSET, np.zeros(n)
    return rng.uniform(0.4, 1.2, n), np.zeros(n)


def conserved_crosscheck(analysis: Analysis, ctx: PartView, exprs: list[sp.Expr],
                         models: dict) -> tuple[Status, float, str]:
    """(status, worst relative drift, detail) for the book's integrals along a trajectory."""
    sys = ctx.system
    values = {k: v for k, v in ctx.values().items()}
    params = {k: float(v) for k, v in values.items() if k in set(analysis.problem.values())}
    key = (sys.name, tuple(sorted((str(k), v) for k, v in params.items())))
    if key not in models:
        models[key] = build_model(sys, ctx.dyn, params)
    model = models[key]
    rng = np.random.default_rng(20261123)
    q0, qd0 = _start(analysis, sys, params, rng)
    qd0 = qd0 + rng.uniform(-0.3, 0.3, len(qd0))  # moving, so the integral is exercised
    manifold = manifold_of(sys)
    if manifold is not None:  # a constrained system moves on its constraint manifold
        settled = manifold.settle(params, q0, qd0)
        if settled is None:
            raise UnsupportedError("no start on the constraint manifold found near the "
                                   "chosen state")
        q0, qd0 = np.array(settled[0]), np.array(settled[1])
    ts = np.linspace(0.0, T_END, SAMPLES)
    traj = integrate(model, (0.0, T_END), q0, qd0, method="DOP853", t_eval=ts,
                     rtol=1e-12, atol=1e-12)
    if not traj.success:
        raise UnsupportedError(f"the trajectory could not be integrated: {traj.message}")
    worst = 0.0
    for e in exprs:
        e = e.subs({k: v for k, v in values.items() if k not in params})
        series, scale = [], 0.0
        for j, t in enumerate(traj.t):
            point = dict(params)
            point[sys.t] = float(t)
            point.update({q: float(x) for q, x in zip(sys.q, traj.q[:, j], strict=True)})
            point.update({v: float(x) for v, x in zip(sys.qd, traj.qd[:, j], strict=True)})
            v, m = evaluate(e, {k: sp.Float(x, 20) for k, x in point.items()}, 20)
            series.append(v)
            scale = max(scale, m)
        series = np.array(series)
        drift = float(np.max(np.abs(series - series[0]))) / max(scale, 1e-300)
        worst = max(worst, drift)
        if drift > DRIFT_TOL:
            return Status.FAIL, worst, (f"{sp.sstr(e)[:60]} changes by {drift:.2g} (relative) "
                                        f"over t in [0, {T_END}] from "
                                        f"q0={np.round(q0, 4).tolist()}")
    return Status.PASS, worst, (f"{len(exprs)} integral(s) constant to {worst:.1g} over t in "
                                f"[0, {T_END}]")
