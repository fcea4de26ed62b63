"""`mechbook watch`: check a problem again on every save, the engine kept loaded."""

from __future__ import annotations

import click

from mechbook.app import options as opt
from mechbook.app.cli.common import problem_id_argument, resolve_root, say
from mechbook.app.text import for_terminal
from mechbook.errors import MechbookError
from mechbook.model.catalog import problem_path


@click.command("watch")
@problem_id_argument()
@click.option("--no-crosscheck", is_flag=True, help="Check the book's answers only.")
@click.option("--seconds", type=opt.seconds(), default=120.0, show_default=True,
              help="CPU seconds allowed for each check.")
@click.option("--runs", type=click.IntRange(min=0), default=0, hidden=True,
              help="Stop after this many checks (tests).")
@click.pass_context
def command(ctx: click.Context, problem_id: str, no_crosscheck: bool, seconds: float,
            runs: int) -> None:
    """Check a problem now and again each time its problem file or answer key is saved,
    with the engine kept loaded (a save is answered in the time the check takes, a few
    tenths of a second for a small problem). Ctrl-C stops; nothing is stored."""
    from mechbook.app.watch import WatchOptions
    from mechbook.app.watch import watch as watch_problem

    base = resolve_root(ctx)
    try:
        path = problem_path(problem_id, base)
    except MechbookError as exc:
        raise click.ClickException(for_terminal(str(exc))) from None
    if not path.exists():
        raise click.ClickException(f"no problem {problem_id} (no file {path}; "
                                   "`mechbook list` shows the problems there are)")
    watch_problem(problem_id, base, say,
                  WatchOptions(crosscheck=not no_crosscheck, seconds=seconds, runs=runs))
