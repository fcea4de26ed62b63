"""Reading the HDF5 store: a problem's record, a simulation, the list of problems. Readers
take no lock: the store is only ever replaced by a rename (mechbook.app.store), so a reader
sees the old file or the new one. Every failure to read is a StoreError naming what is
damaged and how to recover. Nothing is taken on trust: a file that is not a store of this
mechbook's format is refused, and every record is read whole, within bounds and checked
(mechbook.app.store.entries, which `damage` and the rebuild judge by too).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import h5py

from mechbook.app.store.bounds import member, walk
from mechbook.app.store.child_read import (
    ChildEnded,
    in_child,
    is_sound,
    mark_sound,
    sheltered,
    signature,
)
from mechbook.app.store.entries import (
    damage,
    read_problem_entry,
    read_simulation_entry,
    reason_of,
    refusal,
    subgroup,
)
from mechbook.errors import MechbookError, NotFoundError
from mechbook.model.catalog import DEFAULT_STORE
from mechbook.model.hints import MAX_LISTED, did_you_mean

DEFAULT_PATH = DEFAULT_STORE


class StoreError(MechbookError):
    """The store cannot be written or read; names the file and the reason."""

    def __init__(self, path: str | Path, reason: str, action: str = "write"):
        self.path, self.reason = Path(path), reason
        super().__init__(f"cannot {action} the store {path}: {reason}")

    def __reduce__(self):  # whole across a pipe (a read in a child: mechbook.app.store.child_read)
        return (_rebuilt, (type(self), str(self.path), self.reason, str(self)))


def _rebuilt(cls: type, path: str, reason: str, message: str) -> StoreError:
    err = cls.__new__(cls)
    Exception.__init__(err, message)
    err.path, err.reason = Path(path), reason
    return err


class StoreHang(StoreError):
    """Reading the store did not end within the CPU limit: HDF5 loops on some damaged
    files (mechbook.app.store.child_read)."""

    def __init__(self, path: str | Path, seconds: float, action: str = "read"):
        super().__init__(path, f"{hang_reason(seconds)}: the file is damaged; the next "
                         "`mechbook check` into it moves it aside", action)


def hang_reason(seconds: float) -> str:
    return (f"reading it did not end within {seconds:.0f} s of CPU time (HDF5 loops on "
            "some damaged files)")


guarded = sheltered(StoreHang)  # a reader of a store not yet found sound runs in a child


@contextmanager
def opened(path: str | Path) -> Iterator[h5py.File]:
    """The store opened for reading; StoreError (what is wrong, how to recover) if it cannot
    be; FileNotFoundError if there is none."""
    if not os.path.lexists(path):
        raise FileNotFoundError(f"no store at {path}; run `mechbook check` first")
    regular_store(path)
    try:
        f = h5py.File(path, "r")
    except Exception as exc:  # noqa: BLE001 - truncated, not HDF5, a directory, unreadable
        raise StoreError(path, f"{reason_of(exc)}: the file is damaged or not a mechbook store "
                         "(the next `mechbook check` into it moves it aside and rebuilds it "
                         "from what can still be read)", "read") from None
    with f:
        why = refusal(f)
        if why is not None:
            raise StoreError(path, why, "read")
        yield f


def regular_store(path: str | Path) -> None:
    """StoreError unless `path` is a regular file (or a link to one), judged by `stat`
    before any open: a FIFO would block the open, a device be read without end."""
    if not Path(path).is_file():  # a FIFO would block the open; a directory, a dead link
        raise StoreError(path, "it is not a regular file (a directory, a FIFO, a device or "
                         "a broken link): give the path of a store", "read")


def _damaged(path: str | Path, what: str, exc: BaseException) -> StoreError:
    return StoreError(path, f"{what} is damaged ({reason_of(exc)}); the next `mechbook check` "
                      "into this store moves it aside and rebuilds it", "read")


def there(name: str, names: list[str], what: str) -> str:
    """What a store holds instead of `name`: '{what}s stored: a, b', 'no {what} is stored',
    or for many how many, and the nearest."""
    if not names:
        return f"no {what} is stored"
    if len(names) <= MAX_LISTED:
        return f"{what}s stored: {', '.join(names)}"
    close = did_you_mean(name, names)
    return f"{len(names)} {what}s stored" + (f"; {close}" if close else "")


def vet(path: str | Path = DEFAULT_PATH) -> None:
    """Read the whole store once in a child (`damage`) and, if it is sound, mark it so:
    a reader of many records (the report, a DataFrame of every problem) then reads them in
    this process, not one child each. A store that is not sound is left to each read to
    describe."""
    if is_sound(path) or signature(path) is None or not Path(path).is_file():
        return  # not a regular file: each read says so (a FIFO is never opened)
    try:
        if in_child(path, damage, path) is None:
            mark_sound(path)
    except ChildEnded:
        pass  # each read now says so at once


@guarded
def read(pid: str, path: str | Path = DEFAULT_PATH) -> dict:
    """One problem's record as plain Python data (NotFoundError, also a KeyError, naming
    those stored if it is absent; FileNotFoundError if there is no store; StoreError naming
    what is damaged). A problem that only has simulations stored has `checked` False and
    no attributes."""
    path = Path(path)
    with opened(path) as f:
        try:
            root = subgroup(f, "problems")
            present = pid in root
            stored = [] if present else names_in(f, "problems")
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, "the list of problems", exc) from None
        if not present:
            raise NotFoundError(f"{pid} is not in {path} ({there(pid, stored, 'problem')}); "
                                f"run `mechbook check {pid}`")
        try:
            return read_problem_entry(member(root, pid))
        except Exception as exc:  # noqa: BLE001 - damage inside the record, described
            raise _damaged(path, f"the stored record of {pid}", exc) from None


@guarded
def read_simulation(pid: str, name: str, path: str | Path = DEFAULT_PATH) -> dict:
    """{"attrs": {...}, "arrays": {key: array}, "array_attrs": {key: {...}}} of one run
    (NotFoundError, also a KeyError, naming the problem's stored runs if it is absent)."""
    with opened(path) as f:
        try:
            s = f["problems"][pid]["simulations"][name]
        except KeyError:
            stored = there(name, names_in(f, "problems", pid, "simulations"), "simulation")
            raise NotFoundError(f"no simulation {name!r} of {pid} in {path} ({stored})") \
                from None
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, f"the simulation {name} of {pid}", exc) from None
        try:
            return read_simulation_entry(s)
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, f"the simulation {name} of {pid}", exc) from None


@guarded
def problems(path: str | Path = DEFAULT_PATH) -> list[str]:
    """The ids stored (StoreError if the store cannot be read)."""
    with opened(path) as f:
        try:
            return sorted(subgroup(f, "problems").keys())
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, "the list of problems", exc) from None


def names_in(f: h5py.File, *keys: str) -> list[str]:
    """The names under f[keys[0]][keys[1]]..., [] where any of them is absent."""
    group = f
    for key in keys:
        if not isinstance(group, h5py.Group) or key not in group:
            return []
        group = member(group, key)
    return sorted(group) if isinstance(group, h5py.Group) else []


def _walk(group: h5py.Group, prefix: str = "") -> Iterator[tuple[str, object]]:
    """(relative name, object) of everything under `group`, parents first, bounded
    (mechbook.app.store.bounds.walk)."""
    return walk(group, prefix=prefix)


