"""Reading the HDF5 store: a problem's record, a simulation, the list of problems, and
whether the whole file reads (`damage`). Readers take no lock: the store is only ever
replaced by a rename (mechbook.app.store), so a reader sees the old file or the new one.
Every failure to read is a StoreError naming what is damaged and how to recover.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import h5py
import numpy as np

from mechbook.errors import MechbookError, NotFoundError
from mechbook.model.catalog import DEFAULT_STORE
from mechbook.model.hints import MAX_LISTED, did_you_mean

DEFAULT_PATH = DEFAULT_STORE
_SCALE_ATTRS = {"CLASS", "NAME", "DIMENSION_LIST", "REFERENCE_LIST", "DIMENSION_LABELS"}


class StoreError(MechbookError):
    """The store cannot be written or read; names the file and the reason."""

    def __init__(self, path: str | Path, reason: str, action: str = "write"):
        self.path, self.reason = Path(path), reason
        super().__init__(f"cannot {action} the store {path}: {reason}")


def _reason(exc: BaseException) -> str:
    """What went wrong, in one line (OSError's text without its errno prefix)."""
    if isinstance(exc, OSError) and exc.strerror and not exc.filename:
        return exc.strerror
    if isinstance(exc, OSError) and exc.strerror:
        return f"{exc.strerror} ({exc.filename})"
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0]


@contextmanager
def _opened(path: str | Path) -> Iterator[h5py.File]:
    """The store opened for reading; StoreError (what is wrong, how to recover) if it cannot
    be; FileNotFoundError if there is none."""
    if not os.path.lexists(path):
        raise FileNotFoundError(f"no store at {path}; run `mechbook check` first")
    if not Path(path).is_file():  # a FIFO would block the open; a directory, a dead link
        raise StoreError(path, "it is not a regular file (a directory, a FIFO, a device or "
                         "a broken link): give the path of a store", "read")
    try:
        f = h5py.File(path, "r")
    except Exception as exc:  # noqa: BLE001 - truncated, not HDF5, a directory, unreadable
        raise StoreError(path, f"{_reason(exc)}: the file is damaged or not a mechbook store "
                         "(the next `mechbook check` into it moves it aside and rebuilds it "
                         "from what can still be read)", "read") from None
    with f:
        yield f


def _damaged(path: str | Path, what: str, exc: BaseException) -> StoreError:
    return StoreError(path, f"{what} is damaged ({_reason(exc)}); the next `mechbook check` "
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


def read(pid: str, path: str | Path = DEFAULT_PATH) -> dict:
    """One problem's record as plain Python data (NotFoundError, also a KeyError, naming
    those stored if it is absent; FileNotFoundError if there is no store; StoreError naming
    what is damaged)."""
    path = Path(path)
    with _opened(path) as f:
        try:
            present = "problems" in f and pid in f["problems"]
            stored = [] if present else _names(f, "problems")
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, "the list of problems", exc) from None
        if not present:
            raise NotFoundError(f"{pid} is not in {path} ({there(pid, stored, 'problem')}); "
                                f"run `mechbook check {pid}`")
        try:
            return _read_problem(f["problems"][pid])
        except Exception as exc:  # noqa: BLE001 - damage inside the record, described
            raise _damaged(path, f"the stored record of {pid}", exc) from None


def _read_problem(g: h5py.Group) -> dict:
    out = {"attrs": {k: _plain(v) for k, v in g.attrs.items()}, "systems": {}, "checks": []}
    for sname in _member(g, "systems"):
        s = g["systems"][sname]
        entry = {"symbolic": {}, "numeric": {}, "notes": {}}
        for kind in entry:
            if kind in s:
                for name, obj in _walk(s[kind]):
                    _collect(entry[kind], name, obj)
        out["systems"][sname] = entry
    for part in _member(g, "checks"):
        c = g["checks"][part]
        out["checks"].append({"part": part, **{k: _plain(v) for k, v in c.attrs.items()}})
    out["checks"].sort(key=lambda c: c.get("index", 0))
    out["crosschecks"] = _crosschecks(g)
    out["simulations"] = sorted(_member(g, "simulations").keys())
    return out


