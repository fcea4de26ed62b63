"""Optional dependencies (pandas, xarray, Dask, heyoka), imported where they are needed.

The first import of an optional package is the one place its absence can be noticed, so
it goes through `require`: a missing package is a MissingDependencyError that says what
needed it and the extra that installs it, never a bare ModuleNotFoundError raised from
somewhere in the middle of a run.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from mechbook.errors import MissingDependencyError


def require(module: str, extra: str, purpose: str) -> ModuleType:
    """`module` imported, or MissingDependencyError naming `purpose` and the extra (an
    ImportError raised while importing it, because a package it needs is missing, counts:
    the extra installs that too)."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingDependencyError(module, extra, purpose) from None
