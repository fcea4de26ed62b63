"""Finding problem and answer files in a mechbook tree (problems/<book>/<n>.yaml)."""

from __future__ import annotations

import os
from pathlib import Path

from mechbook.errors import MechbookError
from mechbook.model.books import book_of
from mechbook.model.books import split_id as _split_id

DEFAULT_STORE = Path("results/mechbook.h5")  # relative to the tree's root


def root(start: str | Path | None = None) -> Path:
    """The tree holding problems/ and answers/: $MECHBOOK_ROOT, or the nearest parent."""
    env = os.environ.get("MECHBOOK_ROOT")
    if env:
        return Path(env)
    here = Path(start or Path.cwd()).resolve()
    for d in (here, *here.parents):
        if (d / "problems").is_dir():
            return d
    raise MechbookError("no problems/ directory here or above; run from a mechbook tree "
                        "or set MECHBOOK_ROOT")


def split_id(pid: str) -> tuple[str, str]:
    """'lim-2031' -> ('lim', '2031'); 'symon-09-12' -> ('symon', '09-12')."""
    return _split_id(pid)


def problem_path(pid: str, base: Path) -> Path:
    """problems/<book>/<number>.yaml; the id checked against the tree's books.yaml."""
    book_of(pid, base)
    book, rest = split_id(pid)
    return base / "problems" / book / f"{rest}.yaml"


def answer_path(pid: str, base: Path) -> Path:
    book_of(pid, base)
    book, rest = split_id(pid)
    return base / "answers" / book / f"{rest}.yaml"


def all_ids(base: Path) -> list[str]:
    out = []
    for path in sorted((base / "problems").glob("*/*.yaml")):
        out.append(f"{path.parent.name}-{path.stem}")
    return out
