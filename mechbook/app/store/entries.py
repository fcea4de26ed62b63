"""A store's records read whole and checked to be what mechbook writes, within bounds.

Everything here reads within the bounds of mechbook.app.store.bounds (a small file can
declare gigabytes) and refuses what a check never writes: a record without the attributes a
check always writes, an outcome that is not one, cross-checks of JSON that does not parse or
nests too deep, members a record never holds. A file that is HDF5 but not a mechbook store,
or of a newer store format, is refused with the reason (`refusal`), never judged damaged.
The readers (mechbook.app.store.reader), `damage` and the rebuild of a damaged store
(mechbook.app.store.repair) all judge an entry by `check_entry`, so what `show` calls
damaged is what the next write moves aside, and nothing else.
"""

from __future__ import annotations

import functools
from pathlib import Path

import h5py
import numpy as np

from mechbook.app.bounded import json_value
from mechbook.app.store.bounds import (
    Oversized,
    attribute,
    attributes,
    dataset,
    member,
    members,
    new_budget,
    record,
    walk,
)
from mechbook.records import CrossCheck, Status

FORMAT = 1  # the store format this mechbook reads and writes (the root's `format` attribute)

# what a check writes on every problem and every part, since the first store format
_PROBLEM_ATTRS = {"title": str, "source": str, "problem_sha256": str, "date": str,
                  "mechbook": str, "duration_s": (int, float)}
_CHECK_ATTRS = {"quantity": str, "cite": str, "status": str, "method": str, "detail": str,
                "seconds": (int, float)}
_CROSSCHECK_ATTRS = {"name": str, "kind": str, "system": str, "detail": str,
                     "error": (int, float), "seconds": (int, float)}
_GROUPS = ("systems", "checks", "crosschecks", "simulations")


class Damaged(ValueError):
    """A record that is not what a check writes (a missing attribute, an unknown outcome)."""


def _one_record(read):
    """`read(g, budget)` with the datasets it reads counted against one record's bound
    (mechbook.app.store.bounds.record): every reader of a record goes through it."""
    @functools.wraps(read)
    def bounded(g, budget: list[int] | None = None) -> dict:
        with record(getattr(g, "name", "?")):
            return read(g, budget)

    return bounded


def reason_of(exc: BaseException) -> str:
    """What went wrong, in one line (OSError's text without its errno prefix)."""
    if isinstance(exc, OSError) and exc.strerror and not exc.filename:
        return exc.strerror
    if isinstance(exc, OSError) and exc.strerror:
        return f"{exc.strerror} ({exc.filename})"
    if isinstance(exc, RecursionError):
        return "nested too deeply"
    if isinstance(exc, MemoryError):
        return "too large to read"
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0]


def refusal(f: h5py.File) -> str | None:
    """Why the open HDF5 file `f` is not a store this mechbook may read or write (None: it
    is one): no `format` attribute (HDF5 made by something else), or a format it does not
    know. Such a file is refused, never moved aside or rebuilt: it is not mechbook's."""
    try:
        if "format" not in f.attrs:
            return ("it is an HDF5 file but not a mechbook store (it has no `format` "
                    "attribute): mechbook reads and writes only its own stores; give another "
                    "path")
        value = attribute(f, "format")
    except Exception as exc:  # noqa: BLE001 - an unreadable root: damage, judged elsewhere
        return None if not isinstance(exc, Oversized) else f"its format attribute: {exc}"
    if isinstance(value, np.generic):
        value = value.item()
    if not isinstance(value, int) or isinstance(value, bool) or value < 1:
        return (f"its format attribute is {value!r}, not a mechbook store format: mechbook "
                "reads and writes only its own stores; give another path")
    if value > FORMAT:
        return (f"it is in store format {value}, newer than this mechbook's ({FORMAT}): read "
                "and write it with the newer mechbook that made it, or give another path")
    return None


def _group(obj, what: str) -> h5py.Group:
    if not isinstance(obj, h5py.Group):
        raise Damaged(f"{what} is not a group")
    return obj


def _typed(attrs: dict, wanted: dict, where: str) -> None:
    for key, kind in wanted.items():
        if key not in attrs:
            raise Damaged(f"{where} lacks its attribute {key!r}")
        if not isinstance(attrs[key], kind) or isinstance(attrs[key], bool):
            raise Damaged(f"{where}: the attribute {key!r} is {attrs[key]!r}")


