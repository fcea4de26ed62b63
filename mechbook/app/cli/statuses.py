"""The exit statuses of `mechbook`, one table: what each means, and the one conversion of an
error to the status it exits with.

A script tells the outcomes apart by the status alone, as with pytest (whose 4 and 5 these
follow): 1 is "something is wrong" (a part failed or errored, a file is invalid, results
could not be written), 4 "the command line itself is wrong", 5 "nothing of the tree was
named". The table is shown by `mechbook --help` and in the README and docs/reliability.md;
tests/test_exit_statuses.py holds each command to it.
"""

from __future__ import annotations

import textwrap

import click

from mechbook.app.output.text import for_terminal
from mechbook.errors import MalformedIdError, NothingSelectedError

OK = 0
FAILED = 1
USAGE = 4  # as pytest's "command line usage error" (click's own is 2)
NOTHING_SELECTED = 5  # as pytest's "no tests were collected"
INTERRUPTED = 130  # the shell's convention for Ctrl-C (128 + SIGINT)

TABLE = (
    (OK, "success: every part checked passed (check), or the command did what it was asked"),
    (FAILED, "a part failed or errored, a cross-check failed, a file is invalid, or results "
             "could not be written (the message says which)"),
    (USAGE, "usage error: an unknown option, a missing or malformed argument (a problem id "
            "that is no <book>-<number>), options that cannot go together"),
    (NOTHING_SELECTED, "nothing selected: no such problem (an id with no file), or a "
                       "pattern or book that matches no problem of the tree"),
    (INTERRUPTED, "interrupted (Ctrl-C)"),
)


def epilog() -> str:
    """The table as `--help` shows it (click keeps the lines of a paragraph after \\b)."""
    lines = [textwrap.fill(text, 76, initial_indent=f"  {code:<4} ", subsequent_indent=" " * 7)
             for code, text in TABLE]
    return "\b\nExit status:\n" + "\n".join(lines)


def failure(exc: BaseException) -> click.ClickException:
    """The ClickException a command raises for `exc`: its message, made safe for the
    terminal, exiting with NOTHING_SELECTED for a NothingSelectedError, USAGE for a
    MalformedIdError (an id given on the command line), else FAILED.

    Example: raise failure(exc) from None, in a command's `except MechbookError as exc:`.
    """
    out = click.ClickException(for_terminal(str(exc)))
    if isinstance(exc, NothingSelectedError):
        out.exit_code = NOTHING_SELECTED
    elif isinstance(exc, MalformedIdError):
        out.exit_code = USAGE
    return out
