"""Issue 33, a store from elsewhere: everything read from it is bounded before it is read
(a 40 KB file declaring a 3.2 GB compressed dataset, a megabyte attribute), a file that is
HDF5 but not a mechbook store or of a newer format is refused and left as it is, links
inside the file are not followed (a loop, a file outside the tree), and a damaged record
that `show` calls damaged is what the next check moves aside, with a warning.

Real `mechbook show` and `mechbook check` processes with their address space bounded to
2 GB (reading the bomb whole needs 3.2 GB)."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from hostile import mechbook, pendulum_tree, run

import mechbook.app.store as store

MARKER = "OUTSIDE-THE-STORE-3c9a"


@pytest.fixture(scope="module")
def checked(tmp_path_factory) -> Path:
    """Two pendulums checked once for the module, with their cross-checks (a record's
    crosschecks/ group is damaged below): a real record of each, written the way `check`
    writes them (in this process, serially: the records are the same as a worker's)."""
    base = pendulum_tree(tmp_path_factory.mktemp("checked") / "tree", nums=("2101", "2102"))
    res = run("--root", base, "check", "--serial")
    assert res.exit_code == 0, res.output
    return base


@pytest.fixture
def tree(checked, tmp_path) -> Path:
    """A copy of the checked tree of the test's own (each test damages its store)."""
    return Path(shutil.copytree(checked, tmp_path / "tree"))


def _store(tree: Path) -> Path:
    return tree / "results" / "mechbook.h5"


def _bomb(path: Path) -> None:
    """One gzip-compressed dataset of 4 * 10^8 zeros (3.2 GB in memory) under a record;
    only its first chunk is written, so the file stays small."""
    with h5py.File(path, "a") as f:
        d = f.create_dataset("problems/lim-2101/systems/main/numeric/bomb",
                             shape=(400_000_000,), dtype="f8", chunks=(1 << 20,),
                             compression="gzip", fillvalue=0.0)
        d[: 1 << 20] = 0.0


def _clean(res) -> None:
    text = res.stdout + res.stderr
    for bad in ("Traceback", "MemoryError", "Unable to allocate", "None by mechbook None"):
        assert bad not in text, text


def test_a_compressed_bomb_is_refused_before_it_is_read(tree):
    path = _store(tree)
    _bomb(path)
    assert path.stat().st_size < 200_000
    res = mechbook("--root", tree, "show", "lim-2101", cwd=tree)
    _clean(res)
    assert res.returncode == 1
    assert "/problems/lim-2101/systems/main/numeric/bomb declares 3.2 GB" in res.stderr
    # the other record still reads
    assert mechbook("--root", tree, "show", "lim-2102", cwd=tree).returncode == 0
    # a check into it: the check's parent reads the store, outside any worker's --memory
    res = mechbook("--root", tree, "check", "lim-2102", "-j", "1", "--no-crosscheck",
                   "--fresh", cwd=tree)
    _clean(res)
    assert res.returncode == 0, res.stderr
    assert re.search(r"warning: the store .* was damaged \(the dataset "
                     r"/problems/lim-2101/\S+ declares 3.2 GB", res.stderr), res.stderr
    assert "could not read (lost here, kept in the damaged file): /problems/lim-2101" \
        in res.stderr
    assert store.problems(path) == ["lim-2102"]
    assert len(list(path.parent.glob("mechbook.h5.damaged-*"))) == 1


def test_the_bounds_are_checked_on_the_declared_size():
    """A dataset never written reads as its whole shape of fill values: refused at once."""
    import tempfile

    from mechbook.app.store.bounds import MAX_DATASET_BYTES, Oversized, dataset

    with tempfile.TemporaryFile() as fh, h5py.File(fh, "w") as f:
        d = f.create_dataset("x", shape=(10**10,), dtype="f8", chunks=(1 << 16,))
        with pytest.raises(Oversized, match="declares 80.0 GB"):
            dataset(d)
        small = f.create_dataset("y", data=np.arange(10.0))
        assert dataset(small).tolist() == list(range(10))
        assert MAX_DATASET_BYTES >= 16 * 10**6 * 8  # a simulation's q still reads


@pytest.mark.parametrize("kind", ["numeric", "text"])
def test_a_huge_attribute_is_refused_by_name(tree, kind):
    with h5py.File(_store(tree), "a") as f:
        g = f["problems/lim-2101"]
        if kind == "numeric":
            g.attrs.create("blob", np.zeros(300_000))
        else:
            g.attrs.create("title", "x" * 3_000_000, dtype=h5py.string_dtype())
    res = mechbook("--root", tree, "show", "lim-2101", cwd=tree)
    _clean(res)
    assert res.returncode == 1
    assert "of /problems/lim-2101" in res.stderr and "at most 1.0 MB" in res.stderr


def _unchanged_and_refused(tree: Path, path: Path, why: str) -> None:
    before = path.read_bytes()
    res = mechbook("--root", tree, "show", "lim-2101", "--store", path, cwd=tree)
    _clean(res)
    assert res.returncode == 1 and why in res.stderr, res.stderr
    res = mechbook("--root", tree, "check", "lim-2101", "-j", "1", "--no-crosscheck",
                   "--store", path, cwd=tree)
    _clean(res)
    assert res.returncode == 1
    assert f"cannot write the store {path}: " in res.stderr and why in res.stderr
    assert re.search(r"kept in \S+\.jsonl", res.stderr)
    assert path.read_bytes() == before, "a file that is not a mechbook store was changed"
    assert not list(path.parent.glob(f"{path.name}.damaged-*")), "moved aside"


def test_hdf5_that_is_not_a_mechbook_store_is_refused_and_left_alone(tree):
    path = tree / "their-data.h5"
    with h5py.File(path, "w") as f:
        f.create_dataset("measurements", data=np.arange(100.0))
        f.attrs["instrument"] = "a spectrometer"
    _unchanged_and_refused(tree, path, "not a mechbook store")


def test_a_store_of_a_newer_format_is_refused_and_left_alone(tree):
    path = _store(tree)
    with h5py.File(path, "a") as f:
        f.attrs["format"] = 2
    _unchanged_and_refused(tree, path, "store format 2, newer than this mechbook's (1)")


@pytest.mark.parametrize("how", ["soft-loop", "external"])
def test_links_inside_a_store_are_not_followed(tree, tmp_path, how):
    outside = tmp_path / "outside.h5"
    with h5py.File(outside, "w") as f:
        f.attrs["format"] = 1
        f.create_dataset("secret", data=MARKER, dtype=h5py.string_dtype())
    with h5py.File(_store(tree), "a") as f:
        g = f["problems/lim-2101/systems/main/symbolic"]
        g["loop"] = h5py.SoftLink("/problems") if how == "soft-loop" else \
            h5py.ExternalLink(str(outside), "/")
    res = mechbook("--root", tree, "show", "lim-2101", cwd=tree, timeout=60)
    _clean(res)
    assert MARKER not in res.stdout + res.stderr
    assert res.returncode == 1 and ("soft link" in res.stderr or "external link"
                                    in res.stderr), res.stderr
    res = mechbook("--root", tree, "check", "lim-2102", "-j", "1", "--no-crosscheck",
                   "--fresh", cwd=tree, timeout=120)
    _clean(res)
    assert res.returncode == 0 and "was damaged" in res.stderr
    assert MARKER not in res.stdout + res.stderr
    with h5py.File(_store(tree)) as f:
        f.visit(lambda name: None)  # the rebuilt store holds no link any more
        assert "lim-2101" not in f["problems"]


@pytest.mark.parametrize("damage, why", [
    (lambda f: f["problems/lim-2101/crosschecks/0"].attrs.__setitem__(
        "parts", "[" * 50_000 + "]" * 50_000), "nested more than 32 levels"),
    (lambda f: f["problems/lim-2101/crosschecks/0"].attrs.__setitem__("parts", "[1, {"),
     "parts"),
    (lambda f: f["problems/lim-2101/checks/a"].attrs.__setitem__("status", "great"),
     "the status 'great' is not an outcome"),
    (lambda f: f["problems/lim-2101"].attrs.__delitem__("title"),
     "lacks its attribute 'title'"),
    (lambda f: f["problems/lim-2101/crosschecks/0"].attrs.__setitem__("error", "big"),
     "the attribute 'error' is 'big'"),
])
def test_a_record_show_calls_damaged_is_moved_aside_by_the_next_check(tree, damage, why):
    """On 0834a76 `show` said "the next check moves it aside" while a check that wrote the
    store kept the record with no word (its check of the file read strings, never JSON or
    outcomes); `show` of a record without its attributes printed 'stored None'."""
    with h5py.File(_store(tree), "a") as f:
        damage(f)
    res = mechbook("--root", tree, "show", "lim-2101", cwd=tree)
    _clean(res)
    assert res.returncode == 1 and why in res.stderr
    assert "the next `mechbook check` into this store moves it aside" in res.stderr
    res = mechbook("--root", tree, "check", "lim-2102", "-j", "1", "--no-crosscheck",
                   "--fresh", cwd=tree)
    _clean(res)
    assert res.returncode == 0
    assert "was damaged" in res.stderr and why in res.stderr, res.stderr
    assert "lost here, kept in the damaged file): /problems/lim-2101" in res.stderr
    assert store.problems(_store(tree)) == ["lim-2102"]


def test_a_problem_with_only_simulations_stored_says_so(tmp_path):
    path = tmp_path / "s.h5"
    store.write_simulation("lim-2031", "main-RK4", {"t": np.linspace(0, 1, 5)}, {}, None, path)
    res = mechbook("--root", tmp_path, "show", "lim-2031", "--store", path, cwd=tmp_path)
    _clean(res)
    assert res.returncode == 0, res.stderr
    assert "no check is stored, only simulations" in res.stdout
    assert "simulation stored: /problems/lim-2031/simulations/main-RK4" in res.stdout
    assert store.damage(path) is None


def test_a_damaged_simulation_costs_only_itself(tree):
    """The rebuild keeps a record whose simulation is damaged, and the record's other
    simulations: each is kept or lost apart."""
    path = _store(tree)
    for name in ("main-RK4", "main-DOP853"):
        store.write_simulation("lim-2101", name, {"t": np.linspace(0, 1, 5)}, {}, None, path)
    with h5py.File(path, "a") as f:
        d = f.create_dataset("problems/lim-2101/simulations/main-RK4/bomb", shape=(10**9,),
                             dtype="f8", chunks=(1 << 16,), compression="gzip")
        d[:10] = 1.0
    res = mechbook("--root", tree, "check", "lim-2102", "-j", "1", "--no-crosscheck",
                   "--fresh", cwd=tree)
    _clean(res)
    assert res.returncode == 0
    assert "lost here, kept in the damaged file): /problems/lim-2101/simulations/main-RK4" \
        in res.stderr, res.stderr
    rec = store.read("lim-2101", path)
    assert rec["checked"] and rec["simulations"] == ["main-DOP853"]


def _twelve_under_the_bound(path: Path) -> None:
    """Twelve datasets under one record, each of 33 * 10^6 float64 (264 MB, just under the
    per-dataset bound), chunked with a fill value and never written: the file stays small,
    reading them all takes 3.2 GB (issue 44)."""
    with h5py.File(path, "a") as f:
        for i in range(12):
            f.create_dataset(f"problems/lim-2101/systems/main/numeric/big{i:02d}",
                             shape=(33_000_000,), dtype="f8", chunks=(1 << 20,),
                             fillvalue=1.0)


@pytest.mark.parametrize("command", ["show", "report"])
def test_a_record_is_bounded_in_total_not_only_per_dataset(tree, command):
    path = _store(tree)
    _twelve_under_the_bound(path)
    assert path.stat().st_size < 1_000_000
    args = ["show", "lim-2101"] if command == "show" else ["report", "lim-2101"]
    res = mechbook("--root", tree, *args, cwd=tree)
    _clean(res)
    text = res.stdout + res.stderr
    assert "holds more than 536.9 MB of data in its datasets together" in text, text
    if command == "show":
        assert res.returncode == 1
    assert mechbook("--root", tree, "show", "lim-2102", cwd=tree).returncode == 0