@_one_record
def read_problem_entry(g, budget: list[int] | None = None) -> dict:
    """A problem's record, read whole (every attribute and dataset of it, within the
    bounds; its simulations only by name: each is read on its own) and checked to be what
    a check writes: Damaged, Oversized or HDF5's own errors otherwise."""
    g = _group(g, f"the entry {g.name}")
    unknown = sorted(set(g) - set(_GROUPS))
    if unknown:
        raise Damaged(f"{g.name} holds {unknown[0]!r}, which a check never writes")
    attrs = {k: plain_value(v) for k, v in attributes(g, budget).items()}
    checked = any(k in attrs for k in _PROBLEM_ATTRS) or any(k in g for k in _GROUPS[:3])
    if checked:
        _typed(attrs, _PROBLEM_ATTRS, g.name)
    out = {"attrs": attrs, "systems": {}, "checks": [], "checked": checked}
    systems = subgroup(g, "systems")
    if systems:
        attributes(systems, budget)
    for sname in members(systems) if systems else ():
        s = _group(member(systems, sname), f"the system {sname}")
        attributes(s, budget)
        entry = {"symbolic": {}, "numeric": {}, "notes": {}}
        unknown = sorted(set(s) - set(entry))
        if unknown:
            raise Damaged(f"{s.name} holds {unknown[0]!r}, which a check never writes")
        for kind in s:
            group = _group(member(s, kind), f"{s.name}/{kind}")
            attributes(group, budget)
            for name, obj in walk(group, budget):
                attributes(obj, budget)
                _collect(entry[kind], name, obj)
        out["systems"][sname] = entry
    checks = subgroup(g, "checks")
    if checks:
        attributes(checks, budget)
    for part in members(checks) if checks else ():
        c = _group(member(checks, part), f"the check of part {part}")
        if len(c):
            raise Damaged(f"{c.name} holds members, which a check never writes")
        a = {k: plain_value(v) for k, v in attributes(c, budget).items()}
        _typed(a, _CHECK_ATTRS, c.name)
        if a["status"] not in set(Status):
            raise Damaged(f"{c.name}: the status {a['status']!r} is not an outcome")
        out["checks"].append({"part": part, **a})
    out["checks"].sort(key=lambda c: c.get("index", 0) if isinstance(c.get("index", 0), int)
                       else 0)
    out["crosschecks"] = read_crosschecks(g, budget)
    sims = subgroup(g, "simulations")
    if sims:
        attributes(sims, budget)
    out["simulations"] = sorted(members(sims)) if sims else []
    for name in out["simulations"]:
        _group(member(sims, name), f"the simulation {name}")
    return out


def read_crosschecks(g: h5py.Group, budget: list[int] | None = None) -> list[dict]:
    out = []
    group = subgroup(g, "crosschecks")
    if group:
        attributes(group, budget)
    for key in members(group) if group else ():
        if not key.isdigit() or len(key) > 9:
            raise Damaged(f"the cross-check entry {key!r} is not numbered")
        x = _group(member(group, key), f"the cross-check {key}")
        if len(x):
            raise Damaged(f"{x.name} holds members, which a check never writes")
        entry = {k: plain_value(v) for k, v in attributes(x, budget).items()}
        for k in ("parts", "modes"):
            if isinstance(entry.get(k), str):
                try:
                    entry[k] = json_value(entry[k])
                except ValueError as exc:
                    raise Damaged(f"{group.name}/{key}: {k}: {exc}") from None
                if not isinstance(entry[k], list):
                    raise Damaged(f"{group.name}/{key}: {k} is not a list")
        if not all(isinstance(p, str) for p in entry.get("parts") or []) or \
                not all(isinstance(m, dict) for m in entry.get("modes") or []):
            raise Damaged(f"{group.name}/{key}: its parts or modes are not what a check "
                          "writes")
        if entry.get("status") not in set(Status):
            raise Damaged(f"{group.name}/{key}: the status {entry.get('status')!r} is not "
                          "an outcome")
        for k, kind in _CROSSCHECK_ATTRS.items():
            if k in entry and (not isinstance(entry[k], kind) or isinstance(entry[k], bool)):
                raise Damaged(f"{group.name}/{key}: the attribute {k!r} is {entry[k]!r}")
        CrossCheck.from_dict(entry)
        out.append((int(key), entry))
    return [e for _, e in sorted(out, key=lambda x: x[0])]


@_one_record
def read_simulation_entry(s, budget: list[int] | None = None) -> dict:
    """A stored simulation, read whole within the bounds: its float arrays and their
    attributes (every other dataset and attribute read too, so damage anywhere shows)."""
    s = _group(s, f"the simulation {s.name}")
    out = {"attrs": {k: plain_value(v) for k, v in attributes(s, budget).items()}, "arrays": {},
           "array_attrs": {}}
    for key, obj in walk(s, budget):
        attrs = {k: plain_value(v) for k, v in attributes(obj, budget).items()}
        if isinstance(obj, h5py.Dataset):
            value = dataset(obj)
            if obj.dtype.kind == "f":
                out["arrays"][key] = np.array(value)
                out["array_attrs"][key] = attrs
    return out


