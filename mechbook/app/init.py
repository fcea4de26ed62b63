"""`mechbook init DIR`: a tree of one's own to start from, which `mechbook check` passes.

The starter tree (mechbook/app/starter, shipped in the package) holds books.yaml with one
book, one example problem (a pendulum on a spring, its radius declared positive) with its
answer key, and a Makefile with the usual targets; and the JSON Schemas of those files
under schemas/, which the first line of each names for an editor's YAML language server
(mechbook.app.editor). Nothing is overwritten: a file that
exists already is refused, naming it.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from mechbook.app.editor import DIRECTORY, NAMES, write_schemas
from mechbook.errors import MechbookError

FILES = {"books.yaml": "books.yaml", "problem.yaml": "problems/mybook/1.1.yaml",
         "answers.yaml": "answers/mybook/1.1.yaml", "Makefile": "Makefile"}


def init_tree(target: str | Path) -> list[Path]:
    """Write the starter tree into `target` (created if needed); the files written."""
    target = Path(target)
    if target.exists() and not target.is_dir():
        raise MechbookError(f"{target} exists and is not a directory")
    dests = [*FILES.values(), *(f"{DIRECTORY}/{name}.json" for name in NAMES)]
    clashes = [target / dest for dest in dests if (target / dest).exists()]
    if clashes:
        raise MechbookError(f"{clashes[0]} exists already: `mechbook init` writes nothing "
                            "over an existing file (choose an empty directory)")
    written = []
    try:
        written += write_schemas(target / DIRECTORY)  # the files' modelines name these
    except OSError as exc:
        raise MechbookError(f"cannot write {target / DIRECTORY}: {exc.strerror}") from None
    source = resources.files("mechbook.app").joinpath("starter")
    for name, dest in FILES.items():
        path = target / dest
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(source.joinpath(name).read_bytes())
        except OSError as exc:
            raise MechbookError(f"cannot write {path}: {exc.strerror}") from None
        written.append(path)
    return written
