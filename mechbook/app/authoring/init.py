"""`mechbook init DIR`: a tree of one's own to start from, which `mechbook check` passes.

The starter tree (mechbook/app/authoring/starter, shipped in the package) holds books.yaml with one
book, one example problem (a pendulum on a spring, its radius declared positive) with its
answer key, a Makefile with the usual targets, a README that says what is where and how to
go on, a .gitignore for what mechbook writes (results/); and the JSON Schemas of those files
under schemas/, which the first line of each names for an editor's YAML language server
(mechbook.app.authoring.editor). Nothing is overwritten: a file that
exists already is refused, naming it.

Nothing is written outside DIR either. DIR itself may be a link to a directory (the user
named it), but below it every folder is made or opened without following a link and every
file is created new (O_EXCL, O_NOFOLLOW), relative to the folder's descriptor: a dangling
link or a linked folder left under DIR is refused with its name, never written through.
"""

from __future__ import annotations

import errno
import os
import stat
from importlib import resources
from pathlib import Path

from mechbook.app.authoring.editor import DIRECTORY, NAMES
from mechbook.app.authoring.editor import text as schema_text
from mechbook.errors import MechbookError

# starter file -> where it goes (`gitignore`: a package's data files are not dot files)
FILES = {"books.yaml": "books.yaml", "problem.yaml": "problems/mybook/1.1.yaml",
         "answers.yaml": "answers/mybook/1.1.yaml", "Makefile": "Makefile",
         "README.md": "README.md", "gitignore": ".gitignore"}
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_DIRECTORY = getattr(os, "O_DIRECTORY", 0)


def _fail(path: Path, exc: OSError) -> MechbookError:
    if exc.errno == errno.ELOOP or (exc.errno == errno.ENOTDIR and os.path.islink(path)):
        return MechbookError(f"{path} is a symbolic link: `mechbook init` writes nothing "
                             "through a link (remove it, or choose an empty directory)")
    if exc.errno == errno.EEXIST:
        return MechbookError(f"{path} exists already: `mechbook init` writes nothing over an "
                             "existing file or link (choose an empty directory)")
    return MechbookError(f"cannot write {path}: {exc.strerror or exc}")


def _top(target: Path) -> int:
    """A descriptor of DIR, made if it does not exist (its parents too)."""
    if not str(target).strip():
        raise MechbookError("no directory named: give the directory to start the tree in "
                            "(`mechbook init mytree`)")
    if os.path.islink(target) and not os.path.isdir(target):
        raise MechbookError(f"{target} is a symbolic link to nothing or to no directory "
                            f"({os.readlink(target)}): choose another directory")
    try:
        if os.path.lexists(target) and not os.path.isdir(target):
            raise MechbookError(f"{target} exists and is not a directory")
        target.mkdir(parents=True, exist_ok=True)
        fd = os.open(target, os.O_RDONLY | _DIRECTORY)
    except OSError as exc:
        raise _fail(target, exc) from None
    return fd


def _folder(parent: int, name: str, shown: Path) -> int:
    """The sub-folder `name` of the folder `parent` (made if missing), never a link."""
    try:
        os.mkdir(name, 0o777, dir_fd=parent)
    except FileExistsError:
        pass
    except OSError as exc:
        raise _fail(shown, exc) from None
    try:
        fd = os.open(name, os.O_RDONLY | _DIRECTORY | _NOFOLLOW, dir_fd=parent)
    except OSError as exc:
        raise _fail(shown, exc) from None
    if not stat.S_ISDIR(os.fstat(fd).st_mode):
        os.close(fd)
        raise MechbookError(f"{shown} exists and is not a directory")
    return fd


def _clash(top: int, dest: str, target: Path) -> str | None:
    """Why `dest` (relative to the folder `top`) cannot be written, before anything is:
    a folder on the way that is a link or not a folder, or something (a file, a link, even
    a dangling one) at the file's place already. None: it can."""
    *folders, name = dest.split("/")
    shown, at = target, ""
    for part in [*folders, name]:
        shown, at = shown / part, f"{at}/{part}" if at else part
        try:
            info = os.stat(at, dir_fd=top, follow_symlinks=False)
        except FileNotFoundError:
            return None  # nothing here: nothing below it either
        except OSError as exc:
            return str(_fail(shown, exc))
        if part == name:
            return (f"{shown} exists already: `mechbook init` writes nothing over an "
                    "existing file or link (choose an empty directory)")
        if stat.S_ISLNK(info.st_mode):
            return (f"{shown} is a symbolic link: `mechbook init` writes nothing through a "
                    "link (remove it, or choose an empty directory)")
        if not stat.S_ISDIR(info.st_mode):
            return f"{shown} exists and is not a directory"
    return None


def _names_fit(target: Path) -> None:
    """Every name on the way to DIR no longer than the file system allows (checked before
    anything is made, so a refusal leaves nothing behind)."""
    longest = 255
    for part in target.parts:
        if len(os.fsencode(part)) > longest:
            raise MechbookError(f"cannot write {target}: the name {part[:40]}... is "
                                f"{len(os.fsencode(part))} bytes long (at most {longest})")


def init_tree(target: str | Path) -> list[Path]:
    """Write the starter tree into `target` (created if needed); the files written."""
    target = Path(target)
    _names_fit(target)
    contents = {f"{DIRECTORY}/{name}.json": schema_text(name).encode("utf-8")
                for name in NAMES}  # first: the files' modelines name these
    source = resources.files("mechbook.app.authoring").joinpath("starter")
    contents.update((dest, source.joinpath(name).read_bytes()) for name, dest in FILES.items())
    top = _top(target)
    try:
        for dest in contents:
            why = _clash(top, dest, target)
            if why is not None:
                raise MechbookError(why)
        written = []
        for dest, data in contents.items():
            _write(top, dest, target, data)
            written.append(target / dest)
    finally:
        os.close(top)
    return written


def _write(top: int, dest: str, target: Path, data: bytes) -> None:
    """Create `dest` (relative to the folder `top`) new, folders on the way without
    following links."""
    *folders, name = dest.split("/")
    fds = [top]
    shown = target
    try:
        for folder in folders:
            shown = shown / folder
            fds.append(_folder(fds[-1], folder, shown))
        shown = shown / name
        try:
            fd = os.open(name, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW, 0o666,
                         dir_fd=fds[-1])
        except OSError as exc:
            raise _fail(shown, exc) from None
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view):]
        except OSError as exc:
            raise _fail(shown, exc) from None
        finally:
            os.close(fd)
    finally:
        for fd in fds[1:]:
            os.close(fd)
