"""`mechbook schema`: the JSON Schemas of problem, answer, books and check-result files, for
an editor's YAML language server (mechbook.app.authoring.editor)."""

from __future__ import annotations

from pathlib import Path

import click

from mechbook.app.cli.common import say

NAMES = ("problem", "answers", "books", "check-result")  # mechbook.app.authoring.editor.NAMES


@click.command("schema")
@click.argument("name", required=False, type=click.Choice(NAMES))
@click.option("--write", "directory", type=click.Path(path_type=Path),
              default=None, help="Write every schema to DIRECTORY (as NAME.json) instead.")
def command(name: str | None, directory: Path | None) -> None:
    """Print the JSON Schema NAME (problem, answers, books or check-result), or write them
    all with --write. With a schema beside the files, an editor with a YAML language server
    completes keys and underlines mistakes while you type: put

        # yaml-language-server: $schema=../../schemas/problem.json

    on the first line of problems/<book>/<n>.yaml (answers.json for answer keys,
    books.json for books.yaml); `mechbook init` does both for a new tree."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.authoring import editor

    if (name is None) == (directory is None):
        raise click.UsageError("name one schema (problem, answers, books, check-result) or "
                               "give --write DIRECTORY, not both")
    if name is not None:
        click.echo(editor.text(name), nl=False)
        return
    written = editor.write_schemas(directory)  # an OutputError is the command's message
    for path in written:
        say(f"wrote {path}")
