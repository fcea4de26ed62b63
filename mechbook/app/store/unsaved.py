"""Results that could not be stored, kept in a side file instead of being lost.

When the store cannot be written (a read-only or full file system, a directory or device at
its path), a finished problem's record or a simulation is appended to a side file (JSON
lines, one result a line, written and synced at once): beside the store if its directory
takes files, else in the temporary directory, else in the home directory. The command that
failed names the file and exits non-zero; `mechbook restore FILE` writes its results into
a store once the cause is fixed (rerunning the command computes them again too).

JSON, not HDF5, because the side file must be writable when HDF5 was what failed, and
because a reader can see what it holds.
"""

from __future__ import annotations

import errno
import json
import logging
import os
import stat
import tempfile
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from mechbook.app.output.text import json_safe
from mechbook.app.store.reader import StoreError
from mechbook.app.store.writer import ProblemRecord, compact_store, write

log = logging.getLogger("mechbook.store")

FORMAT = 1


def json_default(value: object) -> list | float | int | bool:
    """`json.dump`'s `default=`: NumPy arrays and scalars as JSON data; TypeError otherwise."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON data")


def _places(store: Path) -> list[Path]:
    home = Path.home()
    return [store.parent, Path(tempfile.gettempdir()), home]


class SideFile:
    """One run's side file, created on the first result that needs it."""

    def __init__(self, store: Path):
        self.store = Path(store)
        self.path: Path | None = None
        self.count = 0
        self.failures: list[str] = []  # where it could not be written, and why

    def keep(self, kind: str, payload: dict) -> Path | None:
        """Append one result; the side file's path, or None if no place would take it."""
        line = json.dumps(json_safe({"format": FORMAT, "kind": kind,
                                     "store": str(self.store.absolute()), **payload}),
                          default=json_default) + "\n"
        places = [self.path.parent] if self.path is not None else _places(self.store)
        for place in places:
            path = self.path or place / (f"{self.store.name}.unsaved-"
                                         f"{datetime.now(UTC):%Y%m%dT%H%M%SZ}-{os.getpid()}"
                                         ".jsonl")
            try:
                append_line(path, line)
            except OSError as exc:
                self.failures.append(f"{path}: {exc.strerror or exc}")
                continue
            self.path = path
            self.count += 1
            return path
        return None


def append_line(path: Path, line: str) -> None:
    """Append one line, synced; on failure (a full disk) the file is as it was before. A
    link at the path is never followed and a FIFO or device never written (nor waited on:
    O_NONBLOCK): OSError, and the next place is tried."""
    flags = os.O_WRONLY | os.O_APPEND | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) \
        | getattr(os, "O_NONBLOCK", 0)
    fd = os.open(path, flags, 0o644)
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise OSError(errno.EINVAL, "not a regular file", str(path))
        size = info.st_size
        try:
            data = memoryview(line.encode("utf-8"))
            while data:  # a full disk may take part of it: the rest raises, then undone
                data = data[os.write(fd, data):]
            os.fsync(fd)
        except OSError:
            try:
                os.ftruncate(fd, size)
                if size == 0:
                    os.unlink(path)
            except OSError:
                pass
            raise
    finally:
        os.close(fd)


class Saver:
    """Writes each finished problem to the store at once; a problem that cannot be written
    is kept in the side file, and the first failure is remembered for the run's end."""

    def __init__(self, store: Path):
        self.store = Path(store)
        self.side = SideFile(self.store)
        self.written = 0
        self.error: StoreError | None = None
        self.lost: list[str] = []  # ids neither stored nor kept

    def save(self, record: ProblemRecord) -> None:
        try:
            write([record], self.store, compacted=False)  # compacted once, by `finish`
            self.written += 1
        except StoreError as exc:
            self.error = self.error or exc
            if self.side.keep("problem", {"record": asdict(record)}) is None:
                self.lost.append(record.problem_id)

    def finish(self) -> None:
        """At the run's end: the store written anew with only what it holds, if this run
        wrote to it. Its results are stored already: a store that cannot be compacted now
        is said in a warning (it will be at the next run's end), not an error."""
        if not self.written or self.error is not None:
            return
        try:
            compact_store(self.store)
        except StoreError as exc:
            log.warning("the store was not compacted (%s); its results are stored", exc)

    def report(self) -> list[str]:
        """The lines that say what went wrong and where the results went (empty: none)."""
        if self.error is None:
            return []
        lines = [f"error: {self.error}"]
        if self.side.path is not None:
            lines.append(f"error: the results of {self.side.count} problem(s) were not "
                         f"stored; they are kept in {self.side.path} (`mechbook restore "
                         f"{self.side.path} --store {self.store.absolute()}` stores them "
                         "once the cause is fixed)")
        if self.lost:
            lines.append(f"error: the results of {', '.join(self.lost)} could not be kept "
                         "anywhere (" + "; ".join(self.side.failures) + "): check again "
                         "once the cause is fixed")
        return lines
