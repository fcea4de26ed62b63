"""`mechbook restore`: store the results a run kept in a side file when its store failed."""

from __future__ import annotations

from pathlib import Path

import click

from mechbook.app.cli.common import say, store_option
from mechbook.app.text import for_terminal
from mechbook.errors import MechbookError


@click.command("restore")
@click.argument("files", nargs=-1, required=True,
                type=click.Path(exists=True, dir_okay=False, path_type=Path))
@store_option("HDF5 file to write to (default: the store each result was meant for).",
              default=None)
def command(files: tuple[Path, ...], store_path: Path | None) -> None:
    """Store the results a run could not write (its side file, named in its error: a
    read-only or full disk, a directory at the store's path), once the cause is fixed."""
    from mechbook.app.unsaved import restore as restore_file

    for f in files:
        try:
            problems, simulations = restore_file(f, store_path)
        except MechbookError as exc:
            raise click.ClickException(for_terminal(str(exc))) from None
        say(f"{f}: {problems} problem(s) and {simulations} simulation(s) stored")
