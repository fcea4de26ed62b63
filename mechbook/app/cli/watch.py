"""`mechbook watch`: check a problem again on every save, the engine kept loaded."""

from __future__ import annotations

import os

import click

from mechbook.app import options as opt
from mechbook.app.cli.common import (
    memory_option,
    problem_id_argument,
    resolve_root,
    say,
    timeout_option,
)
from mechbook.app.cli.statuses import failure
from mechbook.errors import MechbookError
from mechbook.model.catalog import existing_problem_path, problem_path
from mechbook.model.ids import split_id


@click.command("watch")
@problem_id_argument()
@click.option("--no-crosscheck", is_flag=True, help="Check the book's answers only.")
@timeout_option("Wall-clock seconds allowed for each check (as `mechbook check`); a check "
                "that takes longer is stopped and reported with the stage it was in.")
@memory_option("Resident memory (MB) allowed for each check (0: no bound).")
@click.option("--seconds", type=opt.seconds(), default=None, hidden=True,
              help="The time limit of each check (older name of --timeout).")
@click.option("--runs", type=click.IntRange(min=0), default=0, hidden=True,
              help="Stop after this many checks (tests).")
@click.pass_context
def command(ctx: click.Context, problem_id: str, no_crosscheck: bool, timeout: float,
            memory_mb: float, seconds: float | None, runs: int) -> None:
    """Check a problem now and again each time its problem file or answer key is saved,
    with the engine kept loaded (a save is answered in the time the check takes, a few
    tenths of a second for a small problem). Each check runs in a worker process under the
    limits of `mechbook check` (--timeout, --memory). Ctrl-C stops; nothing is stored."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.authoring.watch import WatchOptions
    from mechbook.app.authoring.watch import watch as watch_problem

    base = resolve_root(ctx)
    try:
        book, number = split_id(problem_id)
        plain = base / "problems" / book / f"{number}.yaml"
        try:
            problem_path(problem_id, base)
        except MechbookError:
            if not os.path.lexists(plain):  # a link gone bad: watched, the check says why
                raise
        if not os.path.lexists(plain):
            existing_problem_path(problem_id, base)  # no such problem: its own status
    except MechbookError as exc:
        raise failure(exc) from None
    watch_problem(problem_id, base, say,
                  WatchOptions(crosscheck=not no_crosscheck,
                               timeout=seconds if seconds is not None else timeout,
                               memory_mb=memory_mb, runs=runs))
