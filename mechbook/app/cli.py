"""The `mechbook` command line: list, solve, check, validate, show, simulate, sweep, report,
completion.

Only click and a few small modules are imported at the top: --help, list, shell completion
and argument errors answer without loading SymPy, NumPy or the engine, which each command
imports when it runs (a test keeps it so; docs/performance.md has the timing).
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path

import click

from mechbook.app import options as opt
from mechbook.app.limits import DEFAULT_MEMORY_MB, DEFAULT_TIMEOUT
from mechbook.app.text import for_terminal
from mechbook.errors import MechbookError
from mechbook.model.catalog import DEFAULT_STORE, all_ids, answer_path, problem_path, root
from mechbook.version import __version__

DEFAULT_PATH = DEFAULT_STORE
SHELLS = ("bash", "zsh", "fish")
PLOT_SUFFIXES = (".png", ".svg", ".pdf", ".eps", ".ps", ".jpg", ".jpeg", ".tif", ".tiff",
                 ".webp")


def _say(text: str = "", err: bool = False) -> None:
    """Print text that may come from a problem file or the store: control characters and
    escape sequences are shown as escapes, never sent to the terminal."""
    click.echo(for_terminal(text), err=err)


class _Warnings(logging.Handler):
    """mechbook's warnings (a damaged store moved aside) on stderr; with -v, debug records
    (the tracebacks of unexpected errors) too."""

    def emit(self, record: logging.LogRecord) -> None:
        label = "warning" if record.levelno >= logging.WARNING else "debug"
        _say(f"{label}: {record.getMessage()}", err=True)


def _logging(verbose: bool = False) -> None:
    logger = logging.getLogger("mechbook")
    if not any(isinstance(h, _Warnings) for h in logger.handlers):
        logger.addHandler(_Warnings())
    logger.setLevel(logging.DEBUG if verbose else logging.WARNING)


def _output(path: Path | None, what: str) -> Path | None:
    """An output path checked before any work: a regular file or nothing (a link is
    followed to its file); a plot's suffix must name a format."""
    from mechbook.app.outputs import OutputError, output_file

    if path is None:
        return None
    if what == "plot" and path.suffix.lower() not in PLOT_SUFFIXES:
        raise click.BadParameter(f"{path}: the suffix names the format; use one of "
                                 f"{', '.join(PLOT_SUFFIXES)}", param_hint="--plot")
    try:
        output_file(path, what)
    except OutputError as exc:
        raise click.ClickException(str(exc)) from None
    return path


def _numeric_text(key: str, arr, arrays: dict) -> str:
    """An array of results as text; frequencies with each unstable mode's growth rate
    instead of NaN (mechbook.engine.growth)."""
    if key.endswith("/frequencies"):
        from mechbook.engine.growth import describe

        return describe(list(arr), arrays.get(key.replace("/frequencies", "/growth_rates")))
    return str(arr.tolist())


