"""Simulating one system of a problem: initial conditions, integration, monitors, record.

Initial conditions come from the system's `initial:` key ({q: value, qdot: value}) and from
the command line (`--init theta=0.1`), which overrides it key by key. Values are read by the
safe parser and may use the parameters (`initial: {theta: pi/6}`); a coordinate or velocity
left out starts at 0. With no initial conditions at all the run starts at rest, 0.1 away
(in every coordinate) from the first stable equilibrium the engine finds, and says so.
Parameters take their default values unless overridden (`--param k=1e6`). The compiled
model of a (system, parameter values, backend) is kept on the analysis for the last few
runs, so a repeated run pays only for its integration.

Choosing the method: with none given, DOP853, unless the run is stiff (`stiffness.assess`:
linear rates far apart over a long span, fast modes hardly excited), when it switches to
`stiffness.IMPLICIT` (Radau) and says why; a forced explicit method on a stiff run gets a
warning instead, as does a fixed step beyond the method's stability limit. With
`accuracy`, the method (unless forced) and the tolerance come from the rule measured by
bench/work_precision.py (`accuracy.choose`), and the run reports the error it expects.
"""

from __future__ import annotations

import time
from collections import OrderedDict
from dataclasses import dataclass, field
from datetime import UTC, datetime

import numpy as np
import sympy as sp

from mechbook.core.timeout import Timeout, hard_time_limit
from mechbook.engine.analysis import Analysis
from mechbook.errors import MechbookError, SpecError, UnsupportedError
from mechbook.model.manifold import manifold_of
from mechbook.numerics.accuracy import choose
from mechbook.numerics.domain import check_start, within_domains
from mechbook.numerics.integrators import SCIPY_METHODS, Trajectory, integrate
from mechbook.numerics.monitors import Drift, conserved_quantities, drifts
from mechbook.numerics.rhs import DEFAULT_BACKEND, Model, build_model
from mechbook.numerics.stiffness import IMPLICIT, Stiffness, assess, fixed_step_warning
from mechbook.version import __version__

FALLBACK_OFFSET = 0.1
MODELS_KEPT = 4  # compiled models kept per analysis for repeated runs (their integrators too)
FALLBACK_SEARCH = 20.0  # seconds for finding a stable equilibrium to start near


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
    choice: str = ""  # how --accuracy chose the method and tolerance, and the error expected
    stiffness: Stiffness | None = None

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
               "notes": "; ".join(self.notes), "accuracy_choice": self.choice,
               "stiffness": self.stiffness.reason if self.stiffness else ""}
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
            raise MechbookError(f"expected name=value (--init, --param), got {item!r}")
        out[name.strip()] = text.strip()
    return out


def _option_value(problem, flag: str, name: str, text: str, names: dict):
    """`text` of `flag name=text` read by the safe parser; its fault is the option's (a
    MechbookError naming it), never blamed on a line of the problem file."""
    try:
        return problem.parse(str(text), (), names)
    except SpecError as exc:
        raise MechbookError(f"{flag} {name}={text}: {exc.bare}") from None


def initial_state(analysis: Analysis, system_name: str | None, overrides: dict[str, str],
                  values: dict, search: float | None = None) -> tuple[np.ndarray, np.ndarray, str]:
    """(q0, q̇0, where they came from) from `initial:` and the command-line overrides, or
    near a stable equilibrium found within `search` seconds (default FALLBACK_SEARCH)."""
    sys = analysis.system(system_name)
    given: dict[str, object] = dict(sys.spec.get("initial") or {})
    source = "problem file `initial:`" if given else ""
    if overrides:
        given.update(overrides)
        source = (source + " + " if source else "") + "command line"
    n = len(sys.q)
    q0, qd0 = np.zeros(n), np.zeros(n)
    if not given:
        return (*_fallback(analysis, system_name, values, search or FALLBACK_SEARCH),
                "fallback")
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
        if key in overrides:  # the command line's: its errors name the option, not the file
            expr = _option_value(analysis.problem, "--init", key, text, names)
        else:
            expr = analysis.problem.parse(str(text), sys.path + ("initial", key), names)
        if expr.free_symbols & (set(sys.q) | set(sys.qd) | set(sys.qdd) | {sys.t}):
            raise MechbookError(f"initial value for {key!r} must be a number or use only "
                                "parameters")
        try:
            target[i] = float(sp.N(expr.subs(values)))
        except (TypeError, ValueError) as exc:
            raise MechbookError(f"initial value for {key!r} does not evaluate: {exc}") from None
        if not np.isfinite(target[i]):
            raise MechbookError(f"initial value for {key!r} is {target[i]}: not a finite "
                                "number")
    manifold = manifold_of(sys)
    if manifold is not None:
        q0, qd0, solved = _on_manifold(analysis, sys, manifold, values, q0, qd0, given,
                                       overrides)
        if solved:
            source += f" ({', '.join(solved)} solved from the constraints)"
    return q0, qd0, source


