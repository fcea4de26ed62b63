"""A damaged store, found before an edit (`ensure_sound`), moved aside whole and rebuilt:
every problem, sweep and top-level entry that still reads whole is copied into a new file.

"Reads whole" is judged as the readers judge it (mechbook.app.store.entries.check_entry, within
the bounds of mechbook.app.store.bounds), and the copy reads within the same bounds, so an
entry the readers would call damaged is never copied, and copying never takes more memory
than reading. The file is read in a child under a CPU limit (mechbook.app.store.child_read):
HDF5 loops for ever on some damage.
"""

from __future__ import annotations

import logging
import os
from datetime import UTC, datetime
from pathlib import Path

import h5py
import numpy as np

from mechbook.app.outputs import replaced
from mechbook.app.store.bounds import SCALE_ATTRS, attribute, dataset, member, new_budget, walk
from mechbook.app.store.child_read import ChildEnded, in_child, is_sound, mark_sound
from mechbook.app.store.entries import (
    FORMAT,
    check_entry,
    damage,
    decoded,
    read_problem_entry,
    read_simulation_entry,
    refusal,
    subgroup,
)
from mechbook.app.store.reader import StoreError, hang_reason

log = logging.getLogger("mechbook.store")
DAMAGED = ".damaged-"  # a damaged store is moved aside to <name>.damaged-<UTC time>


def _salvage(path: Path, out: h5py.File) -> tuple[list[str], list[str]]:
    """Copy every problem, sweep and top-level entry of the damaged file at `path` that
    reads whole into `out`; ([kept], [lost]) by name."""
    kept: list[str] = []
    lost: list[str] = []
    budget = new_budget()
    try:
        src = h5py.File(path, "r")
    except Exception:  # noqa: BLE001 - nothing readable at all: an empty store
        return kept, ["the whole file"]
    with src:
        try:
            tops = list(src.keys())
        except Exception:  # noqa: BLE001
            return kept, ["the whole file"]
        for top in tops:
            try:
                obj = member(src, top)
                children = list(obj.keys()) if isinstance(obj, h5py.Group) and \
                    top in ("problems", "sweeps") else None
            except Exception:  # noqa: BLE001
                lost.append(f"/{top}")
                continue
            for name in (children if children is not None else [None]):
                where = f"/{top}/{name}" if name is not None else f"/{top}"
                if top == "problems" and name is not None:
                    _salvage_problem(src, out, name, budget, kept, lost)
                    continue
                try:
                    entry = member(src[top], name) if name is not None else member(src, top)
                    check_entry(top, name, entry, budget)
                    if isinstance(entry, h5py.Group):
                        copy_group(entry, out.require_group(top).create_group(
                            name, track_order=True) if name is not None
                            else out.create_group(top, track_order=True))
                    else:
                        _copy_dataset(entry, out.require_group(top) if name else out,
                                      name or top)
                    kept.append(where)
                except Exception:  # noqa: BLE001 - that entry is damaged: left out
                    if where in out:
                        del out[where]
                    lost.append(where)
    return kept, lost


def _salvage_problem(src: h5py.File, out: h5py.File, pid: str, budget: list[int],
                     kept: list[str], lost: list[str]) -> None:
    """A problem's record and each of its simulations, kept or lost apart: a damaged
    simulation costs only itself, a damaged record not its simulations."""
    where = f"/problems/{pid}"
    try:
        entry = member(member(src, "problems"), pid)
        read_problem_entry(entry, budget)
        dst = out.require_group("problems").create_group(pid, track_order=True)
        copy_group(entry, dst, skip=("simulations",))
        kept.append(where)
    except Exception:  # noqa: BLE001 - the record is damaged: left out
        if where in out:
            del out[where]
        lost.append(where)
        dst = None
    try:
        sims = subgroup(member(member(src, "problems"), pid), "simulations")
        names = list(sims)
    except Exception:  # noqa: BLE001 - no readable list of simulations
        return
    for name in names:
        at = f"{where}/simulations/{name}"
        try:
            sim = member(sims, name)
            read_simulation_entry(sim, budget)
            if dst is None:  # the record is lost: its simulations stand alone
                dst = out.require_group("problems").create_group(pid, track_order=True)
            copy_group(sim, dst.require_group("simulations").create_group(
                name, track_order=True))
            kept.append(at)
        except Exception:  # noqa: BLE001
            if at in out:
                del out[at]
            lost.append(at)


