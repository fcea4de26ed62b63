"""Issue 33, `mechbook restore`: a side file is read back as a file anyone could have
replaced or planted. It may not make mechbook write outside the tree (absolute, relative
and linked store paths), move aside a file that is not a store, store a problem under an
id the id grammar refuses, or hang, fill memory or end in a traceback (a FIFO, /dev/zero,
JSON nested a hundred thousand deep). Real `mechbook restore` processes, their address
space bounded; real FIFOs and links."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import h5py
import pytest
from hostile import check, mechbook, pendulum_tree

import mechbook.app.store as store
import mechbook.app.store.writer as store_writer
from mechbook.app.store.unsaved import FORMAT


def _line(pid: str = "lim-2101", store_path: str = "results/mechbook.h5", **extra) -> str:
    record = {"problem_id": pid, "title": "a kept pendulum", "source": "a test",
              "problem_sha256": "0" * 64, "results": [], "outcomes": [
                  {"problem": pid, "part": "a", "quantity": "eom", "cite": "test",
                   "status": "pass"}], "duration": 0.5, "answers_sha256": "",
              "crosschecks": []}
    return json.dumps({"format": FORMAT, "kind": "problem", "store": store_path,
                       "record": record, **extra}) + "\n"


def _side(base: Path, *lines: str) -> Path:
    path = base / "results" / "kept.jsonl"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(lines), encoding="utf-8")
    return path


def _clean_refusal(res, *needles: str) -> None:
    assert res.returncode == 1, (res.stdout, res.stderr)
    assert "Traceback" not in res.stderr and "Error: " in res.stderr, res.stderr
    for needle in needles:
        assert needle in res.stderr, res.stderr


@pytest.fixture
def tree(tmp_path) -> Path:
    return pendulum_tree(tmp_path / "tree")


def test_a_side_file_cannot_make_restore_write_outside_the_tree(tree, tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    (tree / "results").mkdir()
    (tree / "results" / "linked.h5").symlink_to(outside / "through-a-link.h5")
    for named in (str(outside / "absolute.h5"), "../outside/relative.h5",
                  "results/linked.h5"):
        side = _side(tree, _line(store_path=named))
        res = mechbook("--root", tree, "restore", side, cwd=tree)
        _clean_refusal(res, f"{side}:1:", "outside the tree", f"--store {named}")
    assert sorted(os.listdir(outside)) == [], "written outside the tree"
    # told so with --store, it writes there: the user's choice, not the file's
    res = mechbook("--root", tree, "restore", side, "--store", outside / "chosen.h5", cwd=tree)
    assert res.returncode == 0, res.stderr
    assert [c["status"] for c in store.read("lim-2101", outside / "chosen.h5")["checks"]] \
        == ["pass"]


def test_a_side_file_cannot_replace_a_file_that_is_not_a_store(tree):
    """The store's damage handling moves aside whatever is at the path and writes HDF5 in
    its place: a side file naming books.yaml must not get that far."""
    books = (tree / "books.yaml").read_bytes()
    side = _side(tree, _line(store_path="books.yaml"))
    res = mechbook("--root", tree, "restore", side, cwd=tree)
    _clean_refusal(res, "not an HDF5 store")
    assert (tree / "books.yaml").read_bytes() == books
    assert not list(tree.glob("books.yaml.damaged-*"))


@pytest.mark.parametrize("pid", ["../../x", "a/b", "lim-2031\x00x", "lim-2031/../../y",
                                 "", 7, None])
def test_problem_ids_from_a_side_file_follow_the_id_grammar(tree, pid):
    side = _side(tree, _line(), _line(pid=pid))
    res = mechbook("--root", tree, "restore", side, cwd=tree)
    _clean_refusal(res, f"{side}:2:", "bad problem id")
    assert not (tree / "results" / "mechbook.h5").exists(), "a line was written before " \
        "the bad one was found"


@pytest.mark.parametrize("field, value, needle", [
    ("outcomes", [{"part": "../a", "quantity": "eom", "status": "pass"}], "not a plain name"),
    ("outcomes", [{"part": "a", "quantity": "eom", "status": "great"}], "not an outcome"),
    ("results", [{"system": "../main", "text": {}, "arrays": {}, "notes": {}}],
     "not a plain name"),
    ("results", [{"system": "main", "text": {"a/../../b": "x"}, "arrays": {}, "notes": {}}],
     "not a plain name"),
    ("results", [{"system": "main", "text": {}, "arrays": {"M": [[1, 2], [3]]}, "notes": {}}],
     "not an array of numbers"),
    ("title", 12, "not text"),
    ("surprise", 1, "unknown field"),
])
def test_every_field_is_checked_before_anything_is_written(tree, field, value, needle):
    line = json.loads(_line())
    line["record"][field] = value
    side = _side(tree, json.dumps(line) + "\n")
    _clean_refusal(mechbook("--root", tree, "restore", side, cwd=tree), needle)
    assert not (tree / "results" / "mechbook.h5").exists()


def test_a_simulation_from_a_side_file_is_checked_too(tree):
    line = {"format": FORMAT, "kind": "simulation", "store": "results/mechbook.h5",
            "problem_id": "lim-2101", "name": "../../main-RK4", "arrays": {"t": [0, 1]},
            "attrs": {}, "array_attrs": {}}
    side = _side(tree, json.dumps(line) + "\n")
    _clean_refusal(mechbook("--root", tree, "restore", side, cwd=tree), "simulation name")
    line["name"] = "main-RK4"
    side = _side(tree, json.dumps(line) + "\n")
    res = mechbook("--root", tree, "restore", side, cwd=tree)
    assert res.returncode == 0, res.stderr
    with h5py.File(tree / "results" / "mechbook.h5") as f:
        assert list(f["problems/lim-2101/simulations"]) == ["main-RK4"]


@pytest.mark.parametrize("kind", ["fifo", "devzero", "directory"])
def test_a_side_file_that_is_not_a_regular_file_is_refused_at_once(tree, kind):
    """On 0834a76 a FIFO blocked `restore` for ever and /dev/zero was read until memory
    ran out (here: the 2 GB the test allows, a MemoryError traceback)."""
    side = tree / "results" / "kept.jsonl"
    side.parent.mkdir()
    if kind == "fifo":
        os.mkfifo(side)
    elif kind == "devzero":
        side.symlink_to("/dev/zero")
    else:
        side.mkdir()
    res = mechbook("--root", tree, "restore", side, cwd=tree, timeout=60)
    _clean_refusal(res, f"cannot read {side}", "not a regular file")


def test_json_nested_deeply_is_refused_with_its_line(tree):
    side = _side(tree, _line(), "[" * 100_000 + "]" * 100_000 + "\n")
    res = mechbook("--root", tree, "restore", side, cwd=tree)
    _clean_refusal(res, f"{side}:2:", "nested")
    assert "RecursionError" not in res.stderr


def test_an_unknown_side_file_format_is_refused(tree):
    side = _side(tree, _line().replace(f'"format": {FORMAT}', '"format": 99'))
    _clean_refusal(mechbook("--root", tree, "restore", side, cwd=tree), "format 99")


def test_what_check_kept_is_restored_into_the_tree_store(tree, monkeypatch):
    """The round trip: a store write that fails (an I/O error injected into HDF5's
    writing), the side file the run names beside the store, then a real `restore` once the
    fault is gone, into the tree's store by the path the side file holds."""
    import errno

    monkeypatch.setattr(store_writer, "_write_problem",
                        lambda *a: (_ for _ in ()).throw(OSError(errno.EIO, "I/O error")))
    res = check(tree)
    monkeypatch.undo()
    assert res.exit_code == 1, res.output
    side = Path(re.search(r"kept in (\S+\.jsonl)", res.stderr).group(1))
    assert f"--store {tree / 'results' / 'mechbook.h5'}" in res.stderr
    assert side.parent == tree / "results"
    res = mechbook("--root", tree, "restore", side, cwd=tree)
    assert res.returncode == 0, res.stderr
    assert "1 problem(s)" in res.stdout
    assert [c["status"] for c in store.read("lim-2101", tree / "results" / "mechbook.h5")
            ["checks"]] == ["pass"]


def test_many_lines_are_written_in_few_edits(tree, monkeypatch):
    """A side file of 250 kept problems is written in three edits of the store (batches
    of 100), not 250: each edit copies the whole store."""
    from mechbook.app.store import restore as restore_module

    edits = []
    real = restore_module.write
    monkeypatch.setattr(restore_module, "write",
                        lambda records, path: edits.append(len(records)) or real(records, path))
    side = _side(tree, *[_line(pid=f"lim-{3000 + i}") for i in range(250)])
    assert restore_module.restore(side, base=tree) == (250, 0)
    assert edits == [100, 100, 50]
    assert len(store.problems(tree / "results" / "mechbook.h5")) == 250
