"""`mechbook report`: the static HTML report of the store (mechbook.app.report)."""

from __future__ import annotations

from pathlib import Path

import click

from mechbook.app import options as opt
from mechbook.app.cli.common import (
    in_tree,
    jobs_option,
    problem_ids_argument,
    resolve_root,
    say,
    serial_option,
    store_option,
)
from mechbook.app.cli.statuses import failure
from mechbook.errors import MechbookError


@click.command("report")
@problem_ids_argument()
@store_option("HDF5 file to read outcomes from.")
@click.option("--out", "out_dir", type=click.Path(file_okay=False, path_type=Path),
              default=Path("results/report"), show_default=True,
              help="Directory to write the report to (index.html and problems/).")
@jobs_option("Worker processes (0: one per core).")
@serial_option("Build the pages in this process.")
@click.option("--seconds", type=opt.seconds(opt.MAX_STEP_SECONDS), default=10.0,
              show_default=True, help="Time limit of each step of a page that computes "
                                      "(a simulation, an equation the check did not store).")
@click.option("--simplify-seconds", type=opt.Finite(min=0, max=opt.MAX_STEP_SECONDS),
              default=3.0, show_default=True,
              help="Time limit of simplifying each expression shown, for reading (0: show "
                   "them as the check stored them); a page spends at most five times this. "
                   "Each simplified form is kept (OUT/.simplified/), so it is spent once: "
                   "a rerun reads it back.")
@click.option("--no-simulate", is_flag=True, help="Leave out the simulated trajectories.")
@click.option("--t-end", type=opt.Finite(min=0, min_open=True, max=1e6), default=10.0,
              show_default=True, help="End time of the simulated trajectories.")
@click.pass_context
def command(ctx: click.Context, problem_ids: tuple[str, ...], store_path: Path,
            out_dir: Path, jobs: int, serial: bool, seconds: float, simplify_seconds: float,
            no_simulate: bool, t_end: float) -> None:
    """Write a static HTML report (all problems by default): an index of every part's
    outcome with filters, errata and unsupported parts, and one page per problem with the
    derivation as mathematics, the book's value beside the engine's, cross-checks, charts
    and an animation of a simulated motion. Outcomes and derived results come from the
    store (`mechbook check` first): nothing the check derived is derived again. Pages are
    written as they finish and kept by content hash: a rerun rebuilds only what changed.
    Works offline."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.report.build import ReportOptions, build_report
    from mechbook.app.report.page import PageOptions
    from mechbook.app.running.service import resolve_ids

    base = resolve_root(ctx)
    try:  # named ones must exist; of all, a bad file gets a page saying so
        ids, _ = resolve_ids(problem_ids, base)
    except MechbookError as exc:  # no such problem: its own status (statuses.TABLE)
        raise failure(exc) from None
    page = PageOptions(seconds=seconds, simplify_seconds=simplify_seconds,
                       simplify_budget=5 * simplify_seconds, simulate=not no_simulate,
                       t_end=t_end, simulate_seconds=seconds)
    out = in_tree(ctx, out_dir)
    try:
        index = build_report(base, in_tree(ctx, store_path), out, ids,
                             ReportOptions(jobs, serial, page),
                             log=lambda text: say(text, err=True))
    except MechbookError as exc:
        raise click.ClickException(str(exc)) from None
    except OSError as exc:  # the report's folder: read-only, full, a file where a folder goes
        raise click.ClickException(f"cannot write the report in {out}: "
                                   f"{exc.strerror or exc}"
                                   + (f" ({exc.filename})" if exc.filename else "")) from None
    say(f"report written to {index}")
