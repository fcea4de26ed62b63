"""Finding problem and answer files in a mechbook tree (problems/<book>/<n>.yaml)."""

from __future__ import annotations

import os
from pathlib import Path

from mechbook.errors import MechbookError, NothingSelectedError
from mechbook.model.books import declared_book
from mechbook.model.ids import check_id, split_id  # noqa: F401 - the id grammar, re-exported

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
    raise MechbookError("no problems/ directory here or above: run from a mechbook tree, "
                        "name one with --root DIR (or set MECHBOOK_ROOT=DIR), or start one "
                        "with `mechbook init DIR`")


def _inside(base: Path, folder: str, book: str, rest: str) -> Path:
    path = base / folder / book / f"{rest}.yaml"
    top = os.path.normpath(base / folder)
    if os.path.commonpath([top, os.path.normpath(path)]) != top:  # check_id makes it so
        raise MechbookError(f"problem id {book}-{rest} resolves outside {top}")
    return _stays_inside(path, base / folder)


def _stays_inside(path: Path, top: Path) -> Path:
    """`path` if nothing is there yet, or it is a regular file whose real location (links
    followed, of the file or of a folder on the way) is inside `top`. A link that leaves
    the tree, dangles or loops, and anything not a regular file, is refused: a problem file
    is read only from inside the tree, and nothing outside is ever shown."""
    if not os.path.lexists(path):
        return path  # nothing there: nothing will be read
    try:
        real = path.resolve(strict=True)
    except FileNotFoundError:
        raise MechbookError(f"{path}: a symbolic link to nothing "
                            f"({os.readlink(path)}): remove it or point it at a file "
                            "inside the tree") from None
    except (RuntimeError, OSError):  # a loop (RuntimeError on Python 3.11), or unreadable
        raise MechbookError(f"{path}: a symbolic link that cannot be followed (a loop?): "
                            "remove it") from None
    inner = Path(os.path.realpath(top))
    if real != inner and inner not in real.parents:
        raise MechbookError(f"{path}: a symbolic link to {real}, outside {top}: problem and "
                            "answer files must stay inside the tree (copy the file in)")
    if not real.is_file():
        raise MechbookError(f"{path}: not a regular file")
    return path


def _tree_file(folder: str, pid: str, base: Path) -> Path:
    """<folder>/<book>/<number>.yaml: the id parsed once (mechbook.model.ids), checked
    against the tree's books.yaml, and the path kept inside the tree."""
    book, number = split_id(pid)
    declared_book(pid, book, number, base)
    return _inside(base, folder, book, number)


def problem_path(pid: str, base: Path) -> Path:
    """problems/<book>/<number>.yaml (see _tree_file)."""
    return _tree_file("problems", pid, base)


def existing_problem_path(pid: str, base: Path) -> Path:
    """`problem_path`, and a NothingSelectedError when no file is there: the one message
    for "no such problem" of the command line and the API alike."""
    path = problem_path(pid, base)
    if not os.path.lexists(path):
        raise NothingSelectedError(f"no problem {pid} (no file {path}; `mechbook list` "
                                   "shows the problems there are)")
    return path


def answer_path(pid: str, base: Path) -> Path:
    """answers/<book>/<number>.yaml (see _tree_file)."""
    return _tree_file("answers", pid, base)


def all_ids(base: Path) -> list[str]:
    out = []
    for path in sorted((base / "problems").glob("*/*.yaml")):
        out.append(f"{path.parent.name}-{path.stem}")
    return out
