"""A store written anew with only what it holds.

HDF5 does not give back the space of a deleted or replaced group once the file is closed:
a store edited in place grew with every run (four `check --fresh` runs: 65 to 108 kB with
nothing new). `compact` copies every top-level member into a new file with HDF5's own object
copy (H5Ocopy: creation properties, compression and attribute types kept; a 4 MB store with
3,900 objects in 0.2 s), so the new file's size depends only on its contents.

Object references do not survive a copy between files, and dimension scales are made of
them (a dataset's DIMENSION_LIST, a scale's REFERENCE_LIST): the copied reference
attributes are dropped and every scale attached again by its path. The store's writers
make no other references.
"""

from __future__ import annotations

from typing import BinaryIO

import h5py

from mechbook.app.store.repair import copy_group

_REFERENCES = ("DIMENSION_LIST", "REFERENCE_LIST")
# HDF5 1.14.2 (h5py 3.10's wheels) crashes copying a group that tracks its members' order
# and holds more than eight attributes (dense attribute storage): every stored problem.
# 2.0.0 (h5py 3.16) copies it; the versions between are untested, so they copy in Python.
NATIVE_COPY_SINCE = (2, 0, 0)


def compact(image: BinaryIO, out: BinaryIO) -> None:
    """Write the store in the file `image` into `out` (an empty file) as a new HDF5 file.

    Parameters
    ----------
    image, out : binary file objects, `image` positioned anywhere, `out` empty.

    Example: ``with open(old, "rb") as a, open(new, "w+b") as b: compact(a, b)``.
    """
    if h5py.version.hdf5_version_tuple < NATIVE_COPY_SINCE:
        with h5py.File(image, "r") as src, h5py.File(out, "w") as dst:
            copy_group(src, dst)  # member by member in Python: slower, and safe there
        return
    with h5py.File(image, "r") as src, h5py.File(out, "w") as dst:
        for key in src.attrs:
            dst.attrs.create(key, src.attrs[key], dtype=src.attrs.get_id(key).dtype)
        for name in src:
            src.copy(src[name], dst, name=name)
        links = _scale_links(src)
        for path in {p for p, _, _ in links} | {s for _, _, s in links}:
            for attr in _REFERENCES:
                if attr in dst[path].attrs:
                    del dst[path].attrs[attr]
        for path, i, scale in links:
            dst[path].dims[i].attach_scale(dst[scale])


def _scale_links(src: h5py.File) -> list[tuple[str, int, str]]:
    """(dataset, axis, scale) for every dimension scale attached in `src`, by path."""
    found: list[str] = []

    def visit(name: bytes, info) -> None:
        if info.type == h5py.h5o.TYPE_DATASET:  # (ObjInfo.num_attrs: h5py >= 3.11 only)
            if h5py.h5a.exists(h5py.h5o.open(src.id, name), b"DIMENSION_LIST"):
                found.append(name.decode("utf-8"))

    h5py.h5o.visit(src.id, visit, info=True)
    return [(path, i, scale.name) for path in found
            for i, dim in enumerate(src[path].dims) for scale in dim.values()]
