"""`mechbook docs`: the documentation pages, listed or printed (mechbook.app.docs): a
wheel's user has them too."""

from __future__ import annotations

import click

from mechbook.app.cli.common import say
from mechbook.errors import MechbookError


@click.command("docs")
@click.argument("page", required=False)
@click.option("--path", "show_path", is_flag=True, help="Print where the pages are.")
def command(page: str | None, show_path: bool) -> None:
    """List the documentation pages, or print PAGE (schema, answers, numerics, ...; the
    docs/*.md that --help and error messages name) as Markdown."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app import docs

    if show_path:
        say(str(docs.location()))
        return
    if page is None:
        found = docs.pages()
        if not found:
            raise click.ClickException(f"no documentation pages at {docs.location()}")
        width = max(map(len, found))
        for name, path in found.items():
            say(f"{name:<{width}}  {docs.title(path)}")
        say("mechbook docs PAGE prints one (e.g. mechbook docs schema | less)")
        return
    try:
        click.echo(docs.page_text(page), nl=False)
    except MechbookError as exc:
        raise click.ClickException(str(exc)) from None
