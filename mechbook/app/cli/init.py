"""`mechbook init`: a tree of one's own to start from (mechbook.app.authoring.init)."""

from __future__ import annotations

from pathlib import Path

import click

from mechbook.app.cli.common import say
from mechbook.app.output.text import for_terminal
from mechbook.errors import MechbookError


@click.command("init")
@click.argument("directory", type=click.Path(file_okay=False))
def command(directory: str) -> None:
    """Start a tree of your own in DIRECTORY: books.yaml, an example problem and its answer
    key (which `mechbook check` passes), and a Makefile. Nothing is overwritten."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.authoring.init import init_tree

    try:
        if not directory.strip():  # '' would be the current directory: never implied
            raise MechbookError("no directory named: give the directory to start the tree "
                                "in (`mechbook init mytree`)")
        written = init_tree(Path(directory))
    except MechbookError as exc:
        raise click.ClickException(for_terminal(str(exc))) from None
    for path in written:
        say(f"wrote {path}")
    say(f"next: cd {directory} && mechbook check   (or: mechbook --root {directory} check)")
