"""The `mechbook` command line: list, solve, check, validate, show, simulate."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from mechbook import __version__
from mechbook.app.batch import DEFAULT_MEMORY_MB, DEFAULT_TIMEOUT
from mechbook.app.console import Progress, print_table
from mechbook.errors import MechbookError
from mechbook.model.catalog import DEFAULT_STORE, all_ids, answer_path, problem_path, root

# The engine (SymPy, SciPy) is imported inside the commands that need it, so --help, list
# and argument errors answer at once.
DEFAULT_PATH = DEFAULT_STORE


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="mechbook")
@click.option("--root", "root_dir", type=click.Path(file_okay=False, path_type=Path),
              default=None,
              help="Tree holding problems/ and answers/ (default: nearest parent, or "
                   "$MECHBOOK_ROOT).")
@click.pass_context
def main(ctx: click.Context, root_dir: Path | None) -> None:
    """mechbook: textbook mechanics problems as Lagrangian systems, checked against the book."""
    ctx.ensure_object(dict)
    ctx.obj["root_opt"] = root_dir


def _resolve_root(ctx: click.Context) -> Path:
    opt = ctx.obj.get("root_opt")
    try:
        return Path(opt) if opt else root()
    except MechbookError as exc:
        raise click.ClickException(str(exc)) from None


@main.command("list")
@click.pass_context
def list_cmd(ctx: click.Context) -> None:
    """List every problem with its title and number of answer parts; an invalid file is
    marked INVALID with the reason (and the exit status is 1)."""
    from mechbook.model.problem import load_problem
    from mechbook.verify.answers import load_answers

    base = _resolve_root(ctx)
    invalid = 0
    for pid in all_ids(base):
        try:
            p = load_problem(problem_path(pid, base))
            title = p.title
        except MechbookError as exc:
            title = f"INVALID: {exc}"
            invalid += 1
        parts = "no answer key"
        try:
            apath = answer_path(pid, base)
            if apath.exists():
                parts = f"{len(load_answers(apath).parts)} parts"
        except MechbookError:
            parts = "INVALID answer key"
            invalid += 1
        click.echo(f"{pid:<22} {parts:<16} {title}")
    if invalid:
        click.echo(f"{invalid} invalid file(s)", err=True)
        sys.exit(1)


@main.command()
@click.argument("problem_id")
@click.option("--system", default=None, help="Which system of a multi-system problem.")
@click.option("--no-simplify", is_flag=True, help="Skip SymPy simplification (faster).")
@click.pass_context
def solve(ctx: click.Context, problem_id: str, system: str | None, no_simplify: bool) -> None:
    """Derive and print a problem's results (what its `compute:` asks for), simplified."""
    from mechbook.engine.analysis import Analysis
    from mechbook.engine.derive import derive
    from mechbook.model.problem import load_problem

    base = _resolve_root(ctx)
    try:
        problem = load_problem(problem_path(problem_id, base))
        analysis = Analysis(problem, simplify=not no_simplify)
        names = [system] if system else list(problem.systems)
        click.echo(f"{problem.id}: {problem.title}  [{problem.source}]")
        for name in names:
            res = derive(analysis, name)
            if len(problem.systems) > 1:
                click.echo(f"\n== system {name}")
            for key, text in res.text.items():
                click.echo(f"{key}:\n    {text}")
            for key, arr in res.arrays.items():
                click.echo(f"{key} (numeric, default parameters):\n    {arr.tolist()}")
            for key, text in res.notes.items():
                click.echo(f"{key}: {text}")
    except (MechbookError, KeyError) as exc:
        raise click.ClickException(str(exc)) from None


@main.command()
@click.argument("problem_ids", nargs=-1)
@click.option("--store", "store_path", type=click.Path(dir_okay=False, path_type=Path),
              default=DEFAULT_PATH, show_default=True, help="HDF5 file to write results to.")
