"""Issue 33, fuzz case 3064 (store kind, seed 1): one byte of a store flipped (the length
of a string in an HDF5 global heap collection) made libhdf5 spin for ever inside
`H5Aread` (HDFGroup/hdf5#1707), and with it every reader: the warm-run cache of `check`,
`show`, the damage check before a write. A store not yet found sound is now read in a
child under a CPU limit (mechbook.app.store.child_read); a file HDF5 does not come back from is
a StoreError, gives no cache hits, and is moved aside unread by the next write."""

from __future__ import annotations

import struct
import time

import h5py
import pytest
from hostile import check, pendulum_tree

import mechbook.app.store as store
import mechbook.app.store.child_read as guard


def _looping(path) -> None:
    """Make the store at `path` one HDF5 loops on: the stored title's string, 6 bytes
    long in the global heap, given a length of 262."""
    with h5py.File(path, "r+") as f:
        f["problems/lim-2101"].attrs["title"] = "newton"
    data = bytearray(path.read_bytes())
    at = data.find(struct.pack("<Q", 6) + b"newton")
    assert at > 0
    data[at:at + 8] = struct.pack("<Q", 262)
    path.write_bytes(bytes(data))


@pytest.fixture
def quick(monkeypatch):
    """A 1 s CPU limit for the children (10 s and more by default)."""
    monkeypatch.setattr(guard, "GUARD_CPU_SECONDS", 1.0)
    monkeypatch.setattr(guard, "_SOUND", {})
    monkeypatch.setattr(guard, "_ENDED", {})


def test_readers_of_a_store_hdf5_loops_on_end_with_an_error(tmp_path, quick):
    base = pendulum_tree(tmp_path)
    assert check(base).exit_code == 0
    path = base / "results" / "mechbook.h5"
    _looping(path)
    start = time.monotonic()
    with pytest.raises(store.StoreError, match="did not end within .* s of CPU time"):
        store.read("lim-2101", path)
    with pytest.raises(store.StoreError, match="did not end"):
        store.problems(path)  # said at once: this version already did not come back
    assert store.cached({"lim-2101": ("a", "b")}, path) == {}
    assert store.durations(path) == {}
    assert time.monotonic() - start < 60  # a hang would never end


def test_a_check_into_it_moves_it_aside_unread_and_goes_on(tmp_path, quick, caplog):
    base = pendulum_tree(tmp_path)
    assert check(base).exit_code == 0
    path = base / "results" / "mechbook.h5"
    _looping(path)
    damaged = path.read_bytes()
    result = check(base)
    assert result.exit_code == 0, result.output
    assert [c["status"] for c in store.read("lim-2101", path)["checks"]] == ["pass"]
    (aside,) = path.parent.glob("mechbook.h5.damaged-*")
    assert aside.read_bytes() == damaged  # kept whole beside the new store
    assert "did not end" in caplog.text and "moved aside" in caplog.text


def test_a_sound_store_is_read_in_this_process_once_found_sound(tmp_path, quick,
                                                                monkeypatch):
    base = pendulum_tree(tmp_path)
    assert check(base).exit_code == 0
    path = base / "results" / "mechbook.h5"
    forks = []
    real = guard.in_child
    monkeypatch.setattr(guard, "in_child", lambda *a, **k: forks.append(1) or real(*a, **k))
    guard._SOUND.clear()
    assert store.read("lim-2101", path)["attrs"]["title"]  # not known sound: a child
    assert len(forks) == 1
    guard.mark_sound(path)
    store.read("lim-2101", path)
    store.problems(path)
    assert len(forks) == 1  # known sound: read here
    store.write([], path)  # written by this process: still known sound
    store.read("lim-2101", path)
    assert len(forks) == 1


def test_vet_reads_the_whole_store_once_for_a_reader_of_many_records(tmp_path, quick):
    base = pendulum_tree(tmp_path, nums=("2101", "2102"))
    assert check(base).exit_code == 0
    path = base / "results" / "mechbook.h5"
    guard._SOUND.clear()
    assert not guard.is_sound(path)
    store.vet(path)
    assert guard.is_sound(path)
    _looping(path)  # a new version of the file: not known sound, and HDF5 loops on it
    store.vet(path)
    assert not guard.is_sound(path)
    with pytest.raises(store.StoreError, match="did not end"):
        store.read("lim-2102", path)