def _crosschecks(g: h5py.Group) -> list[dict]:
    out = []
    group = _member(g, "crosschecks")
    for key in group:
        entry = {k: _plain(v) for k, v in group[key].attrs.items()}
        for k in ("parts", "modes"):
            if isinstance(entry.get(k), str):
                entry[k] = json.loads(entry[k])
        out.append((int(key), entry))
    return [e for _, e in sorted(out, key=lambda x: x[0])]


def read_simulation(pid: str, name: str, path: str | Path = DEFAULT_PATH) -> dict:
    """{"attrs": {...}, "arrays": {key: array}, "array_attrs": {key: {...}}} of one run
    (NotFoundError, also a KeyError, naming the problem's stored runs if it is absent)."""
    with _opened(path) as f:
        try:
            s = f["problems"][pid]["simulations"][name]
        except KeyError:
            stored = there(name, _names(f, "problems", pid, "simulations"), "simulation")
            raise NotFoundError(f"no simulation {name!r} of {pid} in {path} ({stored})") \
                from None
        try:
            out = {"attrs": {k: _plain(v) for k, v in s.attrs.items()}, "arrays": {},
                   "array_attrs": {}}

            def visit(key, obj):
                if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
                    out["arrays"][key] = np.array(obj[()])
                    out["array_attrs"][key] = {k: _plain(v) for k, v in obj.attrs.items()
                                               if k not in _SCALE_ATTRS}

            s.visititems(visit)
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, f"the simulation {name} of {pid}", exc) from None
    return out


def problems(path: str | Path = DEFAULT_PATH) -> list[str]:
    """The ids stored (StoreError if the store cannot be read)."""
    with _opened(path) as f:
        try:
            return sorted(_member(f, "problems").keys())
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, "the list of problems", exc) from None


def _names(f: h5py.File, *keys: str) -> list[str]:
    """The names under f[keys[0]][keys[1]]..., [] where any of them is absent."""
    group = f
    for key in keys:
        if key not in group:
            return []
        group = group[key]
    return sorted(group)


def _member(group: h5py.Group, name: str):
    """group[name], {} if there is none; an entry that is listed but cannot be opened (h5py's
    `get` gives None for it, which reads as absent) raises: it is damage, not absence."""
    return group[name] if name in group else {}


def _walk(group: h5py.Group, prefix: str = "") -> Iterator[tuple[str, object]]:
    """(relative name, object) of everything under `group`, parents first. By the groups'
    own listings, as `read` finds things (HDF5's visititems walks the metadata another way
    and fails on damage that leaves every member readable)."""
    for name in group:
        obj = group[name]  # raises if listed but unreadable
        yield prefix + name, obj
        if isinstance(obj, h5py.Group):
            yield from _walk(obj, f"{prefix}{name}/")


def _read_all(group: h5py.Group) -> None:
    """Read every attribute, dataset and string under `group` (raises on damage)."""
    _attrs(group)
    for _, obj in _walk(group):
        _attrs(obj)
        if isinstance(obj, h5py.Dataset):
            _decoded(obj[()])


def _attrs(obj) -> dict:
    return {k: _decoded(obj.attrs[k]) for k in obj.attrs if k not in _SCALE_ATTRS}


def _decoded(v):
    """A value read from HDF5 with its strings decoded (UnicodeDecodeError if damaged)."""
    if isinstance(v, bytes):
        return v.decode("utf-8")
    if isinstance(v, np.ndarray) and v.dtype.kind == "O":
        return [_decoded(x) for x in v.ravel()]
    return v


def damage(path: str | Path) -> str | None:
    """What is wrong with the store at `path` (None: every object and attribute reads, and
    every string is UTF-8). Reads the whole file once."""
    try:
        with h5py.File(path, "r") as f:
            _read_all(f)
    except Exception as exc:  # noqa: BLE001 - any failure to read is damage, described
        return _reason(exc)
    return None


def _collect(target: dict, name: str, obj) -> None:
    if isinstance(obj, h5py.Dataset):
        data = obj[()]
        target[name] = data.decode() if isinstance(data, bytes) else (
            np.array(data) if obj.dtype.kind == "f" else _plain(data))


def _plain(v):
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.generic):
        return v.item()
    return v
