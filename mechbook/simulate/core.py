"""Simulating one system of a problem: initial conditions, integration, monitors, record.

Initial conditions come from the system's `initial:` key ({q: value, qdot: value}) and from
the command line (`--init theta=0.1`), which overrides it key by key. Values are read by the
safe parser and may use the parameters (`initial: {theta: pi/6}`); a coordinate or velocity
left out starts at 0. With no initial conditions at all the run starts at rest, 0.1 away
(in every coordinate) from the first stable equilibrium the engine finds, and says so.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from datetime import UTC, datetime

import numpy as np
import sympy as sp

from .. import __version__
from ..analysis import Analysis
from ..errors import MechbookError, UnsupportedError
from .integrators import Trajectory, integrate
from .monitors import Drift, conserved_quantities, drifts
from .rhs import DEFAULT_BACKEND, Model, build_model

FALLBACK_OFFSET = 0.1


@dataclass
class Simulation:
    """A finished run: the trajectory, the monitors' drift and every setting used."""

    problem_id: str
    system: str
    model: Model
    trajectory: Trajectory
    drifts: list[Drift]
    initial: dict[str, float]
    initial_source: str
    values: dict[str, float]
    seconds: float
    notes: list[str] = field(default_factory=list)

    def settings(self) -> dict:
        """Everything needed to repeat the run (stored as HDF5 attributes)."""
        out = {"problem": self.problem_id, "system": self.system,
               "coordinates": ",".join(self.model.names),
               "initial": ", ".join(f"{k}={v:.17g}" for k, v in self.initial.items()),
               "initial_source": self.initial_source,
               "parameters": ", ".join(f"{k}={v:.17g}" for k, v in self.values.items()),
               "rhs_backend": self.model.backend,
               "rhs_generation_s": float(self.model.generation_seconds),
               "nfev": int(self.trajectory.nfev), "success": bool(self.trajectory.success),
               "message": self.trajectory.message, "seconds": float(self.seconds),
               "t0": float(self.trajectory.t[0]) if len(self.trajectory.t) else 0.0,
               "t1": float(self.trajectory.t[-1]) if len(self.trajectory.t) else 0.0,
               "mechbook": __version__, "sympy": sp.__version__, "numpy": np.__version__,
               "date": datetime.now(UTC).isoformat(timespec="seconds"),
               "notes": "; ".join(self.notes)}
        out.update({f"setting_{k}": v for k, v in self.trajectory.settings.items()})
        out["method"] = self.trajectory.method
        return out

    def arrays(self) -> dict[str, np.ndarray]:
        out = {"t": self.trajectory.t, "q": self.trajectory.q, "qdot": self.trajectory.qd}
        for d in self.drifts:
            out[f"monitors/{d.name}"] = d.values
        return out


def parse_assignments(items: list[str] | tuple[str, ...]) -> dict[str, str]:
    """`name=value` strings from the command line -> {name: value text}."""
    out = {}
    for item in items:
        name, sep, text = item.partition("=")
        if not sep or not name.strip() or not text.strip():
            raise MechbookError(f"--init expects name=value, got {item!r}")
        out[name.strip()] = text.strip()
    return out


def initial_state(analysis: Analysis, system_name: str | None, overrides: dict[str, str],
                  values: dict) -> tuple[np.ndarray, np.ndarray, str]:
    """(q0, q̇0, where they came from) from `initial:` and the command-line overrides."""
    sys = analysis.system(system_name)
    given: dict[str, object] = dict(sys.spec.get("initial") or {})
    source = "problem file `initial:`" if given else ""
    if overrides:
        given.update(overrides)
        source = (source + " + " if source else "") + "command line"
    n = len(sys.q)
    q0, qd0 = np.zeros(n), np.zeros(n)
    if not given:
        return (*_fallback(analysis, system_name, values), "fallback")
    known = {c: i for i, c in enumerate(sys.coord_names)}
    names = dict(sys.names)
    for key, text in given.items():
        if key in known:
            target, i = q0, known[key]
        elif key.endswith("dot") and key[:-3] in known:
            target, i = qd0, known[key[:-3]]
        else:
            raise MechbookError(f"initial value for {key!r}: not a coordinate or a velocity "
                                f"(coordinates: {', '.join(sys.coord_names)}; velocities "
                                "add 'dot')")
        path = ("initial", key) if key not in overrides else ()
        expr = analysis.problem.parse(str(text), sys.path + path, names)
        if expr.free_symbols & (set(sys.q) | set(sys.qd) | set(sys.qdd) | {sys.t}):
            raise MechbookError(f"initial value for {key!r} must be a number or use only "
                                "parameters")
        try:
            target[i] = float(sp.N(expr.subs(values)))
        except (TypeError, ValueError) as exc:
            raise MechbookError(f"initial value for {key!r} does not evaluate: {exc}") from None
    return q0, qd0, source


def _fallback(analysis: Analysis, system_name: str | None,
              values: dict) -> tuple[np.ndarray, np.ndarray]:
    """Rest, FALLBACK_OFFSET away from the first stable equilibrium (none: an error)."""
    sys = analysis.system(system_name)
    try:
        stable = analysis.stable_equilibria(system_name)
    except UnsupportedError:
        stable = []
    if not stable:
        raise MechbookError(f"{analysis.problem.id}: no initial conditions (`initial:` in the "
                            "problem file, or --init q=value) and no stable equilibrium to "
                            "start near")
    point = stable[0]
    q0 = np.array([float(sp.N(point.get(q, 0).subs(values))) for q in sys.q]) + FALLBACK_OFFSET
    return q0, np.zeros(len(sys.q))


def simulate(analysis: Analysis, system_name: str | None = None, *,
             init: dict[str, str] | None = None, t_span: tuple[float, float] = (0.0, 10.0),
             method: str = "DOP853", points: int = 2001, backend: str = DEFAULT_BACKEND,
             **options) -> Simulation:
    """Integrate the full nonlinear equations of a system at the default parameter values.

    `options` go to the integrator (rtol, atol, max_step for SciPy's methods; step for the
    fixed-step ones). SciPy's methods report at `points` evenly spaced times."""
    start = time.perf_counter()
    problem = analysis.problem
    sys = analysis.system(system_name)
    values = problem.values()
    dyn = analysis.dynamics(sys.name)
    q0, qd0, source = initial_state(analysis, sys.name, init or {}, values)
    model = build_model(sys, dyn, values, conserved_quantities(sys, dyn), backend)
    t_eval = None
    if method in ("RK45", "DOP853", "Radau", "LSODA") and points and points > 1:
        t_eval = np.linspace(t_span[0], t_span[1], int(points))
    traj = integrate(model, t_span, q0, qd0, method, t_eval=t_eval, **options)
    notes = []
    if source == "fallback":
        notes.append(f"no initial conditions given: started at rest, {FALLBACK_OFFSET} from "
                     "the first stable equilibrium")
    if not traj.success:
        notes.append(f"integration stopped early: {traj.message}")
    sim = Simulation(problem.id, sys.name, model, traj, drifts(model, traj),
                     dict(zip([*sys.coord_names, *(c + "dot" for c in sys.coord_names)],
                              [*map(float, q0), *map(float, qd0)], strict=True)),
                     source, {s.name: float(v) for s, v in values.items()}, 0.0, notes)
    sim.seconds = time.perf_counter() - start
    return sim