def _complete_ids(ctx: click.Context, param: click.Parameter, incomplete: str) -> list:
    """Shell completion of problem ids: the files under the tree's problems/ (no engine)."""
    from click.shell_completion import CompletionItem

    try:
        opt = ctx.find_root().params.get("root_dir")
        base = Path(opt) if opt else root()
        ids = all_ids(base)
    except (MechbookError, OSError):
        return []
    return [CompletionItem(pid) for pid in ids if pid.startswith(incomplete)]


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
    _logging()
    from mechbook.app.quiet import install

    install(lambda text: _say(text, err=True))  # warnings as one-line notes, no traceback


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
    marked INVALID with the reason (and the exit status is 1).

    Reads the files' YAML (under the input limits) and the problem schema only (fast, no
    engine): `mechbook validate` checks every expression."""
    from mechbook.model.books import file_id_error
    from mechbook.model.schema import validate
    from mechbook.model.yamlio import load

    base = _resolve_root(ctx)
    invalid = 0
    for pid in all_ids(base):
        try:
            doc = load(problem_path(pid, base))
            validate(doc, "problem")
            why = file_id_error(doc.data["id"], problem_path(pid, base))
            if why:
                raise doc.error(("id",), why)
            title = doc.data["title"]
        except MechbookError as exc:
            title = f"INVALID: {exc}"
            invalid += 1
        parts = "no answer key"
        try:
            apath = answer_path(pid, base)
            if apath.exists():
                found = load(apath).data.get("parts")
                if isinstance(found, list):
                    parts = f"{len(found)} parts"
                else:
                    parts = "INVALID answer key"
                    invalid += 1
        except MechbookError:
            parts = "INVALID answer key"
            invalid += 1
        _say(f"{pid:<22} {parts:<16} {title}")
    if invalid:
        click.echo(f"{invalid} invalid file(s)", err=True)
        sys.exit(1)


@main.command()
@click.argument("problem_id", shell_complete=_complete_ids)
@click.option("--system", default=None, help="Which system of a multi-system problem.")
@click.option("--no-simplify", is_flag=True, help="Skip SymPy simplification (faster).")
@click.pass_context
def solve(ctx: click.Context, problem_id: str, system: str | None, no_simplify: bool) -> None:
    """Derive and print a problem's results (what its `compute:` asks for), simplified."""
    from mechbook.app.api import load
    from mechbook.engine.derive import declared_results, derive
    from mechbook.model.declared import declared

    base = _resolve_root(ctx)
    try:
        problem = load(problem_id, base, simplify=not no_simplify)
        names = [system] if system else problem.systems
        click.echo(f"{problem.id}: {problem.title}  [{problem.source}]")
        for name in names:
            res = derive(problem.analysis, name)
            if len(problem.systems) > 1:
                click.echo(f"\n== system {name}")
            for key, text in res.text.items():
                click.echo(f"{key}:\n    {text}")
            for key, arr in res.arrays.items():
                if not key.endswith("/growth_rates"):
                    click.echo(f"{key} (numeric, default parameters):\n    "
                               f"{_numeric_text(key, arr, res.arrays)}")
            for key, text in res.notes.items():
                click.echo(f"{key}: {text}")
        if not names or any(k in problem.model.doc.data for k in ("vectors", "tensors",
                                                                 "bodies")):
            declared(problem.model)  # a problem's own vectors, tensors and bodies
            res = declared_results(problem.analysis)
            click.echo("\n== declared vectors, tensors and bodies")
            for key, text in res.text.items():
                click.echo(f"{key}:\n    {text}")
    except (MechbookError, KeyError) as exc:
        raise click.ClickException(str(exc)) from None


@main.command()
@click.argument("problem_ids", nargs=-1, shell_complete=_complete_ids)
@click.option("--store", "store_path", type=click.Path(dir_okay=False, path_type=Path),
              default=DEFAULT_PATH, show_default=True, help="HDF5 file to write results to.")
@click.option("--no-store", is_flag=True, help="Do not write results.")
@click.option("-v", "--verbose", is_flag=True, help="Show the method and detail of every part.")
@click.option("--fresh", is_flag=True,
              help="Recompute everything; by default a problem whose problem file, answer key "
                   "and engine are unchanged since the stored run reuses the stored outcomes.")
@click.option("--no-crosscheck", is_flag=True,
              help="Skip the independent cross-checks (simulated frequencies, Newton's law).")
@click.option("-j", "--jobs", type=opt.jobs(), default=0, show_default=True,
              help="Worker processes (0: one per core).")
@click.option("--timeout", type=opt.seconds(), default=DEFAULT_TIMEOUT, show_default=True,
              help="Wall-clock seconds allowed per problem; a problem that takes longer is "
                   "stopped and reported as an error with the stage it was in.")
@click.option("--memory", "memory_mb", type=opt.memory(), default=DEFAULT_MEMORY_MB,
              show_default=True, help="Resident memory (MB) allowed per problem (0: no bound).")
@click.option("--serial", is_flag=True,
              help="Check in this process, one problem after another, without time or memory "
                   "limits (for a debugger).")
@click.option("--prove", is_flag=True,
              help="After a part passes numerically (30 digits at random admissible points), "
                   "also try a symbolic proof with SymPy; the method column says which it got.")
