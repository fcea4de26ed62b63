"""`mechbook completion`: the shell completion script of the whole command line."""

from __future__ import annotations

import click

SHELLS = ("bash", "zsh", "fish")


@click.command("completion")
@click.argument("shell", type=click.Choice(SHELLS))
@click.pass_context
def command(ctx: click.Context, shell: str) -> None:
    """Print the shell completion script (commands, options, problem ids) for SHELL.

    bash: eval "$(mechbook completion bash)" in ~/.bashrc; zsh: the same in ~/.zshrc;
    fish: mechbook completion fish > ~/.config/fish/completions/mechbook.fish"""
    from click.shell_completion import get_completion_class

    cls = get_completion_class(shell)
    click.echo(cls(ctx.find_root().command, {}, "mechbook", "_MECHBOOK_COMPLETE").source())
