"""What the commands share: printing safely, the tree's root, output paths checked before
any work, shell completion of ids, and the option decorators several commands take (one
definition each: the type, bounds and default of --store, --timeout, --memory, -j, ...).

Only click and small modules are imported here: --help and argument errors must answer
without loading SymPy, NumPy or the engine.
"""

from __future__ import annotations

import importlib
import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from mechbook.app import options as opt
from mechbook.app.options import DEFAULT_MEMORY_MB, DEFAULT_TIMEOUT
from mechbook.app.output.text import for_terminal
from mechbook.core.backends import BACKENDS
from mechbook.errors import MechbookError
from mechbook.model.catalog import DEFAULT_STORE, all_ids, root

DEFAULT_PATH = DEFAULT_STORE
PLOT_SUFFIXES = (".png", ".svg", ".pdf", ".eps", ".ps", ".jpg", ".jpeg", ".tif", ".tiff",
                 ".webp")
Decorator = Callable[[Callable[..., Any]], Callable[..., Any]]


def say(text: str = "", err: bool = False) -> None:
    """Print text that may come from a problem file or the store: control characters and
    escape sequences are shown as escapes, never sent to the terminal."""
    click.echo(for_terminal(text), err=err)


class _Warnings(logging.Handler):
    """mechbook's warnings (a damaged store moved aside) on stderr; with -v, debug records
    (the tracebacks of unexpected errors) too."""

    def emit(self, record: logging.LogRecord) -> None:
        label = "warning" if record.levelno >= logging.WARNING else "debug"
        say(f"{label}: {record.getMessage()}", err=True)


def set_logging(verbose: bool = False) -> None:
    logger = logging.getLogger("mechbook")
    if not any(isinstance(h, _Warnings) for h in logger.handlers):
        logger.addHandler(_Warnings())
    logger.setLevel(logging.DEBUG if verbose else logging.WARNING)


def resolve_root(ctx: click.Context) -> Path:
    """The tree the command works on: --root, else $MECHBOOK_ROOT or the nearest parent."""
    given = ctx.obj.get("root_opt")
    try:
        return Path(given) if given else root()
    except MechbookError as exc:
        raise click.ClickException(str(exc)) from None


def in_tree(ctx: click.Context, path: Path) -> Path:
    """A path option as given when absolute, else relative to the tree's root."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.outputs import resolve_path

    return resolve_path(resolve_root(ctx), path)


def checked_output(path: Path | None, what: str) -> Path | None:
    """An output path checked before any work: a regular file or nothing (a link is
    followed to its file); a plot's suffix must name a format."""
    # at call time, not at the top: `mechbook --help` and `list` start without it
    from mechbook.app.outputs import OutputError, output_file

    if path is None:
        return None
    if what == "plot" and path.suffix.lower() not in PLOT_SUFFIXES:
        raise click.BadParameter(f"{path}: the suffix names the format; use one of "
                                 f"{', '.join(PLOT_SUFFIXES)}", param_hint="--plot")
    try:
        output_file(path, what)
    except OutputError as exc:
        raise click.ClickException(str(exc)) from None
    return path


def numeric_text(key: str, arr, arrays: dict) -> str:
    """An array of results as text; frequencies with each unstable mode's growth rate
    instead of NaN (mechbook.engine.growth)."""
    if key.endswith("/frequencies"):
        # at call time, not at the top: `mechbook --help` and `list` start without it
        from mechbook.engine.growth import describe

        return describe(list(arr), arrays.get(key.replace("/frequencies", "/growth_rates")))
    return str(arr.tolist())


def complete_ids(ctx: click.Context, param: click.Parameter, incomplete: str) -> list:
    """Shell completion of problem ids: the files under the tree's problems/ (no engine)."""
    from click.shell_completion import CompletionItem

    try:
        given = ctx.find_root().params.get("root_dir")
        base = Path(given) if given else root()
        ids = all_ids(base)
    except (MechbookError, OSError):
        return []
    return [CompletionItem(pid) for pid in ids if pid.startswith(incomplete)]


def given(ctx: click.Context, name: str) -> bool:
    """Whether the option `name` was given on the command line (not its default)."""
    return ctx.get_parameter_source(name) not in (None, click.core.ParameterSource.DEFAULT)


class OwnedChoice(click.Choice):
    """The choices of an option read from the module that owns them (`module`'s `name`),
    the first time they are needed: parsing or the command's own --help, never the start of
    the command line (`mechbook --help` loads no stage of the engine)."""

    def __init__(self, module: str, name: str):
        self._owner, self._choices = (module, name), None
        super().__init__([])

    @property
    def choices(self) -> tuple:
        if self._choices is None:
            module, name = self._owner
            self._choices = tuple(getattr(importlib.import_module(module), name))
        return self._choices

    @choices.setter
    def choices(self, value) -> None:  # click.Choice.__init__ sets it (empty here)
        if value:
            self._choices = tuple(value)


# ---- options several commands take -------------------------------------------------------
def problem_id_argument() -> Decorator:
    return click.argument("problem_id", shell_complete=complete_ids)


def problem_ids_argument() -> Decorator:
    return click.argument("problem_ids", nargs=-1, shell_complete=complete_ids)


def store_option(help: str, default: Path | None = DEFAULT_PATH) -> Decorator:
    return click.option("--store", "store_path",
                        type=click.Path(dir_okay=False, path_type=Path), default=default,
                        show_default=default is not None, help=help)


def no_store_option(help: str) -> Decorator:
    return click.option("--no-store", is_flag=True, help=help)


def timeout_option(help: str) -> Decorator:
    return click.option("--timeout", type=opt.seconds(), default=DEFAULT_TIMEOUT,
                        show_default=True, help=help)


def memory_option(help: str) -> Decorator:
    return click.option("--memory", "memory_mb", type=opt.memory(), default=DEFAULT_MEMORY_MB,
                        show_default=True, help=help)


def jobs_option(help: str, least: int = 0) -> Decorator:
    """-j: worker processes, at least `least` (0: one per core), `least` by default."""
    return click.option("-j", "--jobs", type=opt.jobs(least), default=least, show_default=True,
                        help=help)


def serial_option(help: str) -> Decorator:
    return click.option("--serial", is_flag=True, help=help)


def scheduler_option(help: str) -> Decorator:
    return click.option("--scheduler", default=None, metavar="ADDRESS", help=help)


def system_option() -> Decorator:
    return click.option("--system", default=None, help="Which system of a multi-system problem.")


def plot_option(help: str) -> Decorator:
    return click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
                        default=None, help=help)


def name_option(help: str) -> Decorator:
    return click.option("--name", default=None, help=help)


def backend_option(help: str, default: str | None) -> Decorator:
    """--backend: the compile layer's backends (mechbook.core.backends owns the list)."""
    return click.option("--backend", type=click.Choice(list(BACKENDS)), default=default,
                        show_default=default is not None, help=help)
