"""Where results may be written: regular files only, replaced whole, no temporary left over.

A store, a netCDF sweep, a JUnit report or a plot is written only to a regular file or to a
path where nothing is yet: a directory, a FIFO or a device node at the path is refused (a
rename would replace it), and a symbolic link is followed to the regular file it names (the
link stays a link; a dangling or looping link is refused).

`replaced` writes a new version of a file beside it and renames it into place, so a reader
sees the old file or the new one. The new version is an anonymous file (Linux `O_TMPFILE`)
that gets a name only an instant before the rename: a process killed while it writes leaves
nothing behind (where `O_TMPFILE` is missing, a named temporary file is used and removed on
every error; `remove_stale` clears what a killed writer left).

`write_file` is the one writer of the files mechbook makes beside a tree's sources (the
schemas of `schema --write`, the report's pages): it refuses a link (even a dangling one), a
FIFO, a device or a directory at the path before anything is opened, writes the new version
beside it and renames it into place, so nothing is written through a link, nothing blocks on
a FIFO, and a full disk leaves the old file (or none), never an empty or half one.
"""

from __future__ import annotations

import errno
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import BinaryIO

from mechbook.errors import MechbookError

TMP_SUFFIX = ".tmp"


class OutputError(MechbookError):
    """A result cannot be written where it was asked to go; names the path and why."""

    def __init__(self, path: str | Path, reason: str, what: str = "output"):
        self.path = Path(path)
        self.reason = reason
        super().__init__(f"cannot write the {what} {path}: {reason}")


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "directory"), (stat.S_ISFIFO, "FIFO"),
                       (stat.S_ISCHR, "character device"), (stat.S_ISBLK, "block device"),
                       (stat.S_ISSOCK, "socket")):
        if test(mode):
            return name
    return "special file"


def output_file(path: str | Path, what: str = "output") -> Path:
    """The regular file to write for `path`: `path` itself, or the file a symbolic link at
    `path` names. OutputError if something other than a regular file is there."""
    path = Path(path)
    real = path
    if path.is_symlink():
        try:
            real = path.resolve(strict=True)
        except FileNotFoundError:
            raise OutputError(path, f"it is a symbolic link to nothing "
                              f"({os.readlink(path)}): remove the link or give another path",
                              what) from None
        except (RuntimeError, OSError) as exc:  # a loop (RuntimeError on Python 3.11)
            raise OutputError(path, f"it is a symbolic link that cannot be followed "
                              f"({getattr(exc, 'strerror', None) or exc})", what) from None
    try:
        info = os.stat(real)
    except FileNotFoundError:
        return real
    except OSError as exc:
        raise OutputError(path, exc.strerror or str(exc), what) from None
    if not stat.S_ISREG(info.st_mode):
        raise OutputError(path, f"it is a {_kind(info.st_mode)}, not a regular file (results "
                          "are written only to regular files): give another path", what)
    return real


def refuse_special(path: str | Path, what: str = "file") -> None:
    """OutputError unless `path` is nothing yet or a regular file that is no link: judged by
    `lstat`, so neither a link nor a FIFO is followed or opened."""
    path = Path(path)
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        return
    except OSError as exc:
        raise OutputError(path, exc.strerror or str(exc), what) from None
    if stat.S_ISLNK(info.st_mode):
        raise OutputError(path, f"it is a symbolic link (to {os.readlink(path)}): nothing "
                          "is written through a link (remove it, or give another path)", what)
    if not stat.S_ISREG(info.st_mode):
        raise OutputError(path, f"it is a {_kind(info.st_mode)}, not a regular file: "
                          "remove it, or give another path", what)


def write_file(path: str | Path, data: bytes, what: str = "file") -> Path:
    """Write `data` as the file `path`, never through a link: `refuse_special`, then a new
    file beside it renamed into place (`replaced`). OutputError names the path and why;
    on any failure the old file (or nothing) is left. Returns `path`.

    Example: ``write_file(Path("schemas/problem.json"), b"{}", "schema")``."""
    path = Path(path)
    refuse_special(path, what)
    try:
        with replaced(path) as fh:
            fh.write(data)
    except OSError as exc:
        raise OutputError(path, exc.strerror or str(exc), what) from None
    return path