@click.option("--prove-seconds", type=opt.seconds(opt.MAX_STEP_SECONDS), default=10.0,
              show_default=True, help="Time limit of each symbolic proof attempt.")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Run the problems on the Dask cluster whose scheduler is at ADDRESS "
                   "(tcp://host:8786; default $MECHBOOK_SCHEDULER, else the local pool). "
                   "The limits hold per problem on the workers.")
@click.option("--format", "fmt", type=click.Choice(["table", "json"]), default="table",
              show_default=True,
              help="table: for people; json: one JSON document on stdout (its schema: "
                   "mechbook/app/schemas/check-result.json), progress stays on stderr.")
@click.option("--junit-xml", "junit_path", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Also write the outcomes as JUnit XML here (for CI).")
@click.pass_context
def check(ctx: click.Context, problem_ids: tuple[str, ...], store_path: Path, no_store: bool,
          verbose: bool, fresh: bool, no_crosscheck: bool, jobs: int, timeout: float,
          memory_mb: float, serial: bool, prove: bool, prove_seconds: float,
          scheduler: str | None, fmt: str, junit_path: Path | None) -> None:
    """Check problems against their answer keys (all by default); exit 1 on any fail.

    Problems run in parallel worker processes, the longest first; each finished problem is
    written to the store at once, so an interrupted run keeps what it finished and the next
    run resumes from there. The cross-check column is independent of the book: each
    frequency part's linear system is confirmed by simulating the nonlinear equations along
    every mode, and each system's Lagrange equations against Newton's law
    (docs/numerics.md); a cross-check fail also exits 1."""
    import json

    from mechbook.app.batch import Batch, BatchOptions
    from mechbook.app.console import Progress, print_table
    from mechbook.app.formats import failures, to_json, write_junit
    from mechbook.app.run import ProblemRun, RunOptions, cached_runs
    from mechbook.app.store import durations
    from mechbook.app.text import json_safe
    from mechbook.app.unsaved import Saver
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
    if not no_store:
        _output(store_file, "store")
    if junit_path is not None:
        _output(junit_path, "JUnit XML file")
    _logging(verbose)
    good = [pid for pid in ids if pid not in refused]
    runs = {} if (fresh or no_store) else cached_runs(good, base, store_file, not no_crosscheck)
    runs.update(refused)
    progress = Progress(len(ids), 0)
    for pid in ids:
        if pid in runs:
            progress.finished(runs[pid])
    saver = Saver(store_file)

    def finished(run) -> None:
        progress.finished(run)
        if verbose:
            for text in run.debug:
                _say(f"debug: {run.pid}: {text}", err=True)
        if run.record is not None and not no_store:
            saver.save(run.record)  # never raises: a failure keeps the record aside

    past = durations(store_file)
    todo = sorted((pid for pid in ids if pid not in runs),
                  key=lambda pid: -past.get(pid, float("inf")))
    options = BatchOptions(jobs, timeout, memory_mb, serial=serial, run=RunOptions(
        crosscheck=not no_crosscheck, policy=ProofPolicy(prove, prove_seconds)))
    from mechbook.app.distributed import ClusterBatch, scheduler_address

    address = None if serial else scheduler_address(scheduler)
    try:
        batch = ClusterBatch(address, base, options, on_done=finished) if address and todo \
            else Batch(base, options, on_done=finished)
        for run in batch.run(todo):
            runs[run.pid] = run
    except MechbookError as exc:
        raise click.ClickException(str(exc)) from None
    finally:
        progress.close()
    ordered = [runs[pid] for pid in ids]
    stored = not no_store and saver.error is None and \
        any(r.record is not None or r.cached for r in ordered)
    if fmt == "json":
        doc = to_json(ordered, base, store_file if stored else None,
                      str(saver.error) if saver.error else None)
        click.echo(json.dumps(json_safe(doc), indent=1, ensure_ascii=False))
    else:
        print_table(ordered, verbose)
        if saver.written and saver.error is None:
            _say(f"results written to {store_file}")
    unwritten = False
    if junit_path is not None:
        try:
            _say(f"JUnit XML written to {write_junit(ordered, junit_path)}", err=True)
        except MechbookError as exc:
            _say(f"error: {exc}", err=True)
            unwritten = True
    for line in saver.report():
        _say(line, err=True)
    bad = failures(ordered)
    if bad:
        click.echo(f"{bad} failure(s)", err=True)
    if bad or saver.error is not None or unwritten:
        sys.exit(1)


@main.command()
@click.argument("files", nargs=-1, required=True,
                type=click.Path(exists=True, dir_okay=False, path_type=Path))
def validate(files: tuple[Path, ...]) -> None:
    """Validate problem or answer files (schema and every expression); nothing runs."""
    from mechbook.app.validate import validate_file

    bad = 0
    refused: set[Path] = set()  # problem files already reported invalid
    for f in files:
        try:
            _say(validate_file(f))
        except MechbookError as exc:
            bad += 1
            problem = getattr(exc, "problem_file", None)
            if problem is not None and Path(problem).resolve() in refused:
                _say(f"invalid: {f}: its problem file {problem} is invalid (above)", err=True)
                continue
            refused.add(Path(getattr(exc, "file", None) or f).resolve())
            _say(f"invalid: {exc}", err=True)
    if bad:
        sys.exit(1)


@main.command()
@click.argument("problem_id", shell_complete=_complete_ids)
@click.option("--no-crosscheck", is_flag=True, help="Check the book's answers only.")
@click.option("--seconds", type=opt.seconds(), default=120.0, show_default=True,
              help="CPU seconds allowed for each check.")
@click.option("--runs", type=click.IntRange(min=0), default=0, hidden=True,
              help="Stop after this many checks (tests).")
@click.pass_context
def watch(ctx: click.Context, problem_id: str, no_crosscheck: bool, seconds: float,
          runs: int) -> None:
    """Check a problem now and again each time its problem file or answer key is saved,
    with the engine kept loaded (a save is answered in the time the check takes, a few
    tenths of a second for a small problem). Ctrl-C stops; nothing is stored."""
    from mechbook.app.watch import WatchOptions
    from mechbook.app.watch import watch as watch_problem
    from mechbook.model.catalog import check_id

    base = _resolve_root(ctx)
    try:
        path = problem_path(check_id(problem_id), base)
    except MechbookError as exc:
        raise click.ClickException(for_terminal(str(exc))) from None
    if not path.exists():
        raise click.ClickException(f"no problem {problem_id} (no file {path}; "
                                   "`mechbook list` shows the problems there are)")
    watch_problem(problem_id, base, _say,
                  WatchOptions(crosscheck=not no_crosscheck, seconds=seconds, runs=runs))


@main.command()
@click.argument("problem_id", shell_complete=_complete_ids)
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
        raise click.ClickException(for_terminal(str(exc))) from None
    except (FileNotFoundError, KeyError) as exc:
        raise click.ClickException(str(exc).strip("'\"")) from None
    a = rec["attrs"]
    _say(f"{problem_id}: {a.get('title')}  [{a.get('source')}]")
    _say(f"stored {a.get('date')} by mechbook {a.get('mechbook')} (SymPy {a.get('sympy')}, "
               f"NumPy {a.get('numpy')}); {a.get('duration_s', 0):.1f} s; problem sha256 "
               f"{str(a.get('problem_sha256'))[:12]}")
    for sname, entry in rec["systems"].items():
        _say(f"\n== system {sname}")
        for key, text in entry["symbolic"].items():
            _say(f"{key}: {text}")
        for key, arr in entry["numeric"].items():
            if not key.endswith("/growth_rates"):
                _say(f"{key} (numeric): {_numeric_text(key, arr, entry['numeric'])}")
        for key, text in entry["notes"].items():
            _say(f"{key}: {text}")
    _say("\n== checks")
    for c in rec["checks"]:
        _say(f"{c['part']:<16} {c['quantity']:<20} {c['status']:<12} {c['method']} "
                   f"{c['detail']}".rstrip())
    if rec.get("crosschecks"):
        _say("\n== cross-checks")
        for x in rec["crosschecks"]:
            parts = ", ".join(x.get("parts") or []) or "-"
            _say(f"{x['name']} [{x['status']}, error {x.get('error', float('nan')):.1e}; "
                       f"parts: {parts}] {x.get('detail', '')}")
    for name in rec.get("simulations", []):
        _say(f"simulation stored: /problems/{problem_id}/simulations/{name}")
    from mechbook.app.sweep_io import stored_sweeps

    for name, text in stored_sweeps(problem_id, path):  # a damaged entry is said so
        _say(f"sweep stored: /sweeps/{problem_id}/{name}: {text}")


@main.command()
@click.argument("problem_id", shell_complete=_complete_ids)
@click.option("--system", default=None, help="Which system of a multi-system problem.")
@click.option("--method", default=None,
              type=click.Choice(["RK45", "DOP853", "Radau", "LSODA", "RK4", "leapfrog",
                                 "yoshida4", "midpoint", "taylor"]),
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
@click.option("--backend", type=click.Choice(["llvm", "symengine", "sympy"]), default=None,
              help="How the equations are compiled (default: llvm; see docs/numerics.md).")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Write coordinates against time and the phase portrait here.")
@click.option("--name", default=None, help="Name of the stored run (default SYSTEM-METHOD).")
@click.option("--store", "store_path", type=click.Path(dir_okay=False, path_type=Path),
              default=DEFAULT_PATH, show_default=True, help="HDF5 file to store the run in.")
@click.option("--no-store", is_flag=True, help="Do not store the run.")
@click.option("--timeout", type=opt.seconds(), default=DEFAULT_TIMEOUT, show_default=True,
              help="Wall-clock seconds allowed for the run (loading, deriving, integrating, "
                   "plotting); past it the run is stopped and reported with its stage.")
@click.option("--memory", "memory_mb", type=opt.memory(), default=DEFAULT_MEMORY_MB,
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
    from mechbook.app.store import StoreError, check_run_name, write_simulation
    from mechbook.app.unsaved import SideFile
    from mechbook.model.catalog import check_id

    base = _resolve_root(ctx)
    path = store_path if store_path.is_absolute() else base / store_path
    try:
        check_id(problem_id)
        if name is not None:
            check_run_name(name, "simulation")
    except MechbookError as exc:
        raise click.ClickException(str(exc)) from None
    if not no_store:
        _output(path, "store")
    _output(plot_path, "plot")
    request = SimRequest(problem_id, system, method, accuracy, tuple(params), rtol, atol,
                         max_step, step, t_end, points, tuple(init), backend,
                         str(plot_path) if plot_path is not None else None)
    report = run_simulation(request, base, timeout, memory_mb, serial)
    if report.error:
        raise click.ClickException(for_terminal(report.error))
    for line in report.lines:
        _say(line)
    failed = not report.success
    if not no_store:
        run_name = name or f"{report.system}-{report.method}"
        try:
            write_simulation(report.problem_id, run_name, report.arrays, report.settings,
                             report.array_attrs, path)
            _say(f"stored as /problems/{report.problem_id}/simulations/{run_name} in {path}")
        except StoreError as exc:
            failed = True
            side = SideFile(path).keep("simulation", {
                "problem_id": report.problem_id, "name": run_name, "arrays": report.arrays,
                "attrs": report.settings, "array_attrs": report.array_attrs})
            _say(f"error: {exc}", err=True)
            _say(f"error: the simulation is kept in {side} (`mechbook restore {side}` stores "
                 "it once the cause is fixed)" if side else
                 "error: the simulation could not be kept anywhere", err=True)
    if report.plot is not None:
        _say(f"plot written to {report.plot}")
    if failed:
        sys.exit(1)


@main.command()
@click.argument("problem_id", shell_complete=_complete_ids)
@click.option("--param", "params", multiple=True, required=True, metavar="NAME=LO:HI:N[:log]",
              help="A swept parameter: N values from LO to HI (evenly; ':log' evenly in log). "
                   "Repeat for a plane or more; the others stay at their values (N=1 fixes "
                   "one: k=2:2:1). For --quantity drift one must be 'amplitude'.")
@click.option("--quantity", type=click.Choice(["frequencies", "stability", "drift"]),
              default="frequencies", show_default=True,
              help="frequencies: the normal frequencies; stability: stable / marginal / "
                   "unstable and the growth rate; drift: the frequency measured from the "
                   "nonlinear motion at each amplitude against the linear one.")
@click.option("--system", default=None, help="Which system of a multi-system problem.")
@click.option("--about", multiple=True, metavar="COORD=EXPR",
              help="The equilibrium to linearize about (theta=pi); default: the stable one.")
@click.option("--steady", multiple=True, metavar="COORD=RATE",
              help="A steady motion: a cyclic coordinate turning at RATE (with --about for "
                   "the others), reduced by Routh's procedure.")
@click.option("--part", default=None,
              help="Take the point (and the book's answer drawn over) from this answer part.")
@click.option("--backend", type=click.Choice(["llvm", "symengine", "sympy"]), default="llvm",
              show_default=True, help="How M(p), C(p), K(p) are compiled.")
@click.option("-j", "--jobs", type=opt.jobs(1), default=1, show_default=True,
              help="Local worker processes for the blocks (1: this process).")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Evaluate the blocks on the Dask cluster at ADDRESS (default "
                   "$MECHBOOK_SCHEDULER, else locally).")
@click.option("--timeout", type=opt.seconds(), default=DEFAULT_TIMEOUT, show_default=True,
              help="Wall-clock seconds allowed per block on a cluster worker.")
@click.option("--memory", "memory_mb", type=opt.memory(), default=DEFAULT_MEMORY_MB,
              show_default=True,
              help="Resident memory (MB) allowed per cluster worker's block, and for the "
                   "sweep's arrays here (a grid whose arrays would need more is refused "
                   "before anything is computed; 0: no bound).")
@click.option("--samples", type=click.IntRange(min=0, max=opt.MAX_SAMPLES),
              default=opt.SWEEP_SAMPLES, show_default=True,
              help="Points where the float64 result is checked against 30 digits.")
@click.option("--name", default=None, help="Name of the stored sweep (default QUANTITY-AXES).")
@click.option("--store", "store_path", type=click.Path(dir_okay=False, path_type=Path),
              default=DEFAULT_PATH, show_default=True, help="HDF5 store to add the sweep to.")
@click.option("--no-store", is_flag=True, help="Do not store the sweep.")
@click.option("--out", "out_path", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Write the sweep to this netCDF-4 file (named dimensions); a "
                                 "sweep too large for the store goes to results/sweeps/ anyway.")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Write the figure here (PNG, SVG, PDF by suffix).")
@click.pass_context
def sweep(ctx: click.Context, problem_id: str, params: tuple[str, ...], quantity: str,
          system: str | None, about: tuple[str, ...], steady: tuple[str, ...],
          part: str | None, backend: str, jobs: int, scheduler: str | None, timeout: float,
          memory_mb: float, samples: int, name: str | None, store_path: Path, no_store: bool,
          out_path: Path | None, plot_path: Path | None) -> None:
    """Map a problem's frequencies, stability or frequency drift over a grid of parameter
    values: derived once, M(p), C(p), K(p) compiled once, every point's eigenproblem solved
    in stacked batches; the float64 result is checked against 30 digits at sampled points
    and the book's answer at the same point is drawn over (and compared)."""
    from mechbook.app.distributed import scheduler_address
    from mechbook.app.store import StoreError, check_run_name
    from mechbook.app.sweep import check_grid, make_spec, run_sweep
    from mechbook.app.sweep_io import STORE_POINTS, write_netcdf, write_store
    from mechbook.app.sweep_text import summary
    from mechbook.engine.sweep import parse_axis

    base = _resolve_root(ctx)
    path = store_path if store_path.is_absolute() else base / store_path

    def pairs(items: tuple[str, ...], what: str) -> dict[str, str]:
        out = {}
        for item in items:
            key, sep, val = item.partition("=")
            if not sep or not key.strip() or not val.strip():
                raise click.BadParameter(f"{item!r}: expected NAME=EXPR", param_hint=what)
            out[key.strip()] = val.strip()
        return out

    try:
        axes = [parse_axis(p) for p in params]
        check_grid(axes, memory_mb)
    except (ValueError, MechbookError) as exc:
        raise click.BadParameter(str(exc), param_hint="--param") from None
    try:
        if name is not None:
            check_run_name(name, "sweep")
    except MechbookError as exc:
        raise click.BadParameter(str(exc), param_hint="--name") from None
    if not no_store:
        _output(path, "store")
    _output(out_path, "netCDF file")
    _output(plot_path, "plot")
    if (about or steady) and part:
        raise click.UsageError("--part takes the point from the answer key: drop --about/"
                               "--steady, or --part")
    try:
        spec = make_spec(problem_id, base, quantity, axes, system=system,
                         about=pairs(about, "--about"), steady=pairs(steady, "--steady"),
                         part=part, backend=backend)
        result = run_sweep(spec, base, jobs=jobs, scheduler=scheduler_address(scheduler),
                           timeout=timeout, memory_mb=memory_mb, samples=samples)
    except (MechbookError, KeyError) as exc:
        raise click.ClickException(str(exc).strip("'\"")) from None
    for line in summary(result):
        _say(line)
    run_name = name or "-".join([quantity] + [a.name for a in axes])
    big = result.attrs["points"] > STORE_POINTS
    if out_path is None and big and not no_store:
        out_path = base / "results" / "sweeps" / f"{problem_id}-{run_name}.nc"
    failed = False
    try:
        if out_path is not None:
            result.attrs["file"] = str(write_netcdf(result, out_path))
            _say(f"written to {out_path} (netCDF-4, dimensions {', '.join(result.coords)})")
        if not no_store:
            write_store(result, run_name, path)
            where = "its attributes and the file's path" if big else "stored"
            _say(f"{where} as /sweeps/{problem_id}/{run_name} in {path}")
    except (StoreError, MechbookError) as exc:
        failed = True
        _say(f"error: {exc}", err=True)
        _say(_keep_sweep(result, path, f"{problem_id}-{run_name}"), err=True)
    if plot_path is not None:
        from mechbook.app.sweep_plot import plot_sweep

        _say(f"plot written to {plot_sweep(result, plot_path)}")
    if failed:
        sys.exit(1)


def _keep_sweep(result, store: Path, label: str) -> str:
    """A sweep that could not be written where asked, kept as a netCDF file in the first
    place that takes it (beside the store, the temporary directory, home)."""
    import tempfile

    from mechbook.app.sweep_io import write_netcdf

    tried = []
    for place in (store.parent, Path(tempfile.gettempdir()), Path.home()):
        try:
            side = write_netcdf(result, place / f"{label}.unsaved.nc")
            return f"error: the sweep is kept in {side} (netCDF-4; xarray opens it)"
        except (OSError, MechbookError, RuntimeError, ValueError) as exc:
            tried.append(f"{place}: {exc}")
    return "error: the sweep could not be kept anywhere (" + "; ".join(tried) + ")"


@main.command()
@click.argument("problem_ids", nargs=-1, shell_complete=_complete_ids)
@click.option("--store", "store_path", type=click.Path(dir_okay=False, path_type=Path),
              default=DEFAULT_PATH, show_default=True, help="HDF5 file to read outcomes from.")
@click.option("--out", "out_dir", type=click.Path(file_okay=False, path_type=Path),
              default=Path("results/report"), show_default=True,
              help="Directory to write the report to (index.html and problems/).")
@click.option("-j", "--jobs", type=opt.jobs(), default=0, show_default=True,
              help="Worker processes (0: one per core).")
@click.option("--serial", is_flag=True, help="Build the pages in this process.")
@click.option("--seconds", type=opt.seconds(opt.MAX_STEP_SECONDS), default=10.0,
              show_default=True, help="Time limit of each step of a page that computes "
                                      "(a simulation, an equation the check did not store).")
@click.option("--simplify-seconds", type=opt.Finite(min=0, max=opt.MAX_STEP_SECONDS),
              default=0.3, show_default=True,
              help="Time limit of simplifying each expression shown, for reading (0: show "
                   "them as the check stored them); a page spends at most five times this.")
@click.option("--no-simulate", is_flag=True, help="Leave out the simulated trajectories.")
@click.option("--t-end", type=opt.Finite(min=0, min_open=True, max=1e6), default=10.0,
              show_default=True, help="End time of the simulated trajectories.")
@click.pass_context
def report(ctx: click.Context, problem_ids: tuple[str, ...], store_path: Path, out_dir: Path,
           jobs: int, serial: bool, seconds: float, simplify_seconds: float,
           no_simulate: bool, t_end: float) -> None:
    """Write a static HTML report (all problems by default): an index of every part's
    outcome with filters, errata and unsupported parts, and one page per problem with the
    derivation as mathematics, the book's value beside the engine's, cross-checks, charts
    and an animation of a simulated motion. Outcomes and derived results come from the
    store (`mechbook check` first): nothing the check derived is derived again. Pages are
    written as they finish and kept by content hash: a rerun rebuilds only what changed.
    Works offline."""
    from mechbook.app.report.build import ReportOptions, build_report
    from mechbook.app.report.page import PageOptions

    base = _resolve_root(ctx)
    ids = list(problem_ids) or all_ids(base)
    for pid in problem_ids:  # named ones must exist; of all, a bad file gets a page saying so
        try:
            if not problem_path(pid, base).exists():
                raise click.ClickException(f"no problem {pid}")
        except MechbookError as exc:
            raise click.ClickException(str(exc)) from None
    store = store_path if store_path.is_absolute() else base / store_path
    out = out_dir if out_dir.is_absolute() else base / out_dir
    page = PageOptions(seconds=seconds, simplify_seconds=simplify_seconds,
                       simplify_budget=5 * simplify_seconds, simulate=not no_simulate,
                       t_end=t_end, simulate_seconds=seconds)
    index = build_report(base, store, out, ids, ReportOptions(jobs, serial, page),
                         log=lambda text: _say(text, err=True))
    _say(f"report written to {index}")


@main.command()
@click.argument("files", nargs=-1, required=True,
                type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--store", "store_path", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="HDF5 file to write to (default: the store each result was "
                                 "meant for).")
@click.pass_context
def restore(ctx: click.Context, files: tuple[Path, ...], store_path: Path | None) -> None:
    """Store the results a run could not write (its side file, named in its error: a
    read-only or full disk, a directory at the store's path), once the cause is fixed."""
    from mechbook.app.unsaved import restore as restore_file

    for f in files:
        try:
            problems, simulations = restore_file(f, store_path)
        except MechbookError as exc:
            raise click.ClickException(for_terminal(str(exc))) from None
        _say(f"{f}: {problems} problem(s) and {simulations} simulation(s) stored")


@main.command()
@click.argument("directory", type=click.Path(file_okay=False, path_type=Path))
def init(directory: Path) -> None:
    """Start a tree of your own in DIRECTORY: books.yaml, an example problem and its answer
    key (which `mechbook check` passes), and a Makefile. Nothing is overwritten."""
    from mechbook.app.init import init_tree

    try:
        written = init_tree(directory)
    except MechbookError as exc:
        raise click.ClickException(for_terminal(str(exc))) from None
    for path in written:
        _say(f"wrote {path}")
    _say(f"next: cd {directory} && mechbook check   (or: mechbook --root {directory} check)")


@main.command()
@click.argument("shell", type=click.Choice(SHELLS))
def completion(shell: str) -> None:
    """Print the shell completion script (commands, options, problem ids) for SHELL.

    bash: eval "$(mechbook completion bash)" in ~/.bashrc; zsh: the same in ~/.zshrc;
    fish: mechbook completion fish > ~/.config/fish/completions/mechbook.fish"""
    from click.shell_completion import get_completion_class

    cls = get_completion_class(shell)
    click.echo(cls(main, {}, "mechbook", "_MECHBOOK_COMPLETE").source())
