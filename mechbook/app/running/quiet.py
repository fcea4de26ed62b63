"""No Python warning or stray traceback on the terminal: they become notes.

NumPy warns on stderr when a float overflows or divides by zero, SymPy when something is
deprecated, and an exception raised inside a finalizer (a time limit's alarm arriving
while the garbage collector runs) prints "Exception ignored in ..." with a traceback. None
of that is for a reader: a check collects each warning as a note on the problem, naming
the stage (the part) it arose in (`warnings_as_notes`); elsewhere a command prints it once
as a one-line `note:` (`install`), and an unraisable exception goes to the debug log
(`mechbook -v`, or a batch run's debug lines).
"""

from __future__ import annotations

import logging
import sys
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

log = logging.getLogger("mechbook.faults")


def describe_warning(message, category: type, filename: str) -> str:
    """'RuntimeWarning in numpy: overflow encountered in dot': the kind, the library (or
    module) whose code was running, the message's first line."""
    text = str(message).strip().splitlines()
    return f"{category.__name__} in {_library(filename)}: {text[0] if text else ''}".rstrip()


def _library(filename: str) -> str:
    parts = Path(str(filename)).parts
    for marker in ("site-packages", "dist-packages"):
        if marker in parts:
            i = parts.index(marker)
            if i + 1 < len(parts):
                return parts[i + 1].removesuffix(".py")
    if "mechbook" in parts:
        return "mechbook"
    return Path(str(filename)).stem or "Python"


@contextmanager
def warnings_as_notes(notes: list[str], where: Callable[[], str] = lambda: "") -> Iterator[None]:
    """Within the block every warning is appended to `notes` (once per text), prefixed with
    `where()` (the stage it arose in), instead of being printed."""
    def note(message, category, filename, lineno, file=None, line=None) -> None:
        place = where()
        text = (f"{place}: " if place else "") + describe_warning(message, category, filename)
        if text not in notes:
            notes.append(text)

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = note
        yield


def _unraisable(info) -> None:
    """An exception no one could catch (in a finalizer, a callback): debug log only."""
    exc = info.exc_value
    log.debug("ignored in %r: %s: %s", info.object, type(exc).__name__, exc,
              exc_info=(info.exc_type, exc, info.exc_traceback) if exc is not None else None)


def install(say: Callable[[str], None] | None = None) -> None:
    """For a whole process (a command, a worker): warnings printed once each as `note:`
    lines through `say` (nothing where `say` is None: a worker's notes travel with its
    results), unraisable exceptions to the debug log."""
    seen: set[str] = set()

    def note(message, category, filename, lineno, file=None, line=None) -> None:
        text = describe_warning(message, category, filename)
        if say is not None and text not in seen:
            seen.add(text)
            say(f"note: {text}")
        elif say is None:
            log.debug("%s", text)

    warnings.showwarning = note
    sys.unraisablehook = _unraisable