def _on_manifold(analysis: Analysis, sys, manifold, values: dict, q0: np.ndarray,
                 qd0: np.ndarray, given: dict, overrides: dict) -> tuple:
    """The stated start, its unstated coordinates and velocities solved from the
    constraints (least change from 0); an error naming the constraint where the stated
    ones alone break it."""
    stated = {q for q, c in zip(sys.q, sys.coord_names, strict=True) if c in given}
    stated |= {v for v, c in zip(sys.qd, sys.coord_names, strict=True) if c + "dot" in given}
    free = manifold.state - stated
    settled = manifold.settle(values, q0, qd0, 0.0, free)
    if settled is not None:
        q1, qd1 = np.array(settled[0]), np.array(settled[1])
        moved = [c for c, a, b in zip(sys.coord_names, q0, q1, strict=True)
                 if abs(a - b) > 1e-12 * max(1.0, abs(a))]
        moved += [c + "dot" for c, a, b in zip(sys.coord_names, qd0, qd1, strict=True)
                  if abs(a - b) > 1e-12 * max(1.0, abs(a))]
        return q1, qd1, moved
    point = dict(values)
    point.update({q: float(x) for q, x in zip(sys.q, q0, strict=True)})
    point.update({v: float(x) for v, x in zip(sys.qd, qd0, strict=True)})
    point[sys.t] = 0.0
    worst = max(manifold.residuals(point), key=lambda r: r[1])
    message = (f"the initial state is not on the constraint manifold: constraint "
               f"{worst[0]!r} is off by {worst[1]:.3g} (relative) there, and the "
               "coordinates and velocities left unstated cannot make it hold: state a start "
               "that satisfies the constraints (or leave the dependent ones out, to be "
               "solved for)")
    if given and not overrides:
        raise analysis.problem.doc.error(sys.path + ("initial",), message)
    raise MechbookError(message)


def _fallback(analysis: Analysis, system_name: str | None, values: dict,
              seconds: float = FALLBACK_SEARCH) -> tuple[np.ndarray, np.ndarray]:
    """Rest, FALLBACK_OFFSET away from the first stable equilibrium (none: an error)."""
    sys = analysis.system(system_name)
    try:
        with hard_time_limit(seconds):
            stable = analysis.stable_equilibria(system_name, budget=seconds)
    except UnsupportedError:
        stable = []
    except Timeout:
        raise MechbookError(f"{analysis.problem.id}: no initial conditions (`initial:` in the "
                            "problem file, or --init q=value), and no stable equilibrium to "
                            f"start near found within {seconds:g} s") from None
    if not stable:
        raise MechbookError(f"{analysis.problem.id}: no initial conditions (`initial:` in the "
                            "problem file, or --init q=value) and no stable equilibrium to "
                            "start near")
    point = stable[0]
    q0 = np.array([float(sp.N(point.get(q, 0).subs(values))) for q in sys.q]) + FALLBACK_OFFSET
    qd0 = np.zeros(len(sys.q))
    manifold = manifold_of(sys)
    if manifold is not None:  # the offset moved the start off the constraints: back onto them
        settled = manifold.settle(values, q0, qd0)
        if settled is None:
            raise MechbookError(f"{analysis.problem.id}: no initial conditions (`initial:` in "
                                "the problem file, or --init q=value), and no start on the "
                                "constraint manifold found near the stable equilibrium")
        q0, qd0 = np.array(settled[0]), np.array(settled[1])
    return q0, qd0


def parameter_values(analysis: Analysis, overrides: dict[str, str] | None) -> dict:
    """The default parameter values with `overrides` ({name: value text}, read by the safe
    parser, may use the other parameters' defaults) applied."""
    problem = analysis.problem
    values = problem.values()
    for name, text in (overrides or {}).items():
        if name not in problem.parameters:
            raise MechbookError(f"--param {name}: not a parameter of {problem.id} (parameters: "
                                f"{', '.join(problem.parameters)})")
        expr = _option_value(problem, "--param", name, text, problem.names())
        try:
            value = float(sp.N(expr.subs(problem.values())))
        except (TypeError, ValueError) as exc:
            raise MechbookError(f"--param {name}: does not evaluate: {exc}") from None
        if not np.isfinite(value):
            raise MechbookError(f"--param {name}={text}: is {value}, not a finite number")
        param = problem.parameters[name]
        if param.positive and not value > 0:
            raise MechbookError(f"--param {name}: the parameter is positive, got {value}")
        values[param.symbol] = value
    return values


def _model(analysis: Analysis, sys, dyn, values: dict, backend: str) -> Model:
    """The compiled model of `sys` at `values`, built once per analysis for the last
    MODELS_KEPT (system, values, backend): a repeated run (the API in a notebook, a report)
    reuses it and the Taylor integrators cached on it, which are reset before each run."""
    models = analysis.reuse(("simulation-models",), OrderedDict)
    key = (sys.name, backend, tuple(sorted((str(k), str(v)) for k, v in values.items())))
    model = models.pop(key, None)
    if model is None:
        model = build_model(sys, dyn, values, conserved_quantities(sys, dyn), backend)
    models[key] = model
    while len(models) > MODELS_KEPT:
        models.popitem(last=False)
    return model