@click.option("--no-store", is_flag=True, help="Do not write results.")
@click.option("-v", "--verbose", is_flag=True, help="Show the method and detail of every part.")
@click.option("--fresh", is_flag=True,
              help="Recompute everything; by default a problem whose problem file, answer key "
                   "and engine are unchanged since the stored run reuses the stored outcomes.")
@click.option("--no-crosscheck", is_flag=True,
              help="Skip the independent cross-checks (simulated frequencies, Newton's law).")
@click.option("-j", "--jobs", type=click.IntRange(min=0), default=0, show_default=True,
              help="Worker processes (0: one per core).")
@click.option("--timeout", type=click.FloatRange(min=0, min_open=True),
              default=DEFAULT_TIMEOUT, show_default=True,
              help="Wall-clock seconds allowed per problem; a problem that takes longer is "
                   "stopped and reported as an error with the stage it was in.")
@click.option("--memory", "memory_mb", type=click.FloatRange(min=0), default=DEFAULT_MEMORY_MB,
              show_default=True, help="Resident memory (MB) allowed per problem (0: no bound).")
@click.option("--serial", is_flag=True,
              help="Check in this process, one problem after another, without time or memory "
                   "limits (for a debugger).")
@click.option("--prove", is_flag=True,
              help="After a part passes numerically (30 digits at random admissible points), "
                   "also try a symbolic proof with SymPy; the method column says which it got.")
@click.option("--prove-seconds", type=click.FloatRange(min=0, min_open=True), default=10.0,
              show_default=True, help="Time limit of each symbolic proof attempt.")
@click.pass_context
def check(ctx: click.Context, problem_ids: tuple[str, ...], store_path: Path, no_store: bool,
          verbose: bool, fresh: bool, no_crosscheck: bool, jobs: int, timeout: float,
          memory_mb: float, serial: bool, prove: bool, prove_seconds: float) -> None:
    """Check problems against their answer keys (all by default); exit 1 on any fail.

    Problems run in parallel worker processes, the longest first; each finished problem is
    written to the store at once, so an interrupted run keeps what it finished and the next
    run resumes from there. The cross-check column is independent of the book: each
    frequency part's linear system is confirmed by simulating the nonlinear equations along
    every mode, and each system's Lagrange equations against Newton's law
    (docs/numerics.md); a cross-check fail also exits 1."""
    from mechbook.app.batch import Batch, BatchOptions
    from mechbook.app.run import ProblemRun, RunOptions, cached_runs
    from mechbook.app.store import durations, write
    from mechbook.records import ProofPolicy

    base = _resolve_root(ctx)
    ids = list(problem_ids) or all_ids(base)
    if not ids:
        raise click.ClickException(f"no problems under {base / 'problems'}")
    refused: dict[str, ProblemRun] = {}  # files found under problems/ with unusable names
    for pid in ids:
        try:
            if not problem_path(pid, base).exists():
                raise click.ClickException(f"no problem {pid} (no file "
                                           f"{problem_path(pid, base)})")
        except MechbookError as exc:
            if problem_ids:
                raise click.ClickException(str(exc)) from None
            refused[pid] = ProblemRun(pid, error=str(exc))
    store_file = store_path if store_path.is_absolute() else base / store_path
    good = [pid for pid in ids if pid not in refused]
    runs = {} if (fresh or no_store) else cached_runs(good, base, store_file, not no_crosscheck)
    runs.update(refused)
    progress = Progress(len(ids), 0)
    for pid in ids:
        if pid in runs:
            progress.finished(runs[pid])

    def finished(run) -> None:
        progress.finished(run)
        if run.record is not None and not no_store:
            write([run.record], store_file)

    past = durations(store_file)
    todo = sorted((pid for pid in ids if pid not in runs),
                  key=lambda pid: -past.get(pid, float("inf")))
    options = BatchOptions(jobs, timeout, memory_mb, serial=serial, run=RunOptions(
        crosscheck=not no_crosscheck, policy=ProofPolicy(prove, prove_seconds)))
    try:
        for run in Batch(base, options, on_done=finished).run(todo):
            runs[run.pid] = run
    finally:
        progress.close()
    ordered = [runs[pid] for pid in ids]
    print_table(ordered, verbose)
    if not no_store and any(r.record is not None for r in ordered):
        click.echo(f"results written to {store_file}")
    bad = sum(1 for r in ordered if r.error) + sum(1 for r in ordered for o in r.outcomes
                                                   if o.status in ("fail", "error"))
    bad += sum(1 for r in ordered for x in r.crosschecks if x.failed)
    if bad:
        click.echo(f"{bad} failure(s)", err=True)
        sys.exit(1)


