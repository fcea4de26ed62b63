"""`mechbook check`: options in, the check service (mechbook.app.running.service) runs the problems
and writes the store, the outcomes out (a table, JSON, JUnit XML) and the exit status."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from mechbook.app import options as opt
from mechbook.app.cli.common import (
    checked_output,
    given,
    jobs_option,
    memory_option,
    no_store_option,
    problem_ids_argument,
    resolve_root,
    say,
    scheduler_option,
    serial_option,
    set_logging,
    store_option,
    timeout_option,
)
from mechbook.app.cli.statuses import epilog, failure
from mechbook.app.output.text import json_safe
from mechbook.errors import MechbookError


@click.command("check", epilog=epilog())
@problem_ids_argument()
@store_option("HDF5 file to write results to.")
@no_store_option("Do not write results.")
@click.option("-v", "--verbose", is_flag=True, help="Show the method and detail of every part.")
@click.option("--fresh", is_flag=True,
              help="Recompute everything; by default a problem whose problem file, answer key "
                   "and engine are unchanged since the stored run reuses the stored outcomes.")
@click.option("--no-crosscheck", is_flag=True,
              help="Skip the independent cross-checks (simulated frequencies, Newton's law).")
@jobs_option("Worker processes (0: one per core).")
@timeout_option("Wall-clock seconds allowed per problem; a problem that takes longer is "
                "stopped and reported as an error with the stage it was in.")
@memory_option("Resident memory (MB) allowed per problem (0: no bound).")
@serial_option("Check in this process, one problem after another, without time or memory "
               "limits (for a debugger).")
@click.option("--prove", is_flag=True,
              help="After a part passes numerically (30 digits at random admissible points), "
                   "also try an exact symbolic proof (canonical forms, then SymPy's simplify); "
                   "the method column says `symbolic`, or why the part is unproved.")
@click.option("--prove-seconds", type=opt.seconds(opt.MAX_STEP_SECONDS), default=10.0,
              show_default=True, help="CPU seconds each part's proofs may spend in SymPy's "
                   "simplify (the canonical forms are cheap and always tried).")
@scheduler_option("Run the problems on the Dask cluster whose scheduler is at ADDRESS "
                  "(tcp://host:8786; default $MECHBOOK_SCHEDULER, else the local pool). "
                  "The limits hold per problem on the workers.")
@click.option("--format", "fmt", type=click.Choice(["table", "json"]), default="table",
              show_default=True,
              help="table: for people; json: one JSON document on stdout (its schema: "
                   "mechbook/app/schemas/check-result.json), progress stays on stderr.")
@click.option("--junit-xml", "junit_path", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Also write the outcomes as JUnit XML here (for CI).")
@click.option("-x", "--exitfirst", is_flag=True,
              help="Stop at the first problem that fails or errors (the others are reported "
                   "as not checked).")
@click.option("--lf", "--last-failed", "last_failed", is_flag=True,
              help="Check only the problems that failed or errored when last checked (all "
                   "of them when none did), as pytest's --lf.")
@click.pass_context
def command(ctx: click.Context, problem_ids: tuple[str, ...], store_path: Path,
            no_store: bool, verbose: bool, fresh: bool, no_crosscheck: bool, jobs: int,
            timeout: float, memory_mb: float, serial: bool, prove: bool,
            prove_seconds: float, scheduler: str | None, fmt: str,
            junit_path: Path | None, exitfirst: bool, last_failed: bool) -> None:
    """Check problems against their answer keys (all by default); exit 1 on any fail, 5
    when nothing is selected (the statuses below).

    PROBLEM_IDS are ids (lim-2031), patterns over ids ('mybook-*', quoted for the shell)
    or a book's id (mybook: all its problems).

    Problems run in parallel worker processes, the longest first; each finished problem is
    written to the store at once, so an interrupted run keeps what it finished and the next
    run resumes from there. The cross-check column is independent of the book: each
    frequency part's linear system is confirmed by simulating the nonlinear equations along
    every mode, and each system's Lagrange equations against Newton's law
    (docs/numerics.md); a cross-check fail also exits 1."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.running.batch import BatchOptions, settle
    from mechbook.app.running.run import RunOptions
    from mechbook.app.running.service import CheckOptions, CheckService
    from mechbook.records import ProofPolicy

    _refuse_serial_limits(ctx, serial)
    if serial:  # this process checks: the engine imported, the collector kept off it
        settle(preload=True)
    base = resolve_root(ctx)
    batch = BatchOptions(jobs, timeout, memory_mb, serial=serial, run=RunOptions(
        crosscheck=not no_crosscheck, policy=ProofPolicy(prove, prove_seconds)))
    service = CheckService(base, CheckOptions(store_path, write=not no_store, fresh=fresh,
                                              batch=batch, scheduler=scheduler,
                                              exitfirst=exitfirst))
    try:
        ids = service.resolve(problem_ids)
    except MechbookError as exc:  # no such problem: its own status (statuses.TABLE)
        raise failure(exc) from None
    if last_failed:
        ids = _last_failed(service.store, ids)
    checked_output(junit_path, "JUnit XML file")
    set_logging(verbose)
    report = _run(service, ids, verbose)
    if not no_store and report.store_error is None:  # a store not written: its record neither
        _remember(report)
    _print(report, base, fmt, verbose, junit_path)


