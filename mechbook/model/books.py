"""Books declared in data (`books.yaml` at the tree's root) and problem ids `<book>-<number>`.

A problem id is a book id and the book's own problem number joined by the first '-' (the
grammar: mechbook.model.ids). `books.yaml` declares each book: title, author, edition, and
a regular expression its numbers follow (`numbers`, matched in full; `example` is one number
that must match, so a broken expression is caught when the file is read). Adding a book is
an entry there and the files under problems/<book>/ and answers/<book>/; no code changes.

With books.yaml present, an id whose book it does not declare, or whose number does not look
like that book's, is refused with the reason. A tree without books.yaml (a scratch tree in a
test) accepts any well-formed id.

`numbers` is written by whoever writes books.yaml, so it is matched by RE2 (google-re2), whose
matching time is linear in the number's length whatever the pattern: a pattern such as
`(a+)+b`, which makes Python's backtracking `re` run for minutes on a 36-letter number, is
answered at once. RE2 refuses what cannot be matched that way (backreferences, lookaround)
when books.yaml is read, with the line.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from mechbook.errors import MechbookError
from mechbook.model.ids import ID, split_id  # noqa: F401 - the id grammar, for readers here

FILE = "books.yaml"


@dataclass(frozen=True)
class Book:
    """One declared book (an entry of books.yaml)."""

    id: str
    title: str
    author: str
    numbers: str  # regular expression the book's problem numbers match in full
    example: str
    short: str = ""
    edition: str = ""
    doc: str = ""

    def matches(self, number: str) -> bool:
        return compiled(self.numbers).fullmatch(number) is not None

    @property
    def label(self) -> str:
        """How problems of the book are cited: 'Symon' in 'Symon 9-12'."""
        return self.short or self.id

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


MAX_PATTERN_MEMORY = 8 * 2**20  # bytes RE2 may spend on one compiled pattern


@cache
def compiled(pattern: str):
    """`pattern` compiled by RE2 (linear-time matching); ValueError saying why it cannot
    be (a syntax error, a backreference or lookaround, a pattern too large)."""
    import re2

    options = re2.Options()
    options.log_errors = False  # the message goes into the error, not to stderr
    options.max_mem = MAX_PATTERN_MEMORY
    try:
        return re2.compile(pattern, options)
    except re2.error as exc:
        why = exc.args[0] if exc.args else exc
        why = why.decode("utf-8", "replace") if isinstance(why, bytes) else str(why)
        raise ValueError(why) from None


_CACHE: dict[Path, tuple[tuple, dict[str, Book]]] = {}


def books(base: str | Path) -> dict[str, Book]:
    """The books declared in `base`/books.yaml ({} when the tree has none), by id."""
    path = Path(base) / FILE
    try:
        st = path.stat()
    except OSError:
        if path.is_symlink():  # dangling or looping: not "no books.yaml"
            raise MechbookError(f"{path}: a symbolic link that leads nowhere "
                                f"({os.readlink(path)}): remove it or point it at a file "
                                "inside the tree") from None
        return {}
    if path.is_symlink():
        top, real = os.path.realpath(base), os.path.realpath(path)
        if os.path.commonpath([top, real]) != top:
            raise MechbookError(f"{path}: a symbolic link to {real}, outside the tree {base}: "
                                "books.yaml is read only from inside the tree (copy the file "
                                "in)")
    stamp = (st.st_mtime_ns, st.st_size)
    hit = _CACHE.get(path)
    if hit is None or hit[0] != stamp:
        hit = (stamp, load_books(path))
        _CACHE[path] = hit
    return hit[1]


def load_books(path: str | Path) -> dict[str, Book]:
    """Read and check a books.yaml; a fault is a SpecError naming file and line."""
    # at call time: `mechbook --help` reads no YAML (ruamel, jsonschema)
    from mechbook.model.schema import validate
    from mechbook.model.yamlio import load

    doc = load(path)
    validate(doc, "books")
    out: dict[str, Book] = {}
    for i, entry in enumerate(doc.data["books"]):
        where = ("books", i)
        if entry["id"] in out:
            raise doc.error(where + ("id",), f"book {entry['id']!r} is declared twice")
        try:
            compiled(entry["numbers"])
        except ValueError as exc:
            raise doc.error(where + ("numbers",), f"not a regular expression mechbook can "
                            f"match ({exc}; backreferences and lookaround are not "
                            "supported: matching must take time linear in the number's "
                            "length)") from None
        book = Book(**entry)
        if not book.matches(book.example):
            raise doc.error(where + ("example",), f"example {book.example!r} does not match "
                            f"numbers {book.numbers!r}")
        try:
            split_id(f"{book.id}-{book.example}")
        except MechbookError:
            raise doc.error(where + ("example",), f"example {book.example!r} is not a valid "
                            "problem number (letters and digits, single '.', '-' or '_' "
                            "between them)") from None
        out[book.id] = book
    return out


def book_of(pid: str, base: str | Path) -> Book | None:
    """The declared book of problem `pid`, checking the id against books.yaml (None when the
    tree declares no books); MechbookError says what is wrong with the id."""
    return declared_book(pid, *split_id(pid), base)


def declared_book(pid: str, book: str, number: str, base: str | Path) -> Book | None:
    """`book_of` for an id already split (by mechbook.model.ids.split_id)."""
    declared = books(base)
    if not declared:
        return None
    if book not in declared:
        raise MechbookError(f"problem id {pid!r}: book {book!r} is not declared in "
                            f"{Path(base) / FILE} (books: {', '.join(sorted(declared))})")
    entry = declared[book]
    if not entry.matches(number):
        raise MechbookError(f"problem id {pid!r}: {number!r} does not look like a problem "
                            f"number of {entry.label} (numbers: {entry.numbers}, e.g. "
                            f"{book}-{entry.example})")
    return entry


def file_id_error(pid: str, path: str | Path) -> str | None:
    """Why the id written in a problem file does not fit where the file lies, or None.

    In a tree (problems/<book>/<number>.yaml) the id must be <book>-<number> and follow
    books.yaml; a file elsewhere must at least end with its file name."""
    path = Path(path)
    try:
        split_id(pid)
    except MechbookError as exc:
        return str(exc)
    if path.parent.parent.name == "problems":
        expected = f"{path.parent.name}-{path.stem}"
        if pid != expected:
            return f"id {pid!r} does not match the file's place (expected {expected!r})"
        try:
            book_of(pid, path.parent.parent.parent)
        except MechbookError as exc:
            return str(exc)
        return None
    if not pid.endswith(path.stem):
        return f"id {pid!r} does not match the file name {path.stem!r}"
    return None