def subgroup(group: h5py.Group, name: str):
    """group[name] (a group), {} if there is none; an entry that is listed but cannot be
    opened (h5py's `get` gives None for it, which reads as absent) raises: it is damage,
    not absence; so does a link that is not a plain one, and anything but a group."""
    return _group(member(group, name), f"{group.name.rstrip('/')}/{name}") \
        if name in group else {}


def _read_all(group: h5py.Group, budget: list[int] | None = None) -> None:
    """Read every attribute, dataset and string under `group`, within the bounds (raises on
    damage, on anything oversized, and past `budget` objects)."""
    decoded(attributes(group, budget))
    for _, obj in walk(group, budget):
        decoded(attributes(obj, budget))
        if isinstance(obj, h5py.Dataset):
            decoded(dataset(obj))


def decoded(v):
    """A value read from HDF5 with its strings decoded (UnicodeDecodeError if damaged)."""
    if isinstance(v, bytes):
        return v.decode("utf-8")
    if isinstance(v, dict):
        return {k: decoded(x) for k, x in v.items()}
    if isinstance(v, np.ndarray) and v.dtype.kind == "O":
        return [decoded(x) for x in v.ravel()]
    return v


def check_entry(top: str, name: str | None, obj, budget: list[int] | None = None) -> None:
    """Read one top-level entry of a store (a problem with its simulations, the sweeps of a
    problem, or anything else at the top) as its readers will, whole: raises on any damage.
    `damage` and the rebuild of a damaged store judge every entry by this, so that a record
    `show` or a check's cache would call damaged is never called sound."""
    if top == "problems" and name is not None:
        read_problem_entry(obj, budget)
        sims = subgroup(obj, "simulations")
        for sim in sims:
            read_simulation_entry(member(sims, sim), budget)
    elif top == "sweeps" and name is not None:
        attributes(_group(obj, f"the sweeps of {name}"), budget)
        for sweep in obj:
            read_sweep_entry(member(obj, sweep), budget)
    elif isinstance(obj, h5py.Group):
        _read_all(obj, budget)
    else:
        decoded(attributes(obj, budget))
        decoded(dataset(obj))


def damage(path: str | Path) -> str | None:
    """What is wrong with the store at `path` (None: every entry reads whole, as
    `check_entry` reads it). Reads the whole file once, within the bounds."""
    budget = new_budget()
    try:
        with h5py.File(path, "r") as f:
            decoded(attributes(f, budget))
            for top in f:
                obj = member(f, top)
                if top in ("problems", "sweeps"):
                    obj = _group(obj, f"/{top}")
                    for name in obj:
                        check_entry(top, name, member(obj, name), budget)
                    decoded(attributes(obj, budget))
                else:
                    check_entry(top, None, obj, budget)
    except Exception as exc:  # noqa: BLE001 - any failure to read is damage, described
        return reason_of(exc)
    return None


def _collect(target: dict, name: str, obj) -> None:
    if isinstance(obj, h5py.Dataset):
        data = dataset(obj)
        target[name] = data.decode() if isinstance(data, bytes) else (
            np.array(data) if obj.dtype.kind == "f" else plain_value(data))


def plain_value(v: object) -> object:
    """A value read from HDF5 as plain Python (bytes decoded, NumPy scalars as numbers)."""
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.generic):
        return v.item()
    return v


@_one_record
def read_sweep_entry(g, budget: list[int] | None = None) -> dict:
    """A stored sweep, read whole within the store's bounds (mechbook.app.store.bounds);
    raises on damage."""
    if not isinstance(g, h5py.Group):
        raise ValueError(f"{g.name} is not a group")
    attrs = {k: (v.decode() if isinstance(v, bytes) else v)
             for k, v in attributes(g, budget).items()}
    coords, vars_ = {}, {}
    for key in g:
        d = member(g, key)
        if not isinstance(d, h5py.Dataset):
            raise ValueError(f"{d.name} is not a dataset")
        attributes(d, budget)
        if d.is_scale:
            coords[key] = dataset(d)
    for key in g:
        d = g[key]
        if not d.is_scale:
            dims = tuple(d.dims[i][0].name.rsplit("/", 1)[-1] for i in range(d.ndim))
            vars_[key] = (dims, dataset(d))
    return {"attrs": attrs, "coords": coords, "variables": vars_}
