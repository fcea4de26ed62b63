"""Rebuilding a damaged store: every problem, sweep and top-level entry that still reads
whole is copied into a new file (mechbook.app.store moves the damaged one aside first).

"Reads whole" is judged as the readers judge it (mechbook.app.store_check.check_entry, within
the bounds of mechbook.app.store_bounds), and the copy reads within the same bounds, so an
entry the readers would call damaged is never copied, and copying never takes more memory
than reading.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from mechbook.app.store_bounds import _SCALE_ATTRS, attribute, dataset, member, new_budget, walk
from mechbook.app.store_check import (
    _decoded,
    _member,
    _read_problem,
    _read_simulation,
    check_entry,
)


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
                        _copy_group(entry, out.require_group(top).create_group(
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
        _read_problem(entry, budget)
        dst = out.require_group("problems").create_group(pid, track_order=True)
        _copy_group(entry, dst, skip=("simulations",))
        kept.append(where)
    except Exception:  # noqa: BLE001 - the record is damaged: left out
        if where in out:
            del out[where]
        lost.append(where)
        dst = None
    try:
        sims = _member(member(member(src, "problems"), pid), "simulations")
        names = list(sims)
    except Exception:  # noqa: BLE001 - no readable list of simulations
        return
    for name in names:
        at = f"{where}/simulations/{name}"
        try:
            sim = member(sims, name)
            _read_simulation(sim, budget)
            if dst is None:  # the record is lost: its simulations stand alone
                dst = out.require_group("problems").create_group(pid, track_order=True)
            _copy_group(sim, dst.require_group("simulations").create_group(
                name, track_order=True))
            kept.append(at)
        except Exception:  # noqa: BLE001
            if at in out:
                del out[at]
            lost.append(at)


def _copy_group(src: h5py.Group, dst: h5py.Group, skip: tuple[str, ...] = ()) -> None:
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
        dst[name].make_scale(_decoded(label) or name.rsplit("/", 1)[-1])
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
        if key not in _SCALE_ATTRS:
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
