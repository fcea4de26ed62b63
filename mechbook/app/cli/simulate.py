"""`mechbook simulate`: integrate a problem's full equations in a worker under limits, print
the drift of its conserved quantities, store the trajectory (and plot it)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from mechbook.app import options as opt
from mechbook.app.cli.common import (
    OwnedChoice,
    backend_option,
    checked_output,
    given,
    in_tree,
    memory_option,
    name_option,
    no_store_option,
    plot_option,
    problem_id_argument,
    resolve_root,
    say,
    serial_option,
    store_option,
    system_option,
    timeout_option,
)
from mechbook.app.cli.statuses import failure
from mechbook.app.output.text import for_terminal
from mechbook.errors import MechbookError
from mechbook.model.catalog import existing_problem_path

# an integrator option given on the command line, by the keyword the integrator takes
TOLERANCES = {"rtol": "--rtol", "atol": "--atol", "max_step": "--max-step", "step": "--step"}


@click.command("simulate")
@problem_id_argument()
@system_option()
@click.option("--method", default=None, type=OwnedChoice("mechbook.numerics.methods", "CHOICES"),
              help="SciPy's solve_ivp methods; RK4 (fixed step); symplectic leapfrog "
                   "(Störmer–Verlet) and yoshida4 (Forest–Ruth) for separable Hamiltonians, "
                   "midpoint (implicit, symplectic) for any conservative system; taylor "
                   "(heyoka's Taylor method, tolerance --rtol, default machine epsilon; "
                   "pip install 'mechbook[taylor]'). Default: DOP853, or Radau when the run "
                   "is stiff.")
@click.option("--accuracy", type=opt.Finite(min=0, min_open=True, max=1, max_open=True),
              default=None,
              help="Error wanted at the end (relative to each coordinate's and velocity's "
                   "scale): chooses the method (unless given) and tolerance from the measured "
                   "rule (docs/performance.md) and prints the error to expect.")
@click.option("--param", "params", multiple=True, metavar="NAME=VALUE",
              help="Override a parameter's default value (k=1e6). Repeat for several.")
@click.option("--rtol", type=opt.Finite(min=0, min_open=True, max=1, max_open=True),
              default=None, help="Relative tolerance (SciPy methods; default 1e-8; the taylor "
                                 "method's tolerance).")
@click.option("--atol", type=opt.Finite(min=0, max=1e6), default=None,
              help="Absolute tolerance (SciPy methods; default 1e-10).")
@click.option("--max-step", type=opt.Finite(min=0, min_open=True, max=opt.MAX_TIME),
              default=None, help="Largest step (SciPy methods).")
@click.option("--step", type=opt.Finite(min=0, min_open=True, max=opt.MAX_TIME), default=None,
              help="Step size of the fixed-step methods (default: the span / 10000).")
@click.option("--t-end", type=opt.Finite(min=0, min_open=True, max=opt.MAX_TIME),
              default=10.0, show_default=True, help="End time.")
@click.option("--points", type=click.IntRange(min=2, max=opt.MAX_POINTS), default=2001,
              show_default=True,
              help="Samples recorded (SciPy and taylor methods; fixed-step methods record "
                   "every step up to 200001 samples).")
@click.option("--init", "init", multiple=True, metavar="NAME=VALUE",
              help="Initial value of a coordinate (theta=0.1) or velocity (thetadot=0); "
                   "overrides the problem's `initial:`. Repeat for several.")
@backend_option("How the equations are compiled (default: llvm; see docs/numerics.md).", None)
@plot_option("Write coordinates against time and the phase portrait here.")
@name_option("Name of the stored run (default SYSTEM-METHOD).")
@store_option("HDF5 file to store the run in.")
@no_store_option("Do not store the run.")
@timeout_option("Wall-clock seconds allowed for the run (loading, deriving, integrating, "
                "plotting); past it the run is stopped and reported with its stage.")
@memory_option("Resident memory (MB) allowed for the run (0: no bound).")
@serial_option("Run in this process, without time or memory limits (for a debugger).")
@click.pass_context
def command(ctx: click.Context, problem_id: str, system: str | None, method: str | None,
            accuracy: float | None, params: tuple[str, ...], rtol: float | None,
            atol: float | None, max_step: float | None,
            step: float | None, t_end: float, points: int, init: tuple[str, ...],
            backend: str | None, plot_path: Path | None, name: str | None,
            store_path: Path, no_store: bool, timeout: float, memory_mb: float,
            serial: bool) -> None:
    """Integrate a problem's full nonlinear equations of motion; report the drift of every
    conserved quantity the engine found; store the trajectory (and plot it). The run has a
    time limit and a memory bound (a worker process stopped from outside when it exceeds
    either); exceeding one is reported with the stage the run was in, exit status 1."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.running.simrun import SimRequest, run_simulation
    from mechbook.app.store import check_run_name

    _refuse_what_does_not_apply(ctx, method, accuracy, serial)
    base = resolve_root(ctx)
    path = in_tree(ctx, store_path)
    try:
        existing_problem_path(problem_id, base)
        if name is not None:
            check_run_name(name, "simulation")
    except MechbookError as exc:  # no such problem: its own status (statuses.TABLE)
        raise failure(exc) from None
    if not no_store:
        checked_output(path, "store")
    checked_output(plot_path, "plot")
    request = SimRequest(problem_id, system, method, accuracy, tuple(params), rtol, atol,
                         max_step, step, t_end, points, tuple(init), backend,
                         str(plot_path) if plot_path is not None else None)
    report = run_simulation(request, base, timeout, memory_mb, serial)
    if report.error:
        raise click.ClickException(for_terminal(report.error))
    for line in report.lines:
        say(line)
    failed = not report.success
    if not no_store:
        failed = not _store(report, name, path) or failed
    if report.plot is not None:
        say(f"plot written to {report.plot}")
    if failed:
        sys.exit(1)