def copy_group(src: h5py.Group, dst: h5py.Group, skip: tuple[str, ...] = ()) -> None:
    """Copy a subtree between files as plain data (object references, which dimension
    scales are made of, do not survive a copy between files: the scales are re-attached by
    their paths inside the subtree); the members named in `skip` are left out."""
    _copy_attrs(src, dst)
    scales, links = [], []
    for name, obj in walk(src):
        if name.split("/", 1)[0] in skip:
            continue
        if isinstance(obj, h5py.Group):
            _copy_attrs(obj, dst.create_group(name, track_order=True))
            continue
        _copy_dataset(obj, dst, name)
        if obj.is_scale:
            scales.append((name, obj.attrs.get("NAME", b"")))
        for i, dim in enumerate(obj.dims):
            for scale in dim.values():
                links.append((name, i, scale.name[len(src.name):].lstrip("/")))
    for name, label in scales:
        dst[name].make_scale(decoded(label) or name.rsplit("/", 1)[-1])
    for name, i, scale in links:
        if scale in dst:
            dst[name].dims[i].attach_scale(dst[scale])


def _copy_dataset(obj: h5py.Dataset, dst: h5py.Group, name: str) -> None:
    d = dst.create_dataset(name, data=_as_read(dataset(obj)), dtype=obj.dtype,
                           compression=obj.compression)
    _copy_attrs(obj, d)


def _copy_attrs(src, dst) -> None:
    """Every attribute of `src` but the scales' bookkeeping, with its type."""
    for key in src.attrs:
        if key not in SCALE_ATTRS:
            dst.attrs.create(key, _as_read(attribute(src, key)), dtype=src.attrs.get_id(key).dtype)


def _as_read(value):
    """Text as its bytes were: the readers decode what is not UTF-8 (damage flips bytes of
    a string too) with surrogate escapes, which HDF5 cannot encode; the bytes go back as
    they came (a string type takes bytes unchanged)."""
    if isinstance(value, str):
        return value.encode("utf-8", "surrogateescape")
    if isinstance(value, np.ndarray) and value.dtype == object:
        return np.array([_as_read(v) for v in value.flat], dtype=object).reshape(value.shape)
    return value


# ---- before an edit: a damaged store moved aside and rebuilt -------------------------------
def _foreign(path: Path) -> str | None:
    """Why the file at `path` is not a store this mechbook may write (HDF5 made by
    something else, a newer store format), or None (a store of ours, or not HDF5 at all:
    then it is damage, judged by `damage`)."""
    try:
        f = h5py.File(path, "r")
    except Exception:  # noqa: BLE001 - not readable as HDF5: damage
        return None
    with f:
        return refusal(f)


def ensure_sound(path: Path, shown: Path) -> None:
    """Before an edit: a damaged store is moved aside and rebuilt from what still reads; a
    file that is not a store of this mechbook's format is refused (StoreError), whole. The
    file is read in a child under a CPU limit (mechbook.app.store.child_read): HDF5 loops for
    ever on some damage, and a file it does not come back from is moved aside unread."""
    if is_sound(path):
        return
    try:
        foreign = in_child(path, _foreign, path)
        why = None if foreign is not None else in_child(path, damage, path)
    except ChildEnded as end:
        foreign, why = None, hang_reason(end.seconds)
    if foreign is not None:
        raise StoreError(shown, foreign)
    if why is None:
        mark_sound(path)
        return
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%S.%fZ")
    aside = path.with_name(f"{path.name}{DAMAGED}{stamp}")
    with replaced(path) as fh:  # the rebuilt store
        try:
            kept, lost = in_child(path, _rebuilt_into, path, fh)
        except ChildEnded:
            kept, lost = [], ["everything (HDF5 did not come back from reading it)"]
            fh.seek(0)
            fh.truncate()
            with h5py.File(fh, "w") as out:
                out.attrs["format"] = FORMAT
        os.link(path, aside)  # the damaged file stays whole beside the new one
    mark_sound(path)
    lost_text = f"; could not read (lost here, kept in the damaged file): {', '.join(lost)}" \
        if lost else ""
    log.warning("the store %s was damaged (%s): moved aside to %s and rebuilt with the %d "
                "entries that could still be read%s", shown, why, aside, len(kept), lost_text)


def _rebuilt_into(path: Path, fh) -> tuple[list[str], list[str]]:
    """In the child: the store rebuilt from what of `path` still reads, written into `fh`
    (the parent's new file, shared across the fork); ([kept], [lost])."""
    with h5py.File(fh, "w") as out:
        out.attrs["format"] = FORMAT
        kept, lost = _salvage(path, out)
    fh.flush()
    return kept, lost