def _mode_for(path: Path) -> int:
    """The new file's permissions: the old file's, or what the umask leaves of 0o666."""
    try:
        return path.stat().st_mode & 0o777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def _anonymous(directory: Path) -> int | None:
    """An unnamed file in `directory` (O_TMPFILE), or None where the system has none."""
    flag = getattr(os, "O_TMPFILE", None)
    if flag is None or not os.path.isdir("/proc/self/fd"):
        return None
    try:
        return os.open(directory, flag | os.O_RDWR, 0o600)
    except OSError as exc:
        if exc.errno in (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL, errno.ENOENT):
            return None  # the file system cannot: a named temporary file instead
        raise


def remove_stale(path: Path) -> list[Path]:
    """Remove the temporary files a killed writer of `path` left (`<name>.*.tmp`). Call it
    only while holding the lock that writers of `path` hold."""
    gone = []
    for tmp in path.parent.glob(f"{path.name}.*{TMP_SUFFIX}"):
        try:
            if tmp.is_file() and not tmp.is_symlink():
                tmp.unlink()
                gone.append(tmp)
        except OSError:
            pass
    return gone


@contextmanager
def replaced(path: str | Path, copy: bool = False) -> Iterator[BinaryIO]:
    """A binary file to write the new version of `path` into (holding a copy of the old
    file with `copy`, positioned at its start); on success it is synced and renamed over
    `path`, on any error nothing changes. `path` must already have passed `output_file`.
    (A file object, not a name: HDF5 cannot open an anonymous file by name; h5py, h5netcdf,
    ElementTree and Matplotlib all write to file objects.)"""
    path = Path(path)
    mode = _mode_for(path)
    fd = _anonymous(path.parent)
    named = None
    if fd is None:
        fd, named = tempfile.mkstemp(prefix=path.name + ".", suffix=TMP_SUFFIX,
                                     dir=path.parent)
    try:
        with open(fd, "w+b", closefd=False) as fh:
            if copy and path.exists():
                with open(path, "rb") as src:
                    shutil.copyfileobj(src, fh, 1 << 20)
                fh.seek(0)
            yield fh
            fh.flush()
        os.fchmod(fd, mode)
        os.fsync(fd)
        if named is None:  # give the anonymous file a name an instant before the rename
            named = _link_anonymous(fd, path)
        os.replace(named, path)
        named = None
        _sync_directory(path.parent)
    finally:
        os.close(fd)
        if named is not None:
            Path(named).unlink(missing_ok=True)


def _link_anonymous(fd: int, path: Path) -> str:
    """A fresh name beside `path` for the anonymous file `fd` (linkat never overwrites; a
    directory descriptor makes os.link call linkat with AT_SYMLINK_FOLLOW, which links the
    file /proc/self/fd/N stands for rather than that magic link itself)."""
    dfd = os.open(path.parent, os.O_RDONLY)
    try:
        for _ in range(100):
            name = f"{path.name}.{os.urandom(6).hex()}{TMP_SUFFIX}"
            try:
                os.link(f"/proc/self/fd/{fd}", name, dst_dir_fd=dfd, follow_symlinks=True)
                return str(path.parent / name)
            except FileExistsError:
                continue
    finally:
        os.close(dfd)
    raise FileExistsError(errno.EEXIST, "no free temporary name", str(path.parent))


def _sync_directory(directory: Path) -> None:
    try:
        dfd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(dfd)
    except OSError:
        pass
    finally:
        os.close(dfd)


def resolve_path(base: Path, path: str | Path) -> Path:
    """`path` as given when absolute, else relative to the tree's root `base` (where every
    command's --store, --out and the like are read from)."""
    path = Path(path)
    return path if path.is_absolute() else Path(base) / path
