"""`mechbook restore`: store the results a run kept in a side file when its store failed."""

from __future__ import annotations

from pathlib import Path

import click

from mechbook.app.cli.common import say, store_option
from mechbook.app.output.text import for_terminal
from mechbook.errors import MechbookError
from mechbook.model.catalog import root


@click.command("restore")
@click.argument("files", nargs=-1, required=True, type=click.Path(path_type=Path))
@store_option("HDF5 file to write to (default: the store each result was meant for, if it "
              "lies inside the tree).", default=None)
@click.pass_context
def command(ctx: click.Context, files: tuple[Path, ...], store_path: Path | None) -> None:
    """Store the results a run could not write (its side file, named in its error: a
    read-only or full disk, a directory at the store's path), once the cause is fixed.
    Without --store, each result goes to the store it was meant for, and only if that lies
    inside the tree; the whole file is checked before anything is written."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.outputs import resolve_path
    from mechbook.app.store.restore import restore as restore_file

    given = ctx.obj.get("root_opt")
    try:
        base = Path(given) if given else root()
    except MechbookError:
        base = None  # outside a tree: only --store says where
    store = resolve_path(base, store_path) if store_path is not None and base is not None \
        else store_path
    for f in files:
        try:
            problems, simulations = restore_file(f, store, base)
        except MechbookError as exc:
            raise click.ClickException(for_terminal(str(exc))) from None
        say(f"{f}: {problems} problem(s) and {simulations} simulation(s) stored")