def _refuse_what_does_not_apply(ctx: click.Context, method: str | None,
                                accuracy: float | None, serial: bool) -> None:
    """An option the run would drop silently is refused, saying why: a tolerance or step
    the method does not take (mechbook.numerics.methods.OPTIONS; no --method: DOP853 or
    Radau, SciPy's), --points for a fixed-step method, limits with --serial."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.numerics.methods import OPTIONS, kind, why_not

    if method is not None or accuracy is None:  # with --accuracy alone the method is chosen
        family = kind(method or "DOP853")
        keys = [key for key in TOLERANCES if given(ctx, key) and key not in OPTIONS[family]]
        unused = [TOLERANCES[key] for key in keys]
        if family in ("fixed", "midpoint") and given(ctx, "points"):
            unused.append("--points")
        if unused:
            raise click.UsageError(
                f"{', '.join(unused)} {'does' if len(unused) == 1 else 'do'} not apply to "
                f"the {family} method {method or 'DOP853 (the default)'}; it takes "
                f"{', '.join(TOLERANCES.get(k, '') for k in OPTIONS[family] if k in TOLERANCES)}"
                + "".join(f" ({why_not(k, method or 'DOP853')})" for k in keys[:1]))
    dropped = [flag for key, flag in (("timeout", "--timeout"), ("memory_mb", "--memory"))
               if serial and given(ctx, key)]
    if dropped:
        raise click.UsageError(f"--serial runs in this process without limits: "
                               f"{', '.join(dropped)} would have no effect; drop one")


def _store(report, name: str | None, path: Path) -> bool:
    """Write the run to the store; on failure keep it in a side file and say where."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.store import StoreError, write_simulation
    from mechbook.app.store.unsaved import SideFile

    run_name = name or f"{report.system}-{report.method}"
    try:
        write_simulation(report.problem_id, run_name, report.arrays, report.settings,
                         report.array_attrs, path)
        say(f"stored as /problems/{report.problem_id}/simulations/{run_name} in {path}")
        return True
    except StoreError as exc:
        side = SideFile(path).keep("simulation", {
            "problem_id": report.problem_id, "name": run_name, "arrays": report.arrays,
            "attrs": report.settings, "array_attrs": report.array_attrs})
        say(f"error: {exc}", err=True)
        say(f"error: the simulation is kept in {side} (`mechbook restore {side} --store "
            f"{path.absolute()}` stores it once the cause is fixed)" if side else
            "error: the simulation could not be kept anywhere", err=True)
        return False
