"""Reading the files mechbook writes for itself, which anyone can replace: bounded, regular
files only, JSON of bounded depth.

The side file of results that could not be stored (mechbook.app.store.unsaved), the report's page
manifest (mechbook.app.report.cache) and the files `watch` polls are read back later, and in
the meantime they may have become a FIFO (reading waits for a writer that never comes), a
link to /dev/zero (reading never ends), a file of gigabytes, or JSON nested a hundred
thousand levels deep (Python's parser raises RecursionError). Every read here refuses what
is not a regular file before reading a byte, reads at most its bound, and gives nested JSON
back only up to a depth: an `Unreadable` error saying why, never a hang or a traceback.
"""

from __future__ import annotations

import errno
import json
import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import IO

from mechbook.errors import MechbookError

# a value JSON can hold (what `json.loads` gives)
JSON = dict[str, "JSON"] | list["JSON"] | str | int | float | bool | None

MAX_JSON_DEPTH = 32  # mechbook's own documents nest at most 6 levels


class Unreadable(MechbookError):
    """A file that cannot be read as asked: names it and says why (`missing`: there is no
    such file, which a cache takes as no entry rather than a damaged one)."""

    def __init__(self, path: str | Path, reason: str, missing: bool = False):
        self.path, self.reason, self.missing = Path(path), reason, missing
        super().__init__(f"cannot read {path}: {reason}")


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "a special file"


@contextmanager
def regular_file(path: str | Path, max_bytes: int) -> Iterator[IO[bytes]]:
    """`path` opened for reading if it is a regular file of at most `max_bytes` (a link is
    followed to its file). It is opened without blocking (a FIFO's open waits for a writer
    otherwise) and judged on the open file, so a file swapped meanwhile cannot slip past."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0))
    except OSError as exc:
        raise Unreadable(path, exc.strerror or str(exc),
                         missing=exc.errno == errno.ENOENT) from None
    fh = None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise Unreadable(path, f"it is {_kind(info.st_mode)}, not a regular file")
        if info.st_size > max_bytes:
            raise Unreadable(path, f"it holds {info.st_size} bytes, more than the "
                             f"{max_bytes} allowed")
        os.set_blocking(fd, True)
        fh = os.fdopen(fd, "rb")
    except BaseException:
        # a Ctrl-C inside fdopen may come after the new file object took the descriptor
        # (and closed it): closing it again must not turn the KeyboardInterrupt into an
        # OSError that escapes the caller's handler (seen once in `mechbook watch`)
        if fh is not None:
            fh.close()
        else:
            with suppress(OSError):
                os.close(fd)
        raise
    with fh:
        yield fh


def read_regular(path: str | Path, max_bytes: int) -> bytes:
    """The bytes of a regular file of at most `max_bytes` (Unreadable otherwise); what is
    read is bounded too, so a file that grows meanwhile cannot slip past."""
    with regular_file(path, max_bytes) as fh:
        try:
            data = fh.read(max_bytes + 1)
        except OSError as exc:
            raise Unreadable(path, exc.strerror or str(exc)) from None
    if len(data) > max_bytes:
        raise Unreadable(path, f"it holds more than the {max_bytes} bytes allowed")
    return data


def json_value(text: str | bytes, max_depth: int = MAX_JSON_DEPTH) -> JSON:
    """`text` parsed as JSON, refused (ValueError) when it is not JSON or nests deeper than
    `max_depth` (Python's parser itself raises RecursionError at about a thousand)."""
    try:
        value = json.loads(text)
    except RecursionError:
        raise ValueError(f"JSON nested more than {max_depth} levels deep") from None
    if depth(value) > max_depth:
        raise ValueError(f"JSON nested more than {max_depth} levels deep")
    return value


def depth(value: object) -> int:
    """How deeply lists and dicts nest in `value` (a scalar: 0), without recursion."""
    most, todo = 0, [(value, 0)]
    while todo:
        node, level = todo.pop()
        if isinstance(node, dict):
            node = list(node.values())
        if isinstance(node, list):
            most = max(most, level + 1)
            todo.extend((item, level + 1) for item in node if isinstance(item, dict | list))
    return most
