"""Reading an HDF5 store that may come from anywhere: every object's size is known, and
bounded, before a byte of it is read.

A store is a file like any other: someone can hand over one made elsewhere. HDF5 lets a
small file declare a large object — a 14 KB file holding one gzip-compressed dataset of
zeros decompresses to gigabytes, a chunked dataset never written reads as its whole
declared shape of fill values — and reading it whole would take that memory in the process
that reads it (the parent of `mechbook check`, outside any worker's `--memory`). So
everything read from a store goes through this module:

- a dataset or attribute is read only if its declared size (elements × item size) is within
  its bound; a variable-length string array only up to a count of strings, its strings
  read one at a time and given up past the bound (one string is physical data in the file,
  never compressed: it cannot be larger than the file);
- only the types mechbook writes (numbers, booleans, strings); a dataset whose data lies in
  other files (HDF5's external storage, a virtual dataset) or a soft or external link is
  refused, so nothing outside the store is ever read through it;
- one record (a problem's, a simulation's, a sweep's) is bounded in total too
  (`MAX_RECORD_BYTES`, counted by `record`): a dozen datasets each just under their own
  bound would otherwise take gigabytes together;
- walks are bounded in depth, in members per group (counted before the group is listed)
  and in the number of objects (a group may hold itself).

Every refusal is an `Oversized` (a ValueError): to a reader it is damage, described.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any

import h5py
import numpy as np

MAX_DATASET_BYTES = 256 * 2**20  # one dataset in memory; the largest mechbook writes is a
# simulation's q or q̇: 16 coordinates × 10^6 samples × 8 bytes = 128 MB
MAX_RECORD_BYTES = 2 * MAX_DATASET_BYTES  # the datasets of one record together: a
# simulation's q and q̇ at their largest, and its times
MAX_ATTRIBUTE_BYTES = 2**20  # one attribute; HDF5 keeps mechbook's under 64 KiB
MAX_STRINGS = 4096  # strings in one dataset or attribute (mechbook writes one, or a
# simulation's coordinate names)
MAX_TEXT_BYTES = 64 * 2**20  # the strings of one dataset together
MAX_OBJECTS = 200_000  # groups, datasets and attributes walked in one store (a full check
# of the book stores about 14,000)
MAX_MEMBERS = 10_000  # members of one group inside a record (a check writes a few hundred)
MAX_DEPTH = 24  # nesting of groups (mechbook's deepest is about 9)
SCALE_ATTRS = {"CLASS", "NAME", "DIMENSION_LIST", "REFERENCE_LIST", "DIMENSION_LABELS"}
# what a bounded read gives: an array, or one number, string or bytes (HDF5's scalars)
Value = np.ndarray | np.generic | str | bytes | int | float | bool
_NUMERIC = "fiub"  # float, signed and unsigned integers, booleans (an HDF5 enum)


class Oversized(ValueError):
    """Something in the store that is not read: too large, of a type mechbook never
    writes, or reaching outside the file."""


_RECORD: ContextVar[list | None] = ContextVar("mechbook_store_record", default=None)


@contextmanager
def record(name: str) -> Iterator[None]:
    """Within it, the datasets read (`dataset`) count against one record's bound,
    MAX_RECORD_BYTES, by their declared sizes before they are read: Oversized past it."""
    token = _RECORD.set([MAX_RECORD_BYTES, name])
    try:
        yield
    finally:
        _RECORD.reset(token)


def _spend_bytes(n: int) -> None:
    left = _RECORD.get()
    if left is None:
        return
    left[0] -= n
    if left[0] < 0:
        raise Oversized(f"the record {left[1]} holds more than {_size_text(MAX_RECORD_BYTES)} "
                        "of data in its datasets together (at most that is read)")


def _size_text(n: float) -> str:
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.1f} {unit}"
    return f"{n:.0f} bytes"


def _check(what, shape, dtype: np.dtype, limit: int) -> bool:
    """Whether it is variable-length text (to be read string by string); Oversized if its
    declared size or its type is not what a store may hold. `what()` names it (called only
    for the message: naming an HDF5 object costs a call into the library)."""
    count = int(np.prod(shape, dtype=object)) if shape else (0 if shape is None else 1)
    if dtype.kind == "O":
        vlen = h5py.check_string_dtype(dtype)
        if vlen is None or vlen.length is not None:
            raise Oversized(f"{what()} is of the type {dtype}, which a mechbook store never "
                            "holds")
        if count > MAX_STRINGS:
            raise Oversized(f"{what()} declares {count} strings (at most {MAX_STRINGS})")
        return True
    if dtype.kind not in _NUMERIC and dtype.kind != "S":
        raise Oversized(f"{what()} is of the type {dtype}, which a mechbook store never holds")
    if count * dtype.itemsize > limit:
        raise Oversized(f"{what()} declares {_size_text(count * dtype.itemsize)} of data "
                        f"(at most {_size_text(limit)} are read)")
    return False


def dataset(d: h5py.Dataset) -> Value:
    """The value of `d`, read only within the bounds (Oversized otherwise)."""
    def what() -> str:
        return f"the dataset {d.name}"

    plist = d.id.get_create_plist()
    if plist.get_layout() not in (h5py.h5d.COMPACT, h5py.h5d.CONTIGUOUS, h5py.h5d.CHUNKED) \
            or plist.get_external_count():
        raise Oversized(f"{what()} keeps its data in other files (external or virtual "
                        "storage): not read")
    if not _check(what, d.shape, d.dtype, MAX_DATASET_BYTES):
        _spend_bytes(int(np.prod(d.shape, dtype=object)) * d.dtype.itemsize if d.shape
                     else d.dtype.itemsize)
        return d[()]
    if d.shape == ():
        value = _text(what, d[()])
        _spend_bytes(len(value) if isinstance(value, bytes | str) else 0)
        return value
    out, total = [], 0
    for index in np.ndindex(*d.shape):
        value = d[index]
        size = len(value) if isinstance(value, bytes | str) else 0
        total += size
        _spend_bytes(size)
        if total > MAX_TEXT_BYTES:
            raise Oversized(f"{what()} holds more than {_size_text(MAX_TEXT_BYTES)} of text")
        out.append(value)
    return np.array(out, dtype=object).reshape(d.shape)


def _text(what, value: Any, limit: int = MAX_TEXT_BYTES) -> Any:
    if isinstance(value, bytes | str) and len(value) > limit:
        raise Oversized(f"{what()} holds {_size_text(len(value))} of text (at most "
                        f"{_size_text(limit)})")
    return value


def attribute(obj, name: str, attrs=None) -> Value:
    """The attribute `name` of `obj`, read only within the bounds (Oversized otherwise);
    `attrs`: obj.attrs, where the caller has it already."""
    attrs = obj.attrs if attrs is None else attrs

    def what() -> str:
        return f"the attribute {name!r} of {obj.name}"

    aid = attrs.get_id(name)
    shape, dtype = aid.shape, aid.dtype
    if shape is None:  # HDF5's empty dataspace
        return h5py.Empty(dtype)
    if dtype.subdtype is not None:
        raise Oversized(f"{what()} is of the type {dtype}, which a mechbook store never holds")
    text = _check(what, shape, dtype, MAX_ATTRIBUTE_BYTES)
    # read through the attribute already open, as h5py's attrs[name] does, without opening
    # it and converting its type a second time (a store holds ten thousand attributes)
    value = np.zeros(shape, dtype=dtype)
    aid.read(value, mtype=h5py.h5t.py_create(dtype))
    if text:
        strings = [_text(what, b.decode("utf-8", "surrogateescape") if isinstance(b, bytes)
                         else b, MAX_ATTRIBUTE_BYTES) for b in value.flat]
        value = np.array(strings, dtype=dtype).reshape(value.shape)
    return value[()] if value.ndim == 0 else value


def attributes(obj, budget: list[int] | None = None) -> dict[str, Value]:
    """Every attribute of `obj` but the dimension scales' bookkeeping, each read within
    the bounds; `budget` ([objects left]) counts them against a walk's bound."""
    attrs = obj.attrs
    out = {}
    for name in attrs:
        if budget is not None:
            spend(budget, obj)
        if name not in SCALE_ATTRS:
            out[name] = attribute(obj, name, attrs)
    return out


