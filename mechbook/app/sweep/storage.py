"""A sweep's result on disk, with named dimensions: in the HDF5 store or a netCDF-4 file.

Store layout (beside /problems, so a check run, which replaces /problems/<id>, keeps it):
    /sweeps/<id>/<name>          attrs: quantity, point, axes, timings, accuracy (JSON), ...
    /sweeps/<id>/<name>/<axis>   the axis values, an HDF5 dimension scale named after it
    /sweeps/<id>/<name>/mode     0..n-1, a dimension scale
    /sweeps/<id>/<name>/<var>    frequencies (axes…, mode), stability (axes…: 1 stable,
                                 0 marginal, −1 unstable, −2 undefined), growth, linear,
                                 measured, relative_error; book_stable, book_margin,
                                 book_frequencies (the book's answer on the same grid)
A sweep larger than STORE_POINTS goes to a netCDF-4 file instead (h5netcdf; xarray opens it
with the dimensions named) and the store keeps only its attributes and the file's path, so
the store, which is rewritten whole on every edit, stays small.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from mechbook.app.outputs import OutputError, output_file, replaced
from mechbook.app.store import (
    StoreError,
    atomic_edit,
    attribute_value,
    attributes,
    check_run_name,
    member,
    names_in,
    opened,
    read_sweep_entry,
    reason_of,
    refusal,
    there,
)
from mechbook.errors import NotFoundError
from mechbook.version import __version__

STORE_POINTS = 250_000


def variables(result) -> tuple[dict, dict, dict]:
    """(coords {dim: values}, variables {name: (dims, array)}, attrs) of a result."""
    coords = dict(result.coords)
    vars_ = {k: (result.dims[k], v) for k, v in result.arrays.items()}
    book = result.book
    names = tuple(result.coords)
    if "stable" in book:
        vars_["book_stable"] = (names, book["stable"].astype(np.int8))
    if "margin" in book:
        vars_["book_margin"] = (names, book["margin"])
    if "frequencies" in book:
        vars_["book_frequencies"] = (names + ("book_mode",), book["frequencies"])
        coords["book_mode"] = np.arange(book["frequencies"].shape[-1])
    modes = [v.shape[-1] for dims, v in vars_.values() if dims[-1:] == ("mode",)]
    if modes:
        coords["mode"] = np.arange(modes[0])
    attrs = {k: v for k, v in result.attrs.items()}
    for k in ("condition", "cite", "part", "disagree", "max_rel_diff"):
        if k in book:
            attrs[f"book_{k}"] = book[k]
    attrs["mechbook"] = __version__
    return coords, vars_, attrs


def write_store(result, name: str, path: str | Path) -> Path:
    """Add (or replace) the sweep at /sweeps/<id>/<name> of the store, atomically."""
    _check_name(name)
    coords, vars_, attrs = variables(result)
    with atomic_edit(path) as f:
        root = f.require_group("sweeps").require_group(result.spec.pid)
        if name in root:
            del root[name]
        g = root.create_group(name, track_order=True)
        g.attrs.update({k: attribute_value(v) for k, v in attrs.items()})
        if result.attrs["points"] > STORE_POINTS:
            return Path(path)  # the data went to a netCDF file; its path is in the attrs
        scales = {}
        for dim, values in coords.items():
            d = g.create_dataset(dim, data=np.asarray(values))
            d.make_scale(dim)
            scales[dim] = d
        for key, (dims, arr) in vars_.items():
            d = g.create_dataset(key, data=arr, compression="gzip")
            for i, dim in enumerate(dims):
                d.dims[i].attach_scale(scales[dim])
    return Path(path)


def read_store(pid: str, name: str, path: str | Path) -> dict:
    """{"attrs": {...}, "coords": {...}, "variables": {name: (dims, array)}}; NotFoundError
    (also a KeyError) naming the problem's stored sweeps if it is absent, StoreError naming
    what is damaged."""
    with opened(path) as f:
        try:
            g = f["sweeps"][pid][name]
        except KeyError:
            stored = there(name, names_in(f, "sweeps", pid), "sweep")
            raise NotFoundError(f"no sweep {name!r} of {pid} in {path} ({stored})") from None
        except Exception as exc:  # noqa: BLE001 - a damaged listing, described
            raise StoreError(path, f"the sweep {name} of {pid} is damaged ({reason_of(exc)})",
                             "read") from None
        try:
            return read_sweep_entry(g)
        except Exception as exc:  # noqa: BLE001 - damage inside the sweep, described
            raise StoreError(path, f"the sweep {name} of {pid} is damaged ({reason_of(exc)})",
                             "read") from None


def stored_sweeps(pid: str, path: str | Path) -> list[tuple[str, str]]:
    """(name, one-line description) of a problem's stored sweeps (a damaged entry is one
    line that says so)."""
    out = []
    try:
        with h5py.File(path, "r") as f:
            if refusal(f) is not None or "sweeps" not in f or pid not in f["sweeps"]:
                return out
            group = member(member(f, "sweeps"), pid)
            for name in group:
                try:
                    g = member(group, name)
                    a = {k: (v.decode() if isinstance(v, bytes) else v)
                         for k, v in attributes(g).items()}
                except Exception as exc:  # noqa: BLE001 - one damaged entry, said so
                    out.append((name, f"damaged ({reason_of(exc)})"))
                    continue
                where = f" in {a['file']}" if a.get("file") else ""
                out.append((name, f"{a.get('quantity')} over {a.get('axes')} about "
                                  f"{a.get('point')}{where}"))
    except Exception as exc:  # noqa: BLE001 - the store itself unreadable: said so
        out.append(("?", f"the sweeps cannot be read ({reason_of(exc)})"))
    return out


def write_netcdf(result, path: str | Path) -> Path:
    """The sweep as a netCDF-4 file, replacing a regular file (or nothing) at `path` whole
    (mechbook.app.outputs); OutputError with the path and the reason if it cannot be."""
    import h5netcdf

    path = Path(path)
    real = output_file(path, "netCDF file")
    coords, vars_, attrs = variables(result)
    try:
        real.parent.mkdir(parents=True, exist_ok=True)
        with replaced(real) as fh, h5netcdf.File(fh, "w") as f:
            f.dimensions = {dim: len(v) for dim, v in coords.items()}
            for dim, values in coords.items():
                f.create_variable(dim, (dim,), data=np.asarray(values))
            for key, (dims, arr) in vars_.items():
                f.create_variable(key, dims, data=arr, compression="gzip")
            for k, v in attrs.items():  # netCDF has no boolean attributes
                f.attrs[k] = int(v) if isinstance(v, (bool, np.bool_)) else attribute_value(v)
    except (OSError, RuntimeError, ValueError) as exc:
        raise OutputError(path, str(exc).splitlines()[0] if str(exc) else
                          type(exc).__name__, "netCDF file") from exc
    return path


def read_netcdf(path: str | Path) -> dict:
    import h5netcdf

    with h5netcdf.File(path, "r") as f:
        coords = {d: f.variables[d][...] for d in f.dimensions if d in f.variables}
        vars_ = {k: (v.dimensions, v[...]) for k, v in f.variables.items() if k not in coords}
        attrs = dict(f.attrs)
    return {"attrs": attrs, "coords": coords, "variables": vars_}


def _check_name(name: str) -> None:
    check_run_name(name, "sweep")
