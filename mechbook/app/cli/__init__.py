"""The `mechbook` command line: the group `main` and its commands, one module each (check,
listing, solve, validate, watch, show, simulate, sweep, report, restore, init, schema, docs,
completion);
what they share (printing, the tree's root, option decorators) is in `common`.

Only click and a few small modules are imported at the top of every module here: --help,
list, shell completion and argument errors answer without loading SymPy, NumPy or the
engine, which each command imports when it runs (a test keeps it so; docs/performance.md
has the timing). The entry point is `mechbook.app.cli:main`.

May import: every package of mechbook.app (the command line is the top), at start-up only
what --help needs (the rest inside each command).
"""

from __future__ import annotations

from pathlib import Path

import click

from mechbook.app.cli import (
    check,
    completion,
    docs,
    init,
    listing,
    report,
    restore,
    schema,
    show,
    simulate,
    solve,
    sweep,
    validate,
    watch,
)
from mechbook.app.cli.common import say, set_logging
from mechbook.app.cli.statuses import INTERRUPTED, USAGE, epilog, failure
from mechbook.errors import MechbookError
from mechbook.version import __version__


class _Group(click.Group):
    """The command group; Ctrl-C ends any command with one line and exit status 130, never
    a traceback or click's "Aborted!" with status 1 (the workers ignore SIGINT: the run
    stops them, mechbook.app.running.batch); a MechbookError no command caught is its message; a
    usage error (the group's or a command's) exits 4, as pytest's (statuses.TABLE)."""

    def make_context(self, info_name, args, parent=None, **extra) -> click.Context:
        # a usage error exits 4; Ctrl-C while the arguments are read ends with 130 (click
        # would say "Aborted!", status 1)
        try:
            return super().make_context(info_name, args, parent, **extra)
        except click.UsageError as exc:
            exc.exit_code = USAGE
            raise
        except KeyboardInterrupt:
            say("\ninterrupted", err=True)
            raise click.exceptions.Exit(INTERRUPTED) from None

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            say("\ninterrupted", err=True)
            raise click.exceptions.Exit(INTERRUPTED) from None
        except click.UsageError as exc:
            exc.exit_code = USAGE
            raise
        except MechbookError as exc:  # one a command did not catch: still a message
            raise failure(exc) from None


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]},
             epilog=epilog())
@click.version_option(__version__, prog_name="mechbook")
@click.option("--root", "root_dir", type=click.Path(file_okay=False, path_type=Path),
              default=None,
              help="Tree holding problems/ and answers/ (default: nearest parent, or "
                   "$MECHBOOK_ROOT).")
@click.pass_context
def main(ctx: click.Context, root_dir: Path | None) -> None:
    """mechbook: textbook mechanics problems as Lagrangian systems, checked against the book.

    The documentation pages that help texts and messages name (docs/*.md) come with
    mechbook: `mechbook docs` lists them, `mechbook docs schema` prints one."""
    ctx.ensure_object(dict)
    ctx.obj["root_opt"] = root_dir
    set_logging()
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.running.quiet import install

    install(lambda text: say(text, err=True))  # warnings as one-line notes, no traceback


# one module per command (`mechbook --help` lists them by name)
for _module in (listing, solve, check, validate, watch, show, simulate, sweep, report, restore,
                init, schema, docs, completion):
    main.add_command(_module.command)
