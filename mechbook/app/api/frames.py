"""The store as pandas DataFrames: `mechbook.results(path)` for a notebook or a script.

pandas is an optional dependency (`pip install mechbook[data]`): the command line does not
need it, and importing this module does not import it until `results` is called.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

from mechbook.app.api import args
from mechbook.app.store import problems, read, regular_store, vet
from mechbook.core.optional import require
from mechbook.model.catalog import DEFAULT_STORE

if TYPE_CHECKING:  # pandas is imported only when `results` is called
    import pandas as pd


class Frames(NamedTuple):
    """checks: one row per answer part; crosschecks: one row per cross-check; timings: one
    row per problem (duration and the versions that produced it)."""

    checks: pd.DataFrame
    crosschecks: pd.DataFrame
    timings: pd.DataFrame


def results(store: str | Path = DEFAULT_STORE) -> Frames:
    """Read a store written by `mechbook check` into three DataFrames.

    Parameters
    ----------
    store : str or pathlib.Path, default results/mechbook.h5
        The HDF5 store.

    Returns
    -------
    Frames
        (checks, crosschecks, timings): one row per answer part, per cross-check, per
        problem.

    Raises
    ------
    MissingDependencyError
        Without pandas (``pip install 'mechbook[data]'``); an ImportError too.

    Examples
    --------
    >>> checks, crosschecks, timings = mechbook.results("results/mechbook.h5")  # doctest: +SKIP
    >>> checks.groupby("status").size()                                         # doctest: +SKIP
    """
    pd = require("pandas", "data", "mechbook.results()")

    path = args.path("store", store)
    if not os.path.lexists(path):
        raise FileNotFoundError(f"no store at {path}; run `mechbook check` first")
    regular_store(path)  # a FIFO would block the read: refused by its kind, never opened
    vet(path)  # once for the whole file, not a child per record
    checks, cross, timings = [], [], []
    for pid in problems(path):
        rows = _rows(pid, read(pid, path))
        checks += rows[0]
        cross += rows[1]
        timings.append(rows[2])
    columns = {"checks": ["problem", "book", "part", "quantity", "origin", "status", "method",
                          "detail", "cite", "seconds"],
               "crosschecks": ["problem", "book", "name", "kind", "system", "status", "error",
                               "parts", "detail", "seconds"],
               "timings": ["problem", "book", "title", "duration_s", "parts", "check_s",
                           "crosscheck_s", "date", "mechbook", "sympy", "numpy"]}
    return Frames(pd.DataFrame(checks, columns=columns["checks"]),
                  pd.DataFrame(cross, columns=columns["crosschecks"]),
                  pd.DataFrame(timings, columns=columns["timings"]))


def _rows(pid: str, rec: dict) -> tuple[list[dict], list[dict], dict]:
    """One stored problem as rows: its parts, its cross-checks, its timing."""
    a = rec["attrs"]
    book = pid.split("-", 1)[0]
    checks = [{"problem": pid, "book": book, "part": c["part"],
               "quantity": c.get("quantity", ""), "origin": c.get("origin", "book"),
               "status": c.get("status", ""), "method": c.get("method", ""),
               "detail": c.get("detail", ""), "cite": c.get("cite", ""),
               "seconds": float(c.get("seconds", 0.0))} for c in rec["checks"]]
    cross = [{"problem": pid, "book": book, "name": x.get("name", ""),
              "kind": x.get("kind", ""), "system": x.get("system", ""),
              "status": x.get("status", ""), "error": float(x.get("error", "nan")),
              "parts": ", ".join(x.get("parts") or []), "detail": x.get("detail", ""),
              "seconds": float(x.get("seconds", 0.0))} for x in rec.get("crosschecks", [])]
    timing = {"problem": pid, "book": book, "title": a.get("title", ""),
              "duration_s": float(a.get("duration_s", 0.0)), "parts": len(rec["checks"]),
              "check_s": sum(float(c.get("seconds", 0.0)) for c in rec["checks"]),
              "crosscheck_s": sum(float(x.get("seconds", 0.0))
                                  for x in rec.get("crosschecks", [])),
              "date": a.get("date", ""), "mechbook": a.get("mechbook", ""),
              "sympy": a.get("sympy", ""), "numpy": a.get("numpy", "")}
    return checks, cross, timing
