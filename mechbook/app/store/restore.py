"""`mechbook restore FILE`: the results a side file kept (mechbook.app.store.unsaved) written into a
store, once the cause of the failed write is fixed.

A side file is a file like any other by the time it is read back: it may have been edited,
replaced or planted. So nothing in it is trusted:
- it is read as a regular file only, one line at a time, each line bounded and its JSON of
  bounded depth (mechbook.app.bounded): a FIFO, /dev/zero or a file of gigabytes is refused
  with the reason, never waited for or read whole;
- every entry is checked field by field before anything is written: problem ids follow the
  id grammar (mechbook.model.ids), run, system, part and result names are plain names that
  cannot make an HDF5 path of their own, outcomes are outcomes, arrays are numbers;
- where the results go: the store given with `--store` (the user's choice), else the store
  each entry names, only if it lies inside the tree (links followed: its real place) and is
  an HDF5 file or nothing yet. A side file cannot make mechbook write anywhere else, nor move
  aside and replace a file that is not a store.
A bad line is an error naming the file and the line; nothing of a side file with one is
written (the whole file is checked first).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from mechbook.app.bounded import Unreadable, json_value, regular_file
from mechbook.app.store.unsaved import FORMAT
from mechbook.app.store.writer import ProblemRecord, check_run_name, write, write_simulation
from mechbook.errors import MechbookError
from mechbook.model.ids import check_id
from mechbook.records import CrossCheck, Outcome, Results, Status

MAX_LINE_BYTES = 256 * 2**20  # one kept result, read whole (with its JSON, about twice that
# in memory); a simulation of the default 2001 samples is under 1 MB. One of more (over three
# million numbers) is refused with the line: rerun it with a store that can be written
MAX_NAME = 200  # characters of a result's, part's or system's name
_NAME = re.compile(r"[^/\x00-\x1f\x7f]{1,200}")  # one HDF5 path component
_SYSTEM = re.compile(r"[A-Za-z0-9_+-][A-Za-z0-9._+-]{0,99}")


class BadEntry(ValueError):
    """One line of a side file that is not a result mechbook kept."""


@dataclass
class Entry:
    """One checked line: what to write and where."""

    line: int
    kind: str  # "problem" or "simulation"
    target: Path
    record: ProblemRecord | None = None
    simulation: tuple | None = None  # (pid, name, arrays, attrs, array_attrs)


def restore(side: str | Path, store: str | Path | None = None,
            base: str | Path | None = None) -> tuple[int, int]:
    """Write the results kept in the side file `side` into `store` (the user's choice), or
    else into the store each names, which must lie inside the tree `base`:
    (problems, simulations). MechbookError (file:line and why) if a line is not a result
    mechbook kept, or names a store it may not write; then nothing is written.

    Two passes over the open file: every line checked first, then written, the problems
    of consecutive lines for one store in one edit (up to BATCH of them): a side file of
    many lines costs a few rewrites of the store, not one per line, and memory holds one
    batch, never the whole file."""
    side = Path(side)
    try:
        with regular_file(side, 2**62) as fh:
            count = sum(1 for _ in _entries(fh, side, store, base))
            if not count:
                raise MechbookError(f"{side}: no kept results in it")
            fh.seek(0)
            return _write_all(_entries(fh, side, store, base))
    except Unreadable as exc:
        raise MechbookError(str(exc)) from None
    except OSError as exc:
        raise MechbookError(f"cannot read {side}: {exc.strerror or exc}") from None


BATCH = 100  # problems written in one edit of a store


def _write_all(entries) -> tuple[int, int]:
    problems = simulations = 0
    pending: list[ProblemRecord] = []
    target: Path | None = None

    def flush() -> None:
        if pending:
            write(list(pending), target)
            pending.clear()

    for entry in entries:
        if entry.record is not None:
            if entry.target != target or len(pending) >= BATCH:
                flush()
                target = entry.target
            pending.append(entry.record)
            problems += 1
        else:
            flush()
            write_simulation(*entry.simulation, path=entry.target)
            simulations += 1
    flush()
    return problems, simulations


def _entries(fh, side: Path, store: str | Path | None, base: str | Path | None):
    """Every line of the open side file, checked (MechbookError naming the line)."""
    number = 0
    while True:
        line = fh.readline(MAX_LINE_BYTES + 1)
        if not line:
            return
        number += 1
        if len(line) > MAX_LINE_BYTES:
            raise MechbookError(f"{side}:{number}: a line of more than {MAX_LINE_BYTES} "
                                "bytes: not a kept result")
        if not line.strip():
            continue
        try:
            yield _entry(json_value(line), number, store, base)
        except (BadEntry, MechbookError) as exc:
            raise MechbookError(f"{side}:{number}: {exc}") from None
        except (ValueError, TypeError, KeyError, UnicodeDecodeError, RecursionError) as exc:
            raise MechbookError(f"{side}:{number}: not a kept result ({_one_line(exc)})") \
                from None


def _one_line(exc: BaseException) -> str:
    if isinstance(exc, RecursionError):
        return "nested too deeply"
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0][:300]


def _entry(data: Any, number: int, store: str | Path | None,
           base: str | Path | None) -> Entry:
    if not isinstance(data, dict):
        raise BadEntry("not a kept result (a JSON object per line)")
    if data.get("format") != FORMAT:
        raise BadEntry(f"side file format {data.get('format')!r}; this mechbook reads format "
                       f"{FORMAT}")
    kind = data.get("kind")
    target = _target(data.get("store"), store, base)
    if kind == "problem":
        return Entry(number, kind, target, record=_record(data.get("record")))
    if kind == "simulation":
        return Entry(number, kind, target, simulation=_simulation(data))
    raise BadEntry(f"unknown kind {kind!r} (problem or simulation)")


# ---- where it goes -----------------------------------------------------------------------
def _target(named: Any, store: str | Path | None, base: str | Path | None) -> Path:
    """The store to write: the user's `store`, or the entry's own, inside the tree only."""
    if store is not None:
        return Path(store)
    if not isinstance(named, str) or not named or "\x00" in named:
        raise BadEntry(f"names no store ({named!r}): give one with --store")
    if base is None:
        raise BadEntry(f"the result was kept for the store {named}; outside a tree, give the "
                       "store to write with --store")
    path = Path(named)
    if not path.is_absolute():
        path = Path(base) / path
    top = os.path.realpath(base)
    real = os.path.realpath(path)
    if os.path.commonpath([top, real]) != top:
        raise BadEntry(f"the result was kept for the store {named}, which is outside the tree "
                       f"{base}: restore writes there only when told, with --store {named}")
    if os.path.lexists(real) and not _hdf5(real):
        raise BadEntry(f"the result was kept for the store {named}, but what is there is not "
                       "an HDF5 store: restore writes only into a store or a new file (give "
                       "another with --store)")
    return path


def _hdf5(path: str) -> bool:
    import h5py

    try:
        return os.path.isfile(path) and h5py.is_hdf5(path)
    except (OSError, ValueError):
        return False


# ---- what it holds -----------------------------------------------------------------------
def _text(value: Any, what: str) -> str:
    if not isinstance(value, str):
        raise BadEntry(f"{what} is {type(value).__name__}, not text")
    return value


def _number(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise BadEntry(f"{what} is {value!r}, not a number")
    return float(value)


def _name(value: Any, what: str, pattern: re.Pattern = _NAME) -> str:
    value = _text(value, what)
    if not pattern.fullmatch(value) or value in (".", ".."):
        raise BadEntry(f"{what} {value[:80]!r} is not a plain name")
    return value


def _key(value: Any, what: str) -> str:
    """A result's key: names joined by '/' (an HDF5 path inside its group)."""
    value = _text(value, what)
    parts = value.split("/")
    if len(parts) > 8 or any(not _NAME.fullmatch(p) or p in (".", "..") for p in parts):
        raise BadEntry(f"{what} {value[:80]!r} is not a plain name")
    return value


def _mapping(value: Any, what: str) -> dict:
    if not isinstance(value, dict):
        raise BadEntry(f"{what} is not a mapping")
    return value


def _array(value: Any, what: str) -> np.ndarray:
    if not isinstance(value, list | int | float) or isinstance(value, bool):
        raise BadEntry(f"{what} is not an array of numbers")
    try:
        arr = np.asarray(value, dtype=float)
    except (ValueError, TypeError):
        raise BadEntry(f"{what} is not an array of numbers") from None
    if arr.ndim > 4:
        raise BadEntry(f"{what} has {arr.ndim} dimensions (at most 4)")
    return arr


def _allowed(data: dict, cls, what: str) -> None:
    known = {f.name for f in fields(cls)}
    extra = sorted(set(data) - known, key=str)
    if extra:
        raise BadEntry(f"{what}: unknown field {str(extra[0])[:80]!r}")


def _record(data: Any) -> ProblemRecord:
    data = _mapping(data, "the record")
    _allowed(data, ProblemRecord, "the record")
    pid = check_id(data.get("problem_id"))
    out = ProblemRecord(pid, _text(data.get("title"), "title"),
                        _text(data.get("source"), "source"),
                        _text(data.get("problem_sha256"), "problem_sha256"))
    out.answers_sha256 = _text(data.get("answers_sha256", ""), "answers_sha256")
    out.duration = _number(data.get("duration", 0.0), "duration")
    for i, r in enumerate(_list(data.get("results", []), "results")):
        r = _mapping(r, f"results[{i}]")
        _allowed(r, Results, f"results[{i}]")
        out.results.append(Results(
            _name(r.get("system"), f"results[{i}].system", _SYSTEM),
            {_key(k, "a result"): _text(v, f"result {k}")
             for k, v in _mapping(r.get("text", {}), "text").items()},
            {_key(k, "a result"): _array(v, f"result {k}")
             for k, v in _mapping(r.get("arrays", {}), "arrays").items()},
            {_key(k, "a note"): _text(v, f"note {k}")
             for k, v in _mapping(r.get("notes", {}), "notes").items()}))
    for i, o in enumerate(_list(data.get("outcomes", []), "outcomes")):
        o = _mapping(o, f"outcomes[{i}]")
        _allowed(o, Outcome, f"outcomes[{i}]")
        if o.get("status") not in set(Status):
            raise BadEntry(f"outcomes[{i}]: status {o.get('status')!r} is not an outcome")
        out.outcomes.append(Outcome(
            _text(o.get("problem", pid), "problem"), _name(o.get("part"), "part"),
            _text(o.get("quantity"), "quantity"), _text(o.get("cite", ""), "cite"),
            o["status"], _text(o.get("method", ""), "method"),
            _text(o.get("detail", ""), "detail"), _number(o.get("seconds", 0.0), "seconds"),
            _text(o.get("origin", "book"), "origin"), _text(o.get("power", ""), "power")))
    for i, x in enumerate(_list(data.get("crosschecks", []), "crosschecks")):
        x = _mapping(x, f"crosschecks[{i}]")
        _allowed(x, CrossCheck, f"crosschecks[{i}]")
        if x.get("status") not in set(Status):
            raise BadEntry(f"crosschecks[{i}]: status {x.get('status')!r} is not an outcome")
        for key in ("name", "kind", "system", "detail"):
            _text(x.get(key, ""), f"crosschecks[{i}].{key}")
        _number(x.get("seconds", 0.0), f"crosschecks[{i}].seconds")
        if x.get("error") is not None:
            _number(x["error"], f"crosschecks[{i}].error")
        if not all(isinstance(p, str) for p in _list(x.get("parts", []), "parts")):
            raise BadEntry(f"crosschecks[{i}].parts holds something other than names")
        if not all(isinstance(m, dict) for m in _list(x.get("modes", []), "modes")):
            raise BadEntry(f"crosschecks[{i}].modes holds something other than mappings")
        out.crosschecks.append(dict(x))
    return out


def _list(value: Any, what: str) -> list:
    if not isinstance(value, list):
        raise BadEntry(f"{what} is not a list")
    return value


def _scalar(value: Any, what: str) -> Any:
    """An attribute's value: text, a number, or a list or mapping of them (stored as
    JSON)."""
    if value is None or isinstance(value, str | bool | int):
        return value
    if isinstance(value, float | list | dict):
        return value
    raise BadEntry(f"{what} is not a value a store holds")


def _simulation(data: dict) -> tuple:
    pid = check_id(data.get("problem_id"))
    name = check_run_name(data.get("name"), "simulation")
    arrays = {_key(k, "an array"): _array(v, f"array {k}")
              for k, v in _mapping(data.get("arrays"), "arrays").items()}
    attrs = {_name(k, "an attribute"): _scalar(v, f"attribute {k}")
             for k, v in _mapping(data.get("attrs"), "attrs").items()}
    array_attrs = {}
    for key, values in _mapping(data.get("array_attrs") or {}, "array_attrs").items():
        if _key(key, "an array") not in arrays:
            raise BadEntry(f"array_attrs names {key[:80]!r}, which is no array of the run")
        array_attrs[key] = {_name(k, "an attribute"): _scalar(v, f"attribute {k}")
                            for k, v in _mapping(values, f"array_attrs {key}").items()}
    return pid, name, arrays, attrs, array_attrs