def simulate(analysis: Analysis, system_name: str | None = None, *,
             init: dict[str, str] | None = None, t_span: tuple[float, float] = (0.0, 10.0),
             method: str | None = None, points: int = 2001, backend: str = DEFAULT_BACKEND,
             accuracy: float | None = None, parameters: dict[str, str] | None = None,
             **options) -> Simulation:
    """Integrate the full nonlinear equations of a system (default parameter values unless
    `parameters` overrides some).

    `method` None chooses (see the module docstring); `accuracy` chooses the tolerance (and
    the method, unless given) from the measured rule and cannot go with rtol, atol or step.
    `options` go to the integrator (rtol, atol, max_step for SciPy's methods; step for the
    fixed-step ones). SciPy's methods report at `points` evenly spaced times."""
    start = time.perf_counter()
    asked = method  # a method the caller asked for is used or refused, never replaced
    problem = analysis.problem
    sys = analysis.system(system_name)
    values = parameter_values(analysis, parameters)
    dyn = analysis.dynamics(sys.name)
    q0, qd0, source = initial_state(analysis, sys.name, init or {}, values)
    check_start(sys, q0, values)  # inside the coordinates' domains (numerics.domain)
    model = _model(analysis, sys, dyn, values, backend)
    given = {k for k in ("rtol", "atol", "step") if options.get(k) is not None}
    if accuracy is not None and given:
        raise MechbookError(f"give either an accuracy or {'/'.join(sorted(given))}, not both")
    stiff = assess(model, t_span, q0, qd0, rtol=accuracy or options.get("rtol") or 1e-8)
    notes, choice = [], ""
    if accuracy is not None:
        period = stiff.rates.period if stiff.rates else None
        picked = choose(accuracy, method=method, stiff=stiff.stiff and method is None,
                        periods=(t_span[1] - t_span[0]) / period if period else None)
        method, choice = picked.method, picked.describe()
        options = {**options, "rtol": picked.rtol,  # taylor's tolerance is relative only
                   "atol": None if method == "taylor" else picked.atol}
        if stiff.stiff:
            notes.append(f"stiff run: {stiff.reason}")
    elif method is None:
        method = IMPLICIT if stiff.stiff else "DOP853"
        if stiff.stiff:
            notes.append(f"stiff run, switched to {IMPLICIT}: {stiff.reason}")
    elif stiff.stiff and method not in ("Radau", "LSODA", "midpoint"):
        notes.append(f"warning: stiff run for the explicit method {method}: {stiff.reason}; "
                     f"its step stays below ~3/ω_max = {3 / stiff.rates.omega_max:.2g} for "
                     f"the whole span; an implicit method (--method {IMPLICIT}) is cheaper")
    warn = fixed_step_warning(method, options.get("step"), t_span[1] - t_span[0], stiff)
    if warn:
        notes.append(warn)
    t_eval = None
    if (method in SCIPY_METHODS or method == "taylor") and points and points > 1:
        t_eval = np.linspace(t_span[0], t_span[1], int(points))
    try:
        traj = integrate(model, t_span, q0, qd0, method, t_eval=t_eval, **options)
    except UnsupportedError as exc:
        if method != "taylor":
            raise
        if asked == "taylor":  # asked for by name: an error, not another method
            raise MechbookError(f"the taylor method cannot run: {exc.capability}; choose "
                                "another method (or none)") from None
        # chosen by `accuracy`, and heyoka refused the system: the SciPy path, saying so
        method = "DOP853"
        if accuracy is not None:
            picked = choose(accuracy, method=method, periods=None if not stiff.rates
                            or not stiff.rates.period else
                            (t_span[1] - t_span[0]) / stiff.rates.period)
            choice = picked.describe()
            options = {**options, "rtol": picked.rtol, "atol": picked.atol}
        notes.append(f"taylor method unavailable ({exc.capability}): {method} instead")
        traj = integrate(model, t_span, q0, qd0, method, t_eval=t_eval, **options)
    traj, left = within_domains(sys, traj, values)
    if left:
        notes.append(left)
    if source == "fallback":
        notes.append(f"no initial conditions given: started at rest, {FALLBACK_OFFSET} from "
                     "the first stable equilibrium")
    if not traj.success and not left:
        notes.append(f"integration stopped early: {traj.message}")
    sim = Simulation(problem.id, sys.name, model, traj, drifts(model, traj),
                     dict(zip([*sys.coord_names, *(c + "dot" for c in sys.coord_names)],
                              [*map(float, q0), *map(float, qd0)], strict=True)),
                     source, {s.name: float(v) for s, v in values.items()}, 0.0, notes,
                     choice, stiff)
    sim.seconds = time.perf_counter() - start
    return sim
