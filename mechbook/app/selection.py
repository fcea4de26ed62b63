"""Which problems a command means: ids, glob patterns over ids, a book's id, and the
problems that failed last time (`--lf`), as pytest users expect.

    mechbook check lim-2031 symon-09-12    ids, as they are
    mechbook check 'mybook-*' 'lim-20[34]?'  every id of the tree the pattern matches
    mechbook check mybook                  every problem of the book
    mechbook check --lf                    those that failed or errored when last checked

The last failures are kept beside the store (`.<store name>.lastfailed.json`), updated
after every check like pytest's cache: a problem checked now is added if it failed and
dropped if it passed; the others keep their entry.
"""

from __future__ import annotations

import fnmatch
import json
import re
from collections.abc import Iterable, Sequence
from pathlib import Path

from mechbook.app.bounded import Unreadable, json_value, read_regular
from mechbook.app.outputs import replaced
from mechbook.errors import InputError, NothingSelectedError
from mechbook.model.catalog import all_ids
from mechbook.model.ids import BOOK, ID, split_id

GLOB = set("*?[")
MAX_PATTERN = 512  # characters of one id pattern: an id has at most 121, and fnmatch's
# translation into a regular expression takes time quadratic in the pattern (30,000 '['
# took 35 s before this bound), so a longer pattern is refused before it is compiled
_BOOK = re.compile(BOOK)


def select(args: Sequence[str], base: Path) -> list[str]:
    """The problem ids `args` name, in their order, each once. An argument that is a
    well-formed id stays as it is (its file is looked up later); a pattern or a book that
    names no problem of the tree is a NothingSelectedError saying which there are."""
    out: list[str] = []
    tree: list[str] | None = None
    for arg in args:
        if ID.fullmatch(arg) or not (GLOB & set(arg) or _BOOK.fullmatch(arg)):
            found = [arg]  # an id, or something the id grammar refuses with its reason
        else:
            tree = all_ids(base) if tree is None else tree
            found = _matching(arg, tree, base)
        out += [pid for pid in found if pid not in out]
    return out


def _matching(arg: str, tree: list[str], base: Path) -> list[str]:
    if len(arg) > MAX_PATTERN:
        raise InputError(f"the id pattern {arg[:40]!r}... is {len(arg)} characters long (at "
                         f"most {MAX_PATTERN}; a problem id has at most 121)")
    if GLOB & set(arg):
        found = [pid for pid in tree if fnmatch.fnmatchcase(pid, arg)]
        what = f"no problem id matches {arg!r}"
    else:
        found = [pid for pid in tree if split_id(pid)[0] == arg]
        what = f"no problem of book {arg!r}"
    if not found:
        books = sorted({split_id(pid)[0] for pid in tree})
        raise NothingSelectedError(f"{what} under {base / 'problems'} (books there: "
                            f"{', '.join(books) or 'none'}; a pattern such as "
                            f"'{books[0] if books else 'mybook'}-*' selects a book's "
                            "problems)")
    return found


# ---- the last failures -----------------------------------------------------------------------
MAX_RECORD_BYTES = 16 << 20  # the ids of far more problems than any tree holds


def lastfailed_path(store: Path) -> Path:
    return store.with_name(f".{store.name}.lastfailed.json")


def last_failed(store: Path) -> set[str]:
    """The ids that failed when last checked (none when nothing was recorded)."""
    try:  # anyone may have put a FIFO, a link to /dev/zero or deep JSON there: bounded
        data = json_value(read_regular(lastfailed_path(store), MAX_RECORD_BYTES))
    except (OSError, ValueError, Unreadable):
        return set()
    failed = data.get("failed") if isinstance(data, dict) else None
    return {p for p in failed if isinstance(p, str)} if isinstance(failed, list) else set()


def record(store: Path, checked: Iterable[str], failed: Iterable[str]) -> None:
    """Update the record: `checked` ids now failed (`failed`) or passed; OSError if it
    cannot be written (the caller says so)."""
    failed = set(failed)
    now = (last_failed(store) - set(checked)) | failed
    path = lastfailed_path(store)
    path.parent.mkdir(parents=True, exist_ok=True)
    # a new file renamed into place: a killed or failed write leaves nothing behind, and a
    # link put at the path is replaced, never written through
    with replaced(path) as fh:
        fh.write((json.dumps({"failed": sorted(now)}, indent=1) + "\n").encode("utf-8"))