def _last_failed(store: Path, ids: list[str]) -> list[str]:
    """Of `ids`, those that failed when last checked; all of them when none did."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.selection import last_failed

    failed = last_failed(store)
    chosen = [pid for pid in ids if pid in failed]
    if chosen:
        say(f"--lf: checking the {len(chosen)} of {len(ids)} problem(s) that failed when "
            "last checked", err=True)
        return chosen
    say(f"--lf: no problem failed when last checked: checking all {len(ids)}", err=True)
    return ids


def _remember(report) -> None:
    """Record which problems failed now, for `--lf` (a note if it cannot be written)."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.output.formats import failures
    from mechbook.app.selection import lastfailed_path, record

    try:
        record(report.store, [r.pid for r in report.runs],
               [r.pid for r in report.runs if failures([r])])
    except OSError as exc:
        say(f"note: the failures are not recorded for --lf ({lastfailed_path(report.store)}:"
            f" {exc.strerror})", err=True)


def _refuse_serial_limits(ctx: click.Context, serial: bool) -> None:
    """--serial checks in this process without limits or workers: a limit, a worker count
    or a cluster given with it would be dropped silently, so it is refused."""
    if not serial:
        return
    dropped = [f"--{name.replace('_mb', '').replace('_', '-')}"
               for name in ("jobs", "timeout", "memory_mb", "scheduler") if given(ctx, name)]
    if dropped:
        raise click.UsageError(f"--serial runs in this process without workers or limits: "
                               f"{', '.join(dropped)} would have no effect; drop one")


def _run(service, ids: list[str], verbose: bool):
    """The service's run with the progress on stderr (and, with -v, each problem's debug
    lines); a batch that cannot run at all is the command's error."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.output.console import Progress

    progress = Progress(len(ids), 0)

    def finished(run) -> None:
        progress.finished(run)
        if verbose:
            for text in run.debug:
                say(f"debug: {run.pid}: {text}", err=True)

    try:
        return service.run(ids, on_done=finished)
    except MechbookError as exc:
        raise click.ClickException(str(exc)) from None
    finally:
        progress.close()


def _print(report, base: Path, fmt: str, verbose: bool, junit_path: Path | None) -> None:
    """The outcomes as a table or JSON, JUnit XML if asked, what became of the store, and
    the exit status (1 on a fail, an error, or results that could not be written)."""
    import json

    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.output.console import print_table
    from mechbook.app.output.formats import failures, to_json, write_junit

    ordered = report.runs
    if fmt == "json":
        doc = to_json(ordered, base, report.store if report.stored else None,
                      report.store_error)
        click.echo(json.dumps(json_safe(doc), indent=1, ensure_ascii=False))
    else:
        print_table(ordered, verbose)
        if report.written and report.store_error is None:
            say(f"results written to {report.store}")
    unwritten = False
    if junit_path is not None:
        try:
            say(f"JUnit XML written to {write_junit(ordered, junit_path)}", err=True)
        except MechbookError as exc:
            say(f"error: {exc}", err=True)
            unwritten = True
    for line in report.store_lines():
        say(line, err=True)
    bad = failures(ordered)
    if bad:
        click.echo(f"{bad} failure(s)", err=True)
    if report.stopped:
        click.echo(f"stopped at the first failure (-x): {len(report.stopped)} problem(s) "
                   f"not checked: {', '.join(report.stopped[:10])}"
                   + (" ..." if len(report.stopped) > 10 else ""), err=True)
    if bad or report.store_error is not None or unwritten:
        sys.exit(1)
