"""Issue 34 item 2, a store that does not grow: HDF5 never gives back the space of a replaced
group, and on 0834a76 four `check --fresh -j 1` runs took the store from 65 075 to 108 083
bytes with nothing new, and each `simulate` added about 8 kB. A store's size now depends on
what it holds, not on how many runs wrote it."""

from __future__ import annotations

import io

import h5py
import numpy as np
from hostile import check, pendulum_tree, run

import mechbook.app.store as store
from mechbook.app.store.compaction import compact


def _size(path) -> int:
    return path.stat().st_size


def test_fresh_checks_leave_the_store_as_large_as_it_was(tmp_path):
    base = pendulum_tree(tmp_path, nums=("2101", "2102"))
    path = base / "results" / "mechbook.h5"
    sizes = []
    for _ in range(3):
        result = check(base, "--fresh")
        assert result.exit_code == 0, result.output
        sizes.append(_size(path))
    assert sizes[0] == sizes[1] == sizes[2], sizes
    assert [c["status"] for c in store.read("lim-2101", path)["checks"]] == ["pass"]


def test_a_simulation_stored_again_under_its_name_takes_no_more_room(tmp_path):
    base = pendulum_tree(tmp_path)
    path = base / "results" / "mechbook.h5"
    sizes = []
    for _ in range(3):
        result = run("--root", base, "simulate", "lim-2101", "--t-end", "2")
        assert result.exit_code == 0, result.output
        sizes.append(_size(path))
    assert sizes[0] == sizes[1] == sizes[2], sizes
    runs = store.read("lim-2101", path)["simulations"]
    assert len(runs) == 1
    # the copy keeps t and coordinate as dimension scales (xarray opens the group by them)
    with h5py.File(path, "r") as f:
        (sim,) = f["problems/lim-2101/simulations"].values()
        assert sim["t"].is_scale and sim["coordinate"].is_scale
        assert [sim["q"].dims[i].keys() for i in range(2)] == [["coordinate"], ["t"]]
        assert sim["q"].shape[1] == sim["t"].shape[0] > 1


def test_a_store_grown_by_edits_in_place_shrinks_to_its_contents_when_next_written(tmp_path):
    """A store written by an earlier mechbook (edited in place) holds dead space; the next
    write gives it back, and what it held reads as before (values, text, order, scales)."""
    path = tmp_path / "old.h5"
    with h5py.File(path, "w") as f:
        f.attrs["format"] = store.FORMAT
        f.create_group("problems")
    for i in range(20):  # replaced run after run, each its own session, as before this issue
        with h5py.File(path, "r+") as f:
            problems = f["problems"]
            if "lim-2101" in problems:
                del problems["lim-2101"]
            g = problems.create_group("lim-2101", track_order=True)
            g.attrs["title"] = f"run {i}"
            g.create_dataset("b", data=np.arange(200.0) * i)
            g.create_dataset("a", data="text ✓", dtype=h5py.string_dtype("utf-8"))
    grown = _size(path)
    with open(path, "rb") as src:
        out = io.BytesIO()
        compact(src, out)
    assert len(out.getvalue()) < grown / 2, (len(out.getvalue()), grown)
    out.seek(0)
    with h5py.File(out, "r") as f:
        g = f["problems/lim-2101"]
        assert g.attrs["title"] == "run 19"
        assert list(g) == ["b", "a"]  # the order members were made in, kept
        assert np.array_equal(g["b"][()], np.arange(200.0) * 19)
        assert g["a"][()].decode() == "text ✓"
        assert f.attrs["format"] == store.FORMAT
