"""Cross-checks of canonical structure by the motion itself: a Poisson bracket with the
Hamiltonian, {f, H} = h, says that f changes along the motion at df/dt = h + ∂f/∂t; a new
Hamiltonian K of a canonical map says that the new variables move by Hamilton's equations,
dQ/dt = ∂K/∂P and dP/dt = −∂K/∂Q. Here each rate is taken by the chain rule in
(q, q̇, t), with the accelerations of Lagrange's equations (the compiled model the
simulations use), at states along a trajectory integrated by DOP853: neither the engine's
Hamiltonian nor its Legendre inversion nor the bracket's derivatives enter, so an error in
any of them cannot pass both sides. The book's expressions are read with p = ∂L/∂q̇ put in.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from mechbook.core.numeval import evaluate
from mechbook.crosscheck.guard import guarded
from mechbook.crosscheck.partview import PartView
from mechbook.engine.analysis import Analysis
from mechbook.errors import UnsupportedError
from mechbook.numerics.integrators import integrate
from mechbook.numerics.rhs import build_model
from mechbook.records import CrossCheck, Status
from mechbook.verify.answers import Part

RATE_TOL = 1e-7  # relative disagreement allowed (double-precision states and accelerations)
T_END = 1.0  # time units along the run
SAMPLES = 11


def bracket_part(analysis: Analysis, part: Part, models: dict) -> CrossCheck | None:
    """The rate cross-check of a bracket {f, H} = h (or {H, g} = h); None where the part's
    bracket is not with the engine's Hamiltonian (or names its own variables)."""
    x = CrossCheck(f"bracket_flow:{part.name}", "bracket_flow", part.system or "",
                   Status.ERROR, parts=[part.name])
    with guarded(x):
        view = PartView(analysis, part)
        claim = view.bracket()
        if claim is None:
            return None
        f, g, h, H = claim
        if g == H and H not in f.free_symbols:
            target, rate = f, h
        elif f == H and H not in g.free_symbols:
            target, rate = g, -h  # {g, H} = −{H, g}
        else:
            return None
        t = view.system.t
        x.status, x.error, x.detail = rate_crosscheck(
            analysis, view, [("df/dt = {f, H} + ∂f/∂t", target, rate + target.diff(t))], models)
    return x


def new_hamiltonian_part(analysis: Analysis, part: Part, models: dict) -> CrossCheck | None:
    """The motion cross-check of a canonical map's new Hamiltonian K: each new variable's
    rate along the motion against ∂K/∂P (for Q) and −∂K/∂Q (for P), the map put in; None
    where the part states no K (or names its own variables)."""
    x = CrossCheck(f"new_hamiltonian:{part.name}", "new_hamiltonian", part.system or "",
                   Status.ERROR, parts=[part.name])
    with guarded(x):
        view = PartView(analysis, part)
        claim = view.new_hamiltonian()
        if claim is None:
            return None
        pairs, values, K = claim
        rates = []
        for Q, P in pairs:
            rates.append((f"{Q}' = ∂K/∂{P}", values[Q], K.diff(P).xreplace(values)))
            rates.append((f"{P}' = −∂K/∂{Q}", values[P], -K.diff(Q).xreplace(values)))
        x.status, x.error, x.detail = rate_crosscheck(analysis, view, rates, models)
    return x


def rate_crosscheck(analysis: Analysis, view: PartView, rates: list[tuple[str, sp.Expr,
                                                                          sp.Expr]],
                    models: dict) -> tuple[Status, float, str]:
    """(status, worst relative difference, detail): for each (label, f, claimed df/dt) in
    (q, p, t), df/dt by the chain rule with Lagrange's accelerations against the claim, at
    SAMPLES states along a run."""
    sys, dyn = view.system, view.dyn
    if sys.constraints or sys.velocity_constraints or any(e != 0 for e in sys.forces):
        raise UnsupportedError("the bracket's rate: a system with constraints or forces "
                               "outside its Lagrangian")
    values = view.values()
    params = {k: float(v) for k, v in values.items() if k in set(analysis.problem.values())}
    key = (sys.name, tuple(sorted((str(k), v) for k, v in params.items())))
    if key not in models:
        models[key] = build_model(sys, dyn, params)
    model = models[key]
    p = [view.names["p_" + c] for c in sys.coord_names]
    legendre = dict(zip(p, dyn.momenta, strict=True))
    others = {k: v for k, v in values.items() if k not in params}  # answer symbols
    pairs = []
    for label, f, dfdt in rates:
        F = f.xreplace(legendre).subs(others)
        chain = sum((F.diff(q) * v + F.diff(v) * a
                     for q, v, a in zip(sys.q, sys.qd, sys.qdd, strict=True)), F.diff(sys.t))
        pairs.append((label, chain, dfdt.xreplace(legendre).subs(others)))
    rng = np.random.default_rng(20261207)
    n = len(sys.q)
    q0, qd0 = rng.uniform(0.4, 1.2, n), rng.uniform(-0.3, 0.3, n)
    ts = np.linspace(0.0, T_END, SAMPLES)
    traj = integrate(model, (0.0, T_END), q0, qd0, method="DOP853", t_eval=ts,
                     rtol=1e-12, atol=1e-12)
    if not traj.success:
        raise UnsupportedError(f"the trajectory could not be integrated: {traj.message}")
    worst = 0.0
    for j, t in enumerate(traj.t):
        qj, vj = traj.q[:, j], traj.qd[:, j]
        acc = model.accelerations(float(t), qj, vj)
        point = dict(params)
        point[sys.t] = float(t)
        point.update(zip(sys.q, map(float, qj), strict=True))
        point.update(zip(sys.qd, map(float, vj), strict=True))
        point.update(zip(sys.qdd, map(float, acc), strict=True))
        point = {k: sp.Float(v, 20) for k, v in point.items()}
        for label, chain, claimed in pairs:
            a, sa = evaluate(chain, point, 20)
            b, sb = evaluate(claimed, point, 20)
            rel = abs(a - b) / max(sa, sb, 1e-300)
            worst = max(worst, rel)
            if rel > RATE_TOL:
                return Status.FAIL, worst, (f"{label}: the rate is {a.real:.10g} from "
                                            f"Lagrange's equations, {b.real:.10g} claimed "
                                            f"(relative {rel:.2g}) at t = {float(t):.3g} of "
                                            f"a run from q0={np.round(q0, 4).tolist()}")
    what = ", ".join(label for label, _, _ in pairs)
    return Status.PASS, worst, (f"{what}: the rate from Lagrange's equations agrees at "
                                f"{len(traj.t)} states of a run over t in [0, {T_END}], to "
                                f"{worst:.1g}")
