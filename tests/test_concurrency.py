"""Concurrent runs on one store (issue 15): two `mechbook check` processes on different
problems, started together, again and again, lose none of each other's results; readers
never see a torn file while writers replace it."""

from __future__ import annotations

import multiprocessing as mp
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from mechbook.app import store
from mechbook.app.cli import main
from mechbook.app.store import writer as store_writer
from mechbook.records import Outcome

pytestmark = pytest.mark.slow  # concurrent check processes and writers

ROOT = Path(__file__).resolve().parents[1]
# quick problems (about a second each), paired so both runs write at about the same time
PAIRS = [("lim-2031", "lim-2035"), ("lim-2037", "lim-2038"), ("lim-2045", "lim-2056"),
         ("lim-2031", "lim-2038")]


def _copy(tmp_path: Path, pid: str) -> None:
    book, num = pid.split("-", 1)
    for kind in ("problems", "answers"):
        dest = tmp_path / kind / book / f"{num}.yaml"
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / kind / book / f"{num}.yaml", dest)


class Reader(threading.Thread):
    """Reads every stored problem in a loop until stopped; keeps any error but 'no store
    yet'."""

    def __init__(self, path: Path):
        super().__init__(daemon=True)
        self.path, self.reads, self.errors = path, 0, []
        self.stop = threading.Event()

    def run(self) -> None:
        while not self.stop.is_set():
            if not self.path.exists():
                continue
            try:
                for pid in store.problems(self.path):
                    rec = store.read(pid, self.path)
                    assert rec["checks"], f"{pid} stored without checks"
                self.reads += 1
            except FileNotFoundError:
                continue
            except Exception as exc:  # noqa: BLE001 - what the test looks for
                self.errors.append(f"{type(exc).__name__}: {exc}")


def test_two_check_processes_into_one_store_lose_nothing(tmp_path):
    """Each process checks in itself (`--serial`): the store is written by a run's parent
    either way, and a fork server and a worker per run only added two start-ups each."""
    for pid in {p for pair in PAIRS for p in pair}:
        _copy(tmp_path, pid)
    h5 = tmp_path / "results" / "m.h5"
    reader = Reader(h5)
    reader.start()
    expected: set[str] = set()
    try:
        for a, b in PAIRS:
            procs = [subprocess.Popen([sys.executable, "-m", "mechbook", "--root",
                                       str(tmp_path), "check", pid, "--store", str(h5),
                                       "--fresh", "--serial", "--no-crosscheck"],
                                      stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                      text=True) for pid in (a, b)]
            for proc in procs:
                out, _ = proc.communicate(timeout=300)
                assert proc.returncode == 0, out
            expected |= {a, b}
            assert expected <= set(store.problems(h5))
    finally:
        reader.stop.set()
        reader.join(timeout=30)
    assert not reader.errors, reader.errors[:3]
    assert reader.reads > 0
    for pid in sorted(expected):
        res = CliRunner().invoke(main, ["--root", str(tmp_path), "show", pid, "--store",
                                        str(h5)])
        assert res.exit_code == 0, res.output
        assert "== checks" in res.output


def _writer(path: str, who: int, rounds: int) -> None:
    for i in range(rounds):
        rec = store.ProblemRecord(f"w{who}-{i}", "t", "s", "0" * 64,
                                  outcomes=[Outcome(f"w{who}-{i}", "a", "q", "c", "pass")])
        store.write([rec], path)


def test_many_writers_at_once_keep_every_record(tmp_path):
    """The store's lock itself, at a rate no pair of checks reaches: 4 processes writing 15
    records each, as fast as they can."""
    h5 = tmp_path / "m.h5"
    ctx = mp.get_context("fork")
    procs = [ctx.Process(target=_writer, args=(str(h5), w, 15)) for w in range(4)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(timeout=300)
        assert p.exitcode == 0
    names = set(store.problems(h5))
    assert names == {f"w{w}-{i}" for w in range(4) for i in range(15)}
    with h5py.File(h5) as f:  # one whole file, no temporary left beside it
        assert len(f["problems"]) == 60
    assert not list(tmp_path.glob("*.tmp"))


def test_without_the_lock_writers_lose_records(tmp_path, monkeypatch):
    """The test above can fail: with the lock taken away, concurrent writers drop records."""
    from contextlib import contextmanager

    @contextmanager
    def no_lock(directory):
        yield

    monkeypatch.setattr(store_writer, "_locked", no_lock)
    h5 = tmp_path / "m.h5"
    ctx = mp.get_context("fork")
    procs = [ctx.Process(target=_writer, args=(str(h5), w, 15)) for w in range(4)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(timeout=300)
    assert len(store.problems(h5)) < 60
