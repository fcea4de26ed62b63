"""`mechbook simulate` under a time limit and a memory bound.

A simulation runs in a worker process of the batch machinery (mechbook.app.running.batch): a run
past its wall-clock limit or its resident-memory bound is stopped from outside and reported
with the stage it was in, like a problem of `mechbook check`. The worker returns plain data
(the lines to print, the arrays and settings to store); the parent prints them and writes
the store, which keeps it the store's only writer. The plot, if asked for, is drawn by the
worker (it needs the compiled model).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from mechbook.app.authoring.validate import build_limit, build_systems
from mechbook.app.running.batch import Batch, BatchOptions
from mechbook.app.running.run import Stage
from mechbook.core.compile import DEFAULT_BACKEND
from mechbook.engine.analysis import Analysis
from mechbook.errors import MechbookError, describe, message
from mechbook.model.catalog import problem_path
from mechbook.model.problem import load_problem
from mechbook.numerics.plot import plot_simulation
from mechbook.numerics.simulate import parse_assignments, simulate

if TYPE_CHECKING:
    import numpy as np


@dataclass(frozen=True)
class SimRequest:
    """What the command line asked for (plain data: it crosses to the worker)."""

    problem_id: str
    system: str | None = None
    method: str | None = None
    accuracy: float | None = None
    params: tuple[str, ...] = ()
    rtol: float | None = None
    atol: float | None = None
    max_step: float | None = None
    step: float | None = None
    t_end: float = 10.0
    points: int = 2001
    init: tuple[str, ...] = ()
    backend: str | None = None
    plot: str | None = None


@dataclass
class SimReport:
    """What a simulation produced, as plain data."""

    problem_id: str
    lines: list[str] = field(default_factory=list)
    error: str | None = None
    system: str = ""
    method: str = ""
    success: bool = False
    arrays: dict[str, np.ndarray] = field(default_factory=dict)  # t, q, qdot, monitors/<name>
    settings: dict[str, object] = field(default_factory=dict)  # stored as HDF5 attributes
    array_attrs: dict[str, dict] = field(default_factory=dict)
    plot: str | None = None
    stage: str = ""


def simulate_task(request: SimRequest, base: Path, options: None, stage: Stage) -> SimReport:
    """The batch task: load, derive, integrate, (plot); errors become report.error."""
    report = SimReport(request.problem_id)
    try:
        stage("loading")
        problem = load_problem(problem_path(request.problem_id, base))
        report.problem_id = problem.id
        stage("validating")
        with build_limit(problem.doc.file):  # validate's limit, and its message
            built = build_systems(problem)  # one not physical is refused with the reason
        analysis = Analysis(problem, built=built)
        stage("deriving and integrating")
        sim = simulate(analysis, request.system, init=parse_assignments(request.init),
                       t_span=(0.0, request.t_end), method=request.method,
                       points=request.points, backend=request.backend or DEFAULT_BACKEND,
                       accuracy=request.accuracy,
                       parameters=parse_assignments(request.params), rtol=request.rtol,
                       atol=request.atol, max_step=request.max_step, step=request.step)
    except (MechbookError, KeyError) as exc:
        report.error = message(exc)
        return report
    except Exception as exc:  # noqa: BLE001 - a message; the traceback to the debug log
        report.error = f"simulate {request.problem_id}: {describe(exc)}"
        return report
    traj = sim.trajectory
    out = report.lines
    out.append(f"{problem.id} [{sim.system}]: {problem.title}")
    out.append("initial: " + ", ".join(f"{k}={v:.6g}" for k, v in sim.initial.items())
               + f"  ({sim.initial_source})")
    if sim.choice:
        out.append(f"accuracy: {sim.choice}")
    out.append("method: " + ", ".join(f"{k}={v}" for k, v in traj.settings.items())
               + f"; {traj.nfev} evaluations, {len(traj.t)} samples, {sim.seconds:.2f} s "
               f"(RHS: {sim.model.backend}, generated in {sim.model.generation_seconds:.3f} s)")
    out.extend(f"note: {note}" for note in sim.notes)
    if sim.drifts:
        out.extend("drift of " + d.summary() for d in sim.drifts)
    else:
        out.append("no conserved quantity found by the engine: nothing to monitor")
    report.system, report.method, report.success = sim.system, traj.method, bool(traj.success)
    report.arrays, report.settings = sim.arrays(), sim.settings()
    report.array_attrs = {f"monitors/{d.name}": d.attrs() for d in sim.drifts}
    if request.plot is not None:
        stage("plotting")
        report.plot = str(plot_simulation(sim, Path(request.plot)))
    return report


def simulation_stopped(request: SimRequest, why: str, seconds: float, stage: str) -> SimReport:
    return SimReport(request.problem_id, error=f"simulate {request.problem_id}: {why}",
                     stage=stage)


def run_simulation(request: SimRequest, base: Path, timeout: float, memory_mb: float,
                   serial: bool = False) -> SimReport:
    """One simulation in a worker under the limits (or here, with `serial`)."""
    options = BatchOptions(jobs=1, timeout=timeout, memory_mb=memory_mb, serial=serial,
                           run=None)
    batch = Batch(base, options, task=simulate_task, failed=simulation_stopped)
    return batch.run([request])[0]
