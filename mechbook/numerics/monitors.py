"""Monitors of the conserved quantities the engine found, evaluated along a trajectory.

The engine decides what is conserved (`Dynamics.energy_conserved`, `Dynamics.cyclic`); a
monitor evaluates each such quantity at every recorded sample, so a run reports how far
the integrator let it drift: the largest and final deviation from the initial value,
relative to the quantity's scale, and the least-squares drift rate (per unit time), which
separates secular growth from a bounded oscillation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from mechbook.numerics.integrator_base import Trajectory
from mechbook.numerics.rhs import Model


def conserved_quantities(system, dyn) -> dict[str, sp.Expr]:
    """{name: expression in (q, q̇, t)}: the energy function h = Σ q̇ ∂L/∂q̇ − L when the
    engine finds it conserved, and the momentum ∂L/∂q̇ of every cyclic coordinate."""
    L = system.lagrangian
    out: dict[str, sp.Expr] = {}
    if dyn.energy_conserved:
        out["energy_function"] = sum((v * sp.diff(L, v) for v in dyn.qd), sp.S.Zero) - L
    for q in dyn.cyclic:
        i = dyn.q.index(q)
        out[f"p_{system.coord_names[i]}"] = sp.diff(L, dyn.qd[i])
    out.update(constraint_monitors(system))
    return out


CONSTRAINT = "constraint "  # a monitor of a constraint's residual: "constraint <name>"
SCALE = "scale of "  # its companion: the sum of its terms' magnitudes (what it is judged by)


def constraint_monitors(system) -> dict[str, sp.Expr]:
    """Each constraint's residual (holonomic g, velocity A·q̇ + b), which the integrator keeps
    at zero only to its tolerance, and beside it the sum of its terms' magnitudes: a run
    reports how far it drifted off the constraint manifold, relative to that."""
    out: dict[str, sp.Expr] = {}
    for name, c in list(system.constraints) + list(getattr(system, "velocity_constraints", [])):
        out[CONSTRAINT + name] = c
        terms = sp.Add.make_args(sp.expand(c))
        out[SCALE + CONSTRAINT + name] = sp.Add(*(sp.Abs(x) for x in terms))
    return out


@dataclass
class Drift:
    """How far one conserved quantity moved over a run."""

    name: str
    values: np.ndarray
    initial: float
    max_abs: float  # max |Q(t) − Q(0)|
    final: float  # Q(t_end) − Q(0)
    scale: float  # the quantity's magnitude scale (see `drifts`)
    rate: float  # least-squares slope of (Q − Q0)/scale per unit time

    @property
    def relative(self) -> float:
        return self.max_abs / self.scale

    def summary(self) -> str:
        return (f"{self.name}: initial {self.initial:.12g}, max |drift| {self.max_abs:.3e} "
                f"(relative {self.relative:.3e}), final {self.final:+.3e}, "
                f"rate {self.rate:+.3e}/time")

    def attrs(self) -> dict:
        return {"initial": self.initial, "max_abs_drift": self.max_abs,
                "final_drift": self.final, "scale": self.scale,
                "relative_drift": self.relative, "drift_rate": self.rate}


def drifts(model: Model, traj: Trajectory) -> list[Drift]:
    """Drift of every monitored quantity over `traj`.

    Scale: for the energy function the largest of |h(0)| and Σ|q̇_i p_i| along the run (twice
    the kinetic energy of a natural system), so an energy near zero is not divided by zero;
    for a momentum the largest |p_i| of any coordinate along the run."""
    if not model.monitor_names or len(traj.t) == 0:
        return []
    values = model.monitors(traj.t, traj.q, traj.qd)
    momenta = model.momenta_along(traj.t, traj.q, traj.qd)
    series = dict(zip(model.monitor_names, values, strict=True))
    out = []
    for name, vals in series.items():
        if name.startswith(SCALE):
            continue
        q0 = float(vals[0])
        dev = vals - q0
        if name.startswith(CONSTRAINT):  # judged against what it is made of, from zero
            dev = vals
            extra = float(np.max(np.abs(series[SCALE + name])))
        elif name == "energy_function":
            extra = float(np.max(np.sum(np.abs(traj.qd * momenta), axis=0)))
        else:
            extra = float(np.max(np.abs(momenta)))
        scale = max(abs(q0), extra, 1e-300)
        rate = 0.0
        span = float(traj.t[-1] - traj.t[0]) if len(traj.t) else 0.0
        if len(traj.t) > 2 and span > 0 and np.all(np.isfinite(dev)):
            # fitted in time scaled to [0, 1], then per unit time: a span of 1e-300 squared
            # underflows, and NumPy's fit then fails ("SVD did not converge")
            slope = float(np.polyfit((traj.t - traj.t[0]) / span, dev / scale, 1)[0])
            with np.errstate(over="ignore"):
                rate = float(np.float64(slope) / span)
        out.append(Drift(name, vals, q0, float(np.max(np.abs(dev))), float(dev[-1]), scale,
                         rate))
    return out