def spend(budget: list[int], where) -> None:
    budget[0] -= 1
    if budget[0] < 0:
        raise Oversized(f"more than {MAX_OBJECTS} objects (at {where.name}): not a mechbook "
                        "store")


def member(group: h5py.Group, name: str):
    """group[name] where it is a plain (hard) link: a soft link may make a loop and an
    external link names another file, and a mechbook store holds neither."""
    link = group.get(name, getlink=True)
    if not isinstance(link, h5py.HardLink):
        kind = "an external link" if isinstance(link, h5py.ExternalLink) else "a soft link"
        raise Oversized(f"{group.name.rstrip('/')}/{name} is {kind}: not followed")
    return group[name]


def walk(group: h5py.Group, budget: list[int] | None = None, prefix: str = "",
         level: int = 0) -> Iterator[tuple[str, h5py.Group | h5py.Dataset]]:
    """(relative name, object) of everything under `group`, parents first, by the groups'
    own listings (HDF5's visititems walks the metadata another way and fails on damage
    that leaves every member readable); bounded in depth and, with `budget`, in count."""
    if level > MAX_DEPTH:
        raise Oversized(f"{group.name} is nested more than {MAX_DEPTH} levels deep")
    for name in members(group):
        if budget is not None:
            spend(budget, group)
        obj = member(group, name)  # raises if listed but unreadable
        yield prefix + name, obj
        if isinstance(obj, h5py.Group):
            yield from walk(obj, budget, f"{prefix}{name}/", level + 1)


def members(group: h5py.Group) -> list[str]:
    """The names in `group`, if there are at most MAX_MEMBERS (HDF5 counts them without
    listing them); Oversized otherwise."""
    count = len(group)
    if count > MAX_MEMBERS:
        raise Oversized(f"{group.name} holds {count} members (at most {MAX_MEMBERS} in a "
                        "record)")
    return list(group)


def new_budget() -> list[int]:
    """The count of objects one walk of a store may visit (see `spend`)."""
    return [MAX_OBJECTS]
