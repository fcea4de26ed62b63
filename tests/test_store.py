"""The HDF5 store: round trip, several problems, atomic replacement, and `mechbook show`."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
import sympy as sp
from click.testing import CliRunner

import mechbook.app.store as store
import mechbook.app.store.writer as store_writer
from mechbook.app.cli import main
from mechbook.model.problem import load_problem
from mechbook.records import Outcome, Results

ROOT = Path(__file__).resolve().parents[1]

PROBLEM = """\
id: lim-{num}
source: a test source {num}
title: a test title {num}
parameters:
  m: {{value: 1.5}}
  k: {{value: 2.0}}
coordinates:
  x: {{}}
kinetic: m*xdot**2/2
potential: k*x**2/2
"""


def make_problem(tmp_path: Path, num: str):
    d = tmp_path / "problems"
    d.mkdir(exist_ok=True)
    path = d / f"{num}.yaml"
    path.write_text(PROBLEM.format(num=num), encoding="utf-8")
    return load_problem(path)


def make_record(tmp_path: Path, num: str = "2031", tag: str = "first") -> store.ProblemRecord:
    problem = make_problem(tmp_path, num)
    res = Results("main")
    res.text["lagrangian"] = f"m*xdot**2/2 - k*x**2/2  # {tag}"
    res.text["equilibrium_0/frequencies"] = "[sqrt(k)/sqrt(m)]"
    res.text["unicode"] = "ω² = k/m"
    res.arrays["equilibrium_0/frequencies"] = np.array([np.sqrt(2.0 / 1.5)])
    res.arrays["equilibrium_0/M"] = np.array([[1.5]])
    res.notes["hamiltonian"] = "unsupported: a test note"
    outcomes = [
        Outcome(problem.id, "b", "frequencies", "cite b", "pass", "symbolic", "", 0.25),
        Outcome(problem.id, "a", "lagrangian", "cite a", "fail", "numeric(1 points)",
                f"a detail {tag}", 0.5),
        Outcome(problem.id, "c", "proof", "cite c", "unsupported", "", "a proof in words", 0.0),
    ]
    return store.ProblemRecord.of(problem, [res], outcomes, 1.25)


def test_round_trip(tmp_path):
    rec = make_record(tmp_path)
    path = tmp_path / "out" / "store.h5"
    assert store.write([rec], path) == path
    got = store.read("lim-2031", path)
    a = got["attrs"]
    assert a["title"] == "a test title 2031"
    assert a["source"] == "a test source 2031"
    assert a["problem_sha256"] == rec.problem_sha256
    assert a["sympy"] == sp.__version__
    assert a["duration_s"] == pytest.approx(1.25)
    assert "date" in a and "mechbook" in a
    sym = got["systems"]["main"]["symbolic"]
    assert sym["lagrangian"] == "m*xdot**2/2 - k*x**2/2  # first"
    assert sym["equilibrium_0/frequencies"] == "[sqrt(k)/sqrt(m)]"
    assert sym["unicode"] == "ω² = k/m"
    num = got["systems"]["main"]["numeric"]
    np.testing.assert_allclose(num["equilibrium_0/frequencies"], [np.sqrt(2.0 / 1.5)])
    np.testing.assert_allclose(num["equilibrium_0/M"], [[1.5]])
    assert got["systems"]["main"]["notes"] == {"hamiltonian": "unsupported: a test note"}
    # checks come back in the order they were run, with every field
    assert [c["part"] for c in got["checks"]] == ["b", "a", "c"]
    a_check = got["checks"][1]
    assert a_check["status"] == "fail"
    assert a_check["quantity"] == "lagrangian"
    assert a_check["cite"] == "cite a"
    assert a_check["method"] == "numeric(1 points)"
    assert a_check["detail"] == "a detail first"
    assert a_check["seconds"] == pytest.approx(0.5)
    assert store.problems(path) == ["lim-2031"]


def test_read_missing(tmp_path):
    with pytest.raises(FileNotFoundError):
        store.read("lim-2031", tmp_path / "nothing.h5")
    path = store.write([make_record(tmp_path)], tmp_path / "s.h5")
    with pytest.raises(KeyError, match="lim-2032"):
        store.read("lim-2032", path)


def test_second_problem_keeps_the_first(tmp_path):
    path = tmp_path / "store.h5"
    store.write([make_record(tmp_path, "2031")], path)
    store.write([make_record(tmp_path, "2032")], path)
    assert store.problems(path) == ["lim-2031", "lim-2032"]
    first = store.read("lim-2031", path)
    assert first["attrs"]["title"] == "a test title 2031"
    assert first["systems"]["main"]["symbolic"]["lagrangian"].endswith("# first")
    assert store.read("lim-2032", path)["attrs"]["title"] == "a test title 2032"


def test_rewriting_a_problem_replaces_it_whole(tmp_path):
    path = tmp_path / "store.h5"
    store.write([make_record(tmp_path, "2031")], path)
    rec = make_record(tmp_path, "2031", tag="second")
    rec.results[0].text.pop("unicode")
    rec.outcomes = rec.outcomes[:1]
    store.write([rec], path)
    got = store.read("lim-2031", path)
    assert got["systems"]["main"]["symbolic"]["lagrangian"].endswith("# second")
    assert "unicode" not in got["systems"]["main"]["symbolic"]
    assert [c["part"] for c in got["checks"]] == ["b"]


def _leftovers(directory: Path, keep: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir() if p != keep)


@pytest.mark.parametrize("exc", [RuntimeError("disk on fire"), KeyboardInterrupt()])
def test_interrupted_write_keeps_previous_file(tmp_path, monkeypatch, exc):
    d = tmp_path / "results"
    path = d / "store.h5"
    store.write([make_record(tmp_path, "2031")], path)
    before = path.read_bytes()
    real = store_writer._write_problem
    calls = []

    def half_then_fail(root, rec):
        calls.append(rec.problem_id)
        real(root, rec)  # the new problem is (partly) written into the copy ...
        root[rec.problem_id].attrs["title"] = "half written"
        raise exc  # ... and then the run dies

    monkeypatch.setattr(store_writer, "_write_problem", half_then_fail)
    # a failure of the write is a StoreError (path and reason); an interrupt stays one
    with pytest.raises(store.StoreError if isinstance(exc, Exception) else type(exc)):
        store.write([make_record(tmp_path, "2032"), make_record(tmp_path, "2031", "x")], path)
    assert calls == ["lim-2032"]
    assert path.read_bytes() == before
    assert store.problems(path) == ["lim-2031"]
    got = store.read("lim-2031", path)
    assert got["attrs"]["title"] == "a test title 2031"
    assert got["systems"]["main"]["symbolic"]["lagrangian"].endswith("# first")
    assert _leftovers(d, path) == []


def test_failure_at_rename_leaves_no_temp_file(tmp_path, monkeypatch):
    d = tmp_path / "results"
    path = d / "store.h5"
    store.write([make_record(tmp_path, "2031")], path)
    before = path.read_bytes()

    def broken_replace(src, dst):
        raise OSError("rename failed")

    monkeypatch.setattr(store_writer.os, "replace", broken_replace)
    with pytest.raises(store.StoreError, match=f"cannot write the store {path}: rename failed"):
        store.write([make_record(tmp_path, "2032")], path)
    assert path.read_bytes() == before
    assert _leftovers(d, path) == []


def test_interrupted_first_write_creates_nothing(tmp_path, monkeypatch):
    d = tmp_path / "results"
    path = d / "store.h5"

    def fail(root, rec):
        raise RuntimeError("boom")

    monkeypatch.setattr(store_writer, "_write_problem", fail)
    with pytest.raises(store.StoreError, match="boom"):
        store.write([make_record(tmp_path, "2031")], path)
    assert not path.exists()
    assert list(d.iterdir()) == []


def test_store_is_valid_hdf5_with_layout(tmp_path):
    path = store.write([make_record(tmp_path)], tmp_path / "s.h5")
    with h5py.File(path, "r") as f:
        assert f.attrs["format"] == store.FORMAT
        g = f["problems/lim-2031"]
        assert "systems/main/symbolic/lagrangian" in g
        assert "systems/main/numeric/equilibrium_0/M" in g
        assert g["checks/a"].attrs["status"] == "fail"


# ---- mechbook show --------------------------------------------------------------------------
def test_cli_show_prints_stored_results(tmp_path):
    path = store.write([make_record(tmp_path)], tmp_path / "s.h5")
    result = CliRunner().invoke(main, ["--root", str(ROOT), "show", "lim-2031",
                                       "--store", str(path)])
    assert result.exit_code == 0, result.output
    out = result.output
    assert "lim-2031: a test title 2031  [a test source 2031]" in out
    assert "lagrangian: m*xdot**2/2 - k*x**2/2  # first" in out
    assert "ω² = k/m" in out
    assert "equilibrium_0/frequencies (numeric): [1.1547005383792" in out
    assert "hamiltonian: unsupported: a test note" in out
    assert "== checks" in out
    lines = out.splitlines()
    checks = lines[lines.index("== checks") + 1:]
    assert [ln.split()[0] for ln in checks] == ["b", "a", "c"]
    assert "fail" in checks[1] and "a detail first" in checks[1]
    assert rec_sha(tmp_path)[:12] in out


def rec_sha(tmp_path: Path) -> str:
    return load_problem(tmp_path / "problems" / "2031.yaml").sha256


def test_cli_show_missing(tmp_path):
    runner = CliRunner()
    result = runner.invoke(main, ["--root", str(ROOT), "show", "lim-2031",
                                  "--store", str(tmp_path / "none.h5")])
    assert result.exit_code != 0
    assert "no store" in result.output
    path = store.write([make_record(tmp_path)], tmp_path / "s.h5")
    result = runner.invoke(main, ["--root", str(ROOT), "show", "lim-2032", "--store", str(path)])
    assert result.exit_code != 0
    assert "lim-2032 is not in" in result.output


def test_store_file_mode_follows_umask_and_is_kept(tmp_path):
    import os
    import stat

    old = os.umask(0o022)
    try:
        path = store.write([make_record(tmp_path)], tmp_path / "s.h5")
        assert stat.S_IMODE(path.stat().st_mode) == 0o644
        path.chmod(0o640)
        store.write([make_record(tmp_path, "2032")], path)
        assert stat.S_IMODE(path.stat().st_mode) == 0o640
    finally:
        os.umask(old)