@main.command()
@click.argument("files", nargs=-1, required=True,
                type=click.Path(exists=True, dir_okay=False, path_type=Path))
def validate(files: tuple[Path, ...]) -> None:
    """Validate problem or answer files (schema and every expression); nothing runs."""
    from mechbook.app.validate import validate_file

    bad = 0
    for f in files:
        try:
            click.echo(validate_file(f))
        except MechbookError as exc:
            click.echo(f"invalid: {exc}", err=True)
            bad += 1
    if bad:
        sys.exit(1)


@main.command()
@click.argument("problem_id")
@click.option("--store", "store_path", type=click.Path(dir_okay=False, path_type=Path),
              default=DEFAULT_PATH, show_default=True, help="HDF5 file to read.")
@click.pass_context
def show(ctx: click.Context, problem_id: str, store_path: Path) -> None:
    """Print a problem's stored results and checks, read back from the HDF5 store."""
    from mechbook.app.store import read
    from mechbook.model.catalog import check_id

    base = _resolve_root(ctx)
    path = store_path if store_path.is_absolute() else base / store_path
    try:
        rec = read(check_id(problem_id), path)
    except MechbookError as exc:
        raise click.ClickException(str(exc)) from None
    except (FileNotFoundError, KeyError) as exc:
        raise click.ClickException(str(exc).strip("'\"")) from None
    a = rec["attrs"]
    click.echo(f"{problem_id}: {a.get('title')}  [{a.get('source')}]")
    click.echo(f"stored {a.get('date')} by mechbook {a.get('mechbook')} (SymPy {a.get('sympy')}, "
               f"NumPy {a.get('numpy')}); {a.get('duration_s', 0):.1f} s; problem sha256 "
               f"{str(a.get('problem_sha256'))[:12]}")
    for sname, entry in rec["systems"].items():
        click.echo(f"\n== system {sname}")
        for key, text in entry["symbolic"].items():
            click.echo(f"{key}: {text}")
        for key, arr in entry["numeric"].items():
            click.echo(f"{key} (numeric): {arr.tolist()}")
        for key, text in entry["notes"].items():
            click.echo(f"{key}: {text}")
    click.echo("\n== checks")
    for c in rec["checks"]:
        click.echo(f"{c['part']:<16} {c['quantity']:<20} {c['status']:<12} {c['method']} "
                   f"{c['detail']}".rstrip())
    if rec.get("crosschecks"):
        click.echo("\n== cross-checks")
        for x in rec["crosschecks"]:
            parts = ", ".join(x.get("parts") or []) or "-"
            click.echo(f"{x['name']} [{x['status']}, error {x.get('error', float('nan')):.1e}; "
                       f"parts: {parts}] {x.get('detail', '')}")
    for name in rec.get("simulations", []):
        click.echo(f"simulation stored: /problems/{problem_id}/simulations/{name}")


@main.command()
@click.argument("problem_id")
@click.option("--system", default=None, help="Which system of a multi-system problem.")
@click.option("--method", default=None,
              type=click.Choice(["RK45", "DOP853", "Radau", "LSODA", "RK4", "leapfrog",
                                 "yoshida4", "midpoint"]),
              help="SciPy's solve_ivp methods; RK4 (fixed step); symplectic leapfrog "
                   "(Störmer–Verlet) and yoshida4 (Forest–Ruth) for separable Hamiltonians, "
                   "midpoint (implicit, symplectic) for any conservative system. Default: "
                   "DOP853, or Radau when the run is stiff.")
