"""Errors that point a user at the exact place in a problem file that is wrong."""

from __future__ import annotations

import logging

FAULTS = "mechbook.faults"  # the logger of unexpected errors' tracebacks (debug level)


class MechbookError(Exception):
    """Base class for every error mechbook raises on purpose."""


class ExpressionError(MechbookError):
    """An expression string was rejected by the safe parser."""

    def __init__(self, message: str, text: str | None = None):
        self.text = text
        super().__init__(message)


class SpecError(MechbookError):
    """A problem or answer file is malformed; carries file, line and what is wrong."""

    def __init__(self, message: str, file: str | None = None, line: int | None = None):
        self.file = file
        self.line = line
        self.bare = message
        where = file or "<input>"
        if line is not None:
            where += f":{line}"
        super().__init__(f"{where}: {message}")


class NotFoundError(MechbookError, KeyError):
    """A name the user gave that is not there (a system, a particle or body, a declared
    body, a coordinate); the message names those there are. Also a KeyError, so callers
    that catch one keep working; its text is the message itself (a KeyError's would be
    quoted)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class NothingSelectedError(NotFoundError):
    """No problem is what a command was given: an id with no file, a pattern or a book that
    matches none. The command line exits with its own status for it (5, as pytest's "no
    tests collected"), so a script can tell it from a part that failed (1)."""


class MalformedIdError(MechbookError):
    """A problem id that is not `<book>-<number>` at all: the command line exits with its
    usage status for it (4), as for any malformed argument."""


class InputError(MechbookError, ValueError):
    """A value the user gave (on the command line or to the Python API) that is not valid;
    the message says what is expected. Also a ValueError, for callers that catch one."""


class MissingDependencyError(MechbookError, ImportError):
    """An optional dependency that is not installed: the message names what needs it and
    the extra that installs it (`pip install 'mechbook[extra]'`). Also an ImportError, as
    pandas and SciPy raise for their optional parts."""

    def __init__(self, module: str, extra: str, purpose: str):
        self.module, self.extra = module, extra
        super().__init__(f"{purpose} needs {module.split('.')[0]}, which is not installed: "
                         f"pip install 'mechbook[{extra}]'")
        self.name = module


class UnsupportedError(MechbookError):
    """The engine cannot compute this yet; names the capability that is missing."""

    def __init__(self, capability: str):
        self.capability = capability
        super().__init__(f"unsupported: {capability}")


class UndecidedError(MechbookError):
    """The check ran, but nothing it evaluated could decide the claim (the sampled points
    never straddle the book's boundary, or no steady motion exists anywhere sampled): an
    error that says how to widen the check, never a fail, which would blame the book."""


class WrongAnswerError(MechbookError):
    """A value an answer gives contradicts the system (a point that is no equilibrium, a
    mode shape off the constraint manifold): the answer is wrong, a fail."""


class NotEquilibriumError(WrongAnswerError):
    """A point (or steady motion) named by an answer does not satisfy the equations of motion:
    the answer is wrong, which is a fail, not a missing capability."""


def message(exc: MechbookError | KeyError) -> str:
    """A user error's text: a MechbookError's own; a plain KeyError's without the quotes
    its str() puts around the missing key."""
    if isinstance(exc, MechbookError):
        return str(exc)
    return str(exc).strip("'\"")


def describe(exc: BaseException) -> str:
    """The text an error leaves in a part's or a cross-check's detail: a MechbookError's own
    message; for anything else (a fault of the engine or of a library) its type and message.
    Never a traceback: that goes to the debug log (`mechbook check -v` prints it)."""
    if isinstance(exc, MechbookError):
        return str(exc)
    logging.getLogger(FAULTS).debug("%s: %s", type(exc).__name__, exc, exc_info=exc)
    if isinstance(exc, MemoryError):  # its message is usually empty: "MemoryError: "
        return f"ran out of memory (MemoryError{': ' + str(exc) if str(exc) else ''})"
    return f"{type(exc).__name__}: {exc}"
