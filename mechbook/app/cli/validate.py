"""`mechbook validate`: the schema, every expression and every name of files; nothing runs."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from mechbook.app.cli.common import say
from mechbook.errors import MechbookError


@click.command("validate")
@click.argument("files", nargs=-1, required=True,
                type=click.Path(exists=True, dir_okay=False, path_type=Path))
def command(files: tuple[Path, ...]) -> None:
    """Validate problem or answer files (schema and every expression); nothing runs."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.authoring.validate import validate_file

    bad = 0
    refused: set[Path] = set()  # problem files already reported invalid
    for f in files:
        try:
            say(validate_file(f))
        except MechbookError as exc:
            bad += 1
            problem = getattr(exc, "problem_file", None)
            if problem is not None and Path(problem).resolve() in refused:
                say(f"invalid: {f}: its problem file {problem} is invalid (above)", err=True)
                continue
            refused.add(Path(getattr(exc, "file", None) or f).resolve())
            say(f"invalid: {exc}", err=True)
    if bad:
        sys.exit(1)