@click.option("--accuracy", type=float, default=None,
              help="Error wanted at the end (relative to each coordinate's and velocity's "
                   "scale): chooses the method (unless given) and tolerance from the measured "
                   "rule (docs/performance.md) and prints the error to expect.")
@click.option("--param", "params", multiple=True, metavar="NAME=VALUE",
              help="Override a parameter's default value (k=1e6). Repeat for several.")
@click.option("--rtol", type=float, default=None, help="Relative tolerance (SciPy methods; "
              "default 1e-8).")
@click.option("--atol", type=float, default=None, help="Absolute tolerance (SciPy methods; "
              "default 1e-10).")
@click.option("--max-step", type=float, default=None, help="Largest step (SciPy methods).")
@click.option("--step", type=float, default=None,
              help="Step size of the fixed-step methods (default: the span / 10000).")
@click.option("--t-end", type=float, default=10.0, show_default=True, help="End time.")
@click.option("--points", type=int, default=2001, show_default=True,
              help="Samples recorded (SciPy methods; fixed-step methods record every step "
                   "up to 200001 samples).")
@click.option("--init", "init", multiple=True, metavar="NAME=VALUE",
              help="Initial value of a coordinate (theta=0.1) or velocity (thetadot=0); "
                   "overrides the problem's `initial:`. Repeat for several.")
@click.option("--backend", type=click.Choice(["llvm", "symengine", "sympy"]), default=None,
              help="How the equations are compiled (default: llvm; see docs/numerics.md).")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Write coordinates against time and the phase portrait here.")
@click.option("--name", default=None, help="Name of the stored run (default SYSTEM-METHOD).")
@click.option("--store", "store_path", type=click.Path(dir_okay=False, path_type=Path),
              default=DEFAULT_PATH, show_default=True, help="HDF5 file to store the run in.")
@click.option("--no-store", is_flag=True, help="Do not store the run.")
@click.option("--timeout", type=click.FloatRange(min=0, min_open=True),
              default=DEFAULT_TIMEOUT, show_default=True,
              help="Wall-clock seconds allowed for the run (loading, deriving, integrating, "
                   "plotting); past it the run is stopped and reported with its stage.")
@click.option("--memory", "memory_mb", type=click.FloatRange(min=0), default=DEFAULT_MEMORY_MB,
              show_default=True, help="Resident memory (MB) allowed for the run (0: no bound).")
@click.option("--serial", is_flag=True,
              help="Run in this process, without time or memory limits (for a debugger).")
@click.pass_context
def simulate(ctx: click.Context, problem_id: str, system: str | None, method: str | None,
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
    from mechbook.app.simrun import SimRequest, run_simulation
    from mechbook.app.store import write_simulation
    from mechbook.model.catalog import check_id

    base = _resolve_root(ctx)
    try:
        check_id(problem_id)
    except MechbookError as exc:
        raise click.ClickException(str(exc)) from None
    request = SimRequest(problem_id, system, method, accuracy, tuple(params), rtol, atol,
                         max_step, step, t_end, points, tuple(init), backend,
                         str(plot_path) if plot_path is not None else None)
    report = run_simulation(request, base, timeout, memory_mb, serial)
    if report.error:
        raise click.ClickException(report.error)
    for line in report.lines:
        click.echo(line)
    if not no_store:
        path = store_path if store_path.is_absolute() else base / store_path
        run_name = name or f"{report.system}-{report.method}"
        write_simulation(report.problem_id, run_name, report.arrays, report.settings,
                         report.array_attrs, path)
        click.echo(f"stored as /problems/{report.problem_id}/simulations/{run_name} in {path}")
    if report.plot is not None:
        click.echo(f"plot written to {report.plot}")
    if not report.success:
        sys.exit(1)
