"""`mechbook list`: every problem, its answer parts and title, read without the engine."""

from __future__ import annotations

import sys

import click

from mechbook.app.cli.common import resolve_root, say
from mechbook.core.words import plural
from mechbook.errors import MechbookError
from mechbook.model.books import file_id_error
from mechbook.model.catalog import all_ids, answer_path, problem_path


@click.command("list")
@click.pass_context
def command(ctx: click.Context) -> None:
    """List every problem with its title and number of answer parts; an invalid file is
    marked INVALID with the reason (and the exit status is 1).

    Reads the files' YAML (under the input limits) and the problem schema only (fast, no
    engine): `mechbook validate` checks every expression."""
    base = resolve_root(ctx)
    invalid = 0
    for pid in all_ids(base):
        title, bad = _title(pid, base)
        parts, bad_key = _parts(pid, base)
        invalid += bad + bad_key
        say(f"{pid:<22} {parts:<16} {title}")
    if invalid:
        click.echo(f"{invalid} invalid file(s)", err=True)
        sys.exit(1)


def _title(pid: str, base) -> tuple[str, int]:
    """The problem's title, or INVALID and why; and 1 if it is invalid."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.model.schema import validate
    from mechbook.model.yamlio import load

    try:
        doc = load(problem_path(pid, base))
        validate(doc, "problem")
        why = file_id_error(doc.data["id"], problem_path(pid, base))
        if why:
            raise doc.error(("id",), why)
        return doc.data["title"], 0
    except MechbookError as exc:
        return f"INVALID: {exc}", 1


def _parts(pid: str, base) -> tuple[str, int]:
    """How many parts the answer key has (or that it has none, or is invalid)."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.model.yamlio import load

    try:
        apath = answer_path(pid, base)
        if apath.exists():
            found = load(apath).data.get("parts")
            if isinstance(found, list):
                return f"{plural(len(found), 'part')}", 0
            return "INVALID answer key", 1
    except MechbookError:
        return "INVALID answer key", 1
    return "no answer key", 0
