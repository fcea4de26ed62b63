"""Issue 21, the store under attack: a failed write is an error with the path and the reason,
the exit status is non-zero and the results are kept in a side file the message names (never
"results written"); a damaged store is moved aside and rebuilt from what still reads, and
`show` says what is damaged; the store and outputs are written only to regular files; a
write killed with -9 leaves no temporary file."""

from __future__ import annotations

import errno
import json
import os
import re
import signal
import subprocess
import sys
import textwrap
from contextlib import contextmanager
from pathlib import Path

import h5py
import pytest
from hostile import ROOT, can_mount, check, pendulum_tree, run, tmpfs

import mechbook.app.outputs as outputs
import mechbook.app.store as store
import mechbook.app.store.repair as store_repair
import mechbook.app.store.unsaved as unsaved
import mechbook.app.store.writer as store_writer
from mechbook.app.selection import lastfailed_path
from mechbook.app.store.restore import restore


def _side_file(text: str) -> Path:
    found = re.search(r"kept in (\S+\.jsonl)", text)
    assert found, text
    return Path(found.group(1))


def _assert_kept(result, base: Path, store_path: Path, pids: list[str],
                 monkeypatch=None) -> Path:
    """The run failed loudly and lost nothing: exit 1, the store's path and the reason, the
    side file named, never 'results written'; the side file restores every problem (once
    the injected fault is gone)."""
    if monkeypatch is not None:
        monkeypatch.undo()
    assert result.exit_code == 1, result.output
    assert f"cannot write the store {store_path}" in result.stderr
    assert "results written" not in result.output
    side = _side_file(result.stderr)
    kept = [json.loads(line)["record"]["problem_id"] for line in side.read_text().splitlines()]
    assert sorted(kept) == sorted(pids)
    again = base / "restored.h5"
    assert restore(side, again) == (len(pids), 0)
    for pid in pids:
        assert [c["status"] for c in store.read(pid, again)["checks"]] == ["pass"]
    return side


@pytest.fixture
def side_dir(tmp_path, monkeypatch):
    """Side files that cannot go beside the store go here: the places after the store's
    own directory (the temporary directory, home) replaced by one of the test's."""
    d = tmp_path / "tmpdir"
    d.mkdir()
    monkeypatch.setattr(unsaved, "_places", lambda store: [store.parent, d])
    return d


# ---- a store that cannot be written ----------------------------------------------------------
def test_a_read_only_store_exits_nonzero_and_names_where_the_results_went(tmp_path, side_dir):
    """A real read-only file system (a tmpfs remounted read-only), through the batch's
    worker processes (the issue's bug: the batch swallowed the OSError of the write)."""
    if not can_mount():
        pytest.skip("mounting a tmpfs needs root")
    base = pendulum_tree(tmp_path / "tree", nums=("2101", "2102"))
    try:
        with tmpfs(tmp_path / "ro", readonly=True) as ro:
            path = ro / "mechbook.h5"
            result = run("--root", base, "check", "-j", "1", "--no-crosscheck",
                         "--store", path)
            assert "Read-only file system" in result.stderr
            side = _assert_kept(result, base, path, ["lim-2101", "lim-2102"])
            assert side.parent == side_dir  # not beside the store: that is read-only
            assert not path.exists()
    except subprocess.CalledProcessError:
        pytest.skip("mount not permitted here")


def test_a_full_disk_exits_nonzero_and_keeps_the_problem(tmp_path, side_dir):
    """A real full file system: a 64 KiB tmpfs with 56 KiB taken (the store needs more)."""
    if not can_mount():
        pytest.skip("mounting a tmpfs needs root")
    base = pendulum_tree(tmp_path / "tree")
    try:
        with tmpfs(tmp_path / "full", size="64k") as full:
            (full / "filler").write_bytes(b"\0" * 56 * 1024)
            path = full / "mechbook.h5"
            result = check(base, "--store", path)
            assert "No space left on device" in result.stderr
            _assert_kept(result, base, path, ["lim-2101"])
            assert not path.exists()
            assert sorted(p.name for p in full.iterdir() if p.suffix != ".jsonl") == ["filler"]
    except subprocess.CalledProcessError:
        pytest.skip("mount not permitted here")


def _fail_store_writes(monkeypatch, fault: int) -> None:
    """Fault injection: every write of the store fails with `fault` once its new version is
    written, just before it would be renamed into place (the side file is not touched)."""
    real = store_writer.replaced

    @contextmanager
    def failing(path, copy=False):
        with real(path, copy) as fh:
            yield fh
            raise OSError(fault, os.strerror(fault))

    monkeypatch.setattr(store_writer, "replaced", failing)
    monkeypatch.setattr(store_repair, "replaced", failing)


@pytest.mark.parametrize("fault", [errno.EROFS, errno.ENOSPC, errno.EIO])
def test_a_failing_file_system_by_fault_injection(tmp_path, monkeypatch, fault):
    """The same without mounting (fault injection: the sync of the new store fails with
    the errno), and a store written before keeps what it held."""
    base = pendulum_tree(tmp_path / "tree", nums=("2101", "2102"))
    path = tmp_path / "out" / "mechbook.h5"
    assert check(base, "lim-2101", "--store", path).exit_code == 0
    before = path.read_bytes()
    record = lastfailed_path(path)  # --lf's record of the first run: no failures
    recorded = record.read_bytes()
    _fail_store_writes(monkeypatch, fault)
    result = check(base, "--fresh", "--store", path)
    assert os.strerror(fault) in result.stderr
    side = _assert_kept(result, base, path, ["lim-2101", "lim-2102"], monkeypatch)
    assert side.parent == path.parent
    assert path.read_bytes() == before
    assert record.read_bytes() == recorded  # a run whose store failed records nothing
    assert sorted(p.name for p in path.parent.iterdir()) == sorted([path.name, side.name,
                                                                     record.name])


def test_json_output_says_the_store_failed(tmp_path, monkeypatch):
    base = pendulum_tree(tmp_path / "tree")
    path = tmp_path / "mechbook.h5"
    _fail_store_writes(monkeypatch, errno.ENOSPC)
    result = check(base, "--store", path, "--format", "json")
    assert result.exit_code == 1
    doc = json.loads(result.stdout)
    assert doc["store"] is None
    assert "No space left on device" in doc["store_error"]
    assert doc["summary"]["ok"] is False


@pytest.mark.parametrize("kind", ["directory", "fifo", "dangling link"])
def test_the_store_is_written_only_to_a_regular_file(tmp_path, kind):
    """A directory, a FIFO or a dangling link at the store's path is refused before any
    problem is checked, and left as it was."""
    base = pendulum_tree(tmp_path / "tree")
    path = tmp_path / "mechbook.h5"
    if kind == "directory":
        path.mkdir()
    elif kind == "fifo":
        os.mkfifo(path)
    else:
        path.symlink_to(tmp_path / "nowhere" / "x.h5")
    result = check(base, "--store", path)
    assert result.exit_code in (1, 4)  # 4: a usage error, refused by the option's own check
    # (a directory)
    assert f"cannot write the store {path}" in result.output or kind == "directory"
    assert {"directory": "is a directory", "fifo": "is a FIFO",
            "dangling link": "symbolic link to nothing"}[kind] in result.output
    assert "lim-2101" not in result.output  # refused before the run
    assert path.is_dir() if kind == "directory" else True
    assert path.is_fifo() if kind == "fifo" else True
    assert path.is_symlink() if kind == "dangling link" else True


def test_a_linked_store_is_written_through_the_link(tmp_path):
    """A symbolic link to a regular file: the file is replaced, the link stays a link."""
    base = pendulum_tree(tmp_path / "tree", nums=("2101", "2102"))
    real = tmp_path / "real.h5"
    assert check(base, "lim-2101", "--store", real).exit_code == 0
    link = tmp_path / "link.h5"
    link.symlink_to(real)
    assert check(base, "lim-2102", "--store", link).exit_code == 0
    assert link.is_symlink() and real.is_file() and not real.is_symlink()
    assert store.problems(real) == ["lim-2101", "lim-2102"]


@pytest.mark.parametrize("option", ["--junit-xml"])
def test_outputs_refuse_special_files(tmp_path, option):
    base = pendulum_tree(tmp_path / "tree")
    fifo = tmp_path / "out.xml"
    os.mkfifo(fifo)
    result = check(base, "--no-store", option, fifo)
    assert result.exit_code == 1
    assert f"{fifo}: it is a FIFO, not a regular file" in result.output
    assert fifo.is_fifo()


# ---- a damaged store ---------------------------------------------------------------------------
def _two_problem_store(tmp_path: Path) -> tuple[Path, Path]:
    base = pendulum_tree(tmp_path / "tree", nums=("2101", "2102", "2103"))
    path = tmp_path / "out" / "mechbook.h5"
    assert check(base, "lim-2101", "lim-2102", "--store", path).exit_code == 0
    return base, path


def _asides(path: Path) -> list[Path]:
    return sorted(path.parent.glob(path.name + store.DAMAGED + "*"))


@pytest.mark.parametrize("damage", ["text file", "truncated", "empty"])
def test_an_unreadable_store_is_moved_aside_and_rebuilt(tmp_path, damage):
    base, path = _two_problem_store(tmp_path)
    data = path.read_bytes()
    path.write_bytes({"text file": b"hello\n", "truncated": data[: len(data) // 2],
                      "empty": b""}[damage])
    broken = path.read_bytes()
    shown = run("--root", base, "show", "lim-2101", "--store", path)
    assert shown.exit_code == 1 and isinstance(shown.exception, SystemExit)
    assert f"cannot read the store {path}" in shown.output
    assert "damaged" in shown.output and "Traceback" not in shown.output
    result = check(base, "lim-2103", "--store", path)
    assert result.exit_code == 0, result.output
    (aside,) = _asides(path)
    assert aside.read_bytes() == broken  # kept whole, for whoever wants to dig
    assert f"the store {path} was damaged" in result.stderr and str(aside) in result.stderr
    assert store.problems(path) == ["lim-2103"]
    assert "results written" in result.stdout
    assert check(base, "lim-2101", "--store", path).exit_code == 0  # and it goes on
    assert store.problems(path) == ["lim-2101", "lim-2103"]


def test_a_store_with_one_damaged_record_keeps_the_others(tmp_path):
    """One problem's object header overwritten: the rebuilt store keeps the other one, the
    warning names the one lost, and `show` of the damaged file names it instead of a
    traceback."""
    base, path = _two_problem_store(tmp_path)
    with h5py.File(path, "r") as f:
        addr = h5py.h5o.get_info(f["problems/lim-2101"].id).addr
    with open(path, "r+b") as fh:
        fh.seek(addr)
        fh.write(b"\xff" * 64)
    shown = run("--root", base, "show", "lim-2101", "--store", path)
    assert shown.exit_code == 1
    assert "the stored record of lim-2101" in shown.output and "damaged" in shown.output
    assert run("--root", base, "show", "lim-2102", "--store", path).exit_code == 0
    result = check(base, "lim-2103", "--store", path)
    assert result.exit_code == 0, result.output
    assert "/problems/lim-2101" in result.stderr  # named as lost
    assert store.problems(path) == ["lim-2102", "lim-2103"]
    assert store.read("lim-2102", path)["checks"][0]["status"] == "pass"
    assert len(_asides(path)) == 1


def test_flipped_bytes_never_end_in_a_traceback(tmp_path):
    """The issue's 64 flipped bytes (the cache lookup raised AttributeError): `check`
    finishes, `show` answers or says what is damaged, and nothing is lost."""
    import random

    base, path = _two_problem_store(tmp_path)
    rng = random.Random(64)
    data = bytearray(path.read_bytes())
    for _ in range(64):
        data[rng.randrange(len(data))] ^= 0xFF
    path.write_bytes(bytes(data))
    for pid in ("lim-2101", "lim-2102"):
        shown = run("--root", base, "show", pid, "--store", path)
        assert shown.exit_code in (0, 1)
        assert shown.exception is None or isinstance(shown.exception, SystemExit), shown.output
    result = check(base, "--store", path)
    assert result.exit_code == 0, result.output
    assert sorted(store.problems(path)) == ["lim-2101", "lim-2102", "lim-2103"]


# ---- no temporary file left by a kill ---------------------------------------------------------
KILLED_WRITER = textwrap.dedent("""\
    import sys, time
    from pathlib import Path
    import mechbook.app.store as store
    import mechbook.app.store.writer as store_writer
    sys.path.insert(0, {tests!r})
    from test_store import make_record
    path = Path({path!r})
    real = store_writer._write_problem
    def slow(root, rec):
        real(root, rec)
        print("writing", flush=True)
        time.sleep(60)
    store_writer._write_problem = slow
    store.write([make_record(Path({tmp!r}), "2032")], path)
""")


def test_a_write_killed_with_sigkill_leaves_no_temporary_file(tmp_path):
    """A real process killed with -9 in the middle of writing the store: the store is as it
    was, and nothing else is in its directory (the new version was an anonymous file)."""
    from test_store import make_record

    d = tmp_path / "results"
    path = d / "store.h5"
    store.write([make_record(tmp_path, "2031")], path)
    before = path.read_bytes()
    script = KILLED_WRITER.format(tests=str(ROOT / "tests"), path=str(path),
                                  tmp=str(tmp_path))
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "writing"
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=10)
    assert sorted(p.name for p in d.iterdir()) == ["store.h5"]
    assert path.read_bytes() == before
    assert store.problems(path) == ["lim-2031"]


def test_temporaries_of_a_killed_writer_are_removed_by_the_next_write(tmp_path):
    """Where no anonymous file can be made, a named temporary is used; what a killed writer
    left is removed under the lock at the next write."""
    from test_store import make_record

    d = tmp_path / "results"
    path = d / "store.h5"
    store.write([make_record(tmp_path, "2031")], path)
    stale = d / "store.h5.k2j3h4.tmp"
    stale.write_bytes(b"\0" * 4096)
    store.write([make_record(tmp_path, "2032")], path)
    assert sorted(p.name for p in d.iterdir()) == ["store.h5"]


def test_named_temporaries_where_there_is_no_anonymous_file(tmp_path, monkeypatch):
    from test_store import make_record

    monkeypatch.setattr(outputs, "_anonymous", lambda directory: None)
    path = tmp_path / "store.h5"
    store.write([make_record(tmp_path, "2031")], path)

    def fail(root, rec):
        raise RuntimeError("boom")

    monkeypatch.setattr(store_writer, "_write_problem", fail)
    with pytest.raises(store.StoreError):
        store.write([make_record(tmp_path, "2032")], path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["problems", "store.h5"]


def test_report_says_the_store_is_damaged_instead_of_a_traceback(tmp_path):
    base, path = _two_problem_store(tmp_path)
    path.write_bytes(b"not a store\n")
    out = tmp_path / "report"
    result = run("--root", base, "report", "lim-2101", "--serial", "--no-simulate",
                 "--simplify-seconds", "0", "--store", path, "--out", out)
    assert result.exit_code == 0, result.output
    assert f"warning: cannot read the store {path}" in result.stderr
    assert "Traceback" not in result.output
    page = (out / "problems" / "lim-2101.html").read_text(encoding="utf-8")
    assert "its stored outcomes are not shown" in page


def test_salvage_keeps_simulations_with_their_dimension_scales(tmp_path):
    """A rebuilt store copies what reads as plain data; a simulation's dimension scales
    (object references, which do not survive a copy between files) are attached again."""
    import numpy as np
    from test_store import make_record

    path = tmp_path / "s.h5"
    store.write([make_record(tmp_path, "2031"), make_record(tmp_path, "2032")], path)
    t = np.linspace(0, 1, 5)
    store.write_simulation("lim-2031", "main-RK45", {"t": t, "q": np.ones((2, 5)),
                                                     "qdot": np.zeros((2, 5))},
                           {"coordinates": "x,y"}, None, path)
    with h5py.File(path, "r") as f:
        addr = h5py.h5o.get_info(f["problems/lim-2032"].id).addr
    with open(path, "r+b") as fh:
        fh.seek(addr)
        fh.write(b"\xff" * 64)
    store.write([make_record(tmp_path, "2033")], path)
    assert store.problems(path) == ["lim-2031", "lim-2033"]
    sim = store.read_simulation("lim-2031", "main-RK45", path)
    assert np.array_equal(sim["arrays"]["t"], t)
    with h5py.File(path, "r") as f:
        q = f["problems/lim-2031/simulations/main-RK45/q"]
        assert q.dims[0][0].name.endswith("/coordinate") and q.dims[1][0].name.endswith("/t")
        assert list(q.dims[0][0].asstr()[()]) == ["x", "y"]


def test_salvage_keeps_text_whose_bytes_damage_made_invalid_utf8(tmp_path):
    """Fuzz case 2844 (store kind, seed 1): a flipped byte inside a stored title left a
    string that is not UTF-8, which the readers read (with surrogate escapes) but the
    rebuild could not write back, so a readable record was lost when another one was
    damaged. Its bytes now go back as they came."""
    from test_store import make_record

    path = tmp_path / "s.h5"
    store.write([make_record(tmp_path, "2031"), make_record(tmp_path, "2032")], path)
    data = bytearray(path.read_bytes())
    title = store.read("lim-2031", path)["attrs"]["title"].encode("utf-8")
    at = data.find(title)
    assert at > 0
    data[at + 1] = 0xE1  # a lead byte with no continuation: not UTF-8
    with h5py.File(path, "r") as f:
        addr = h5py.h5o.get_info(f["problems/lim-2032"].id).addr
    data[addr:addr + 64] = b"\xff" * 64  # and another record damaged: the store is rebuilt
    path.write_bytes(bytes(data))
    before = store.read("lim-2031", path)["attrs"]["title"]
    assert "\udce1" in before
    store.write([make_record(tmp_path, "2033")], path)
    assert store.problems(path) == ["lim-2031", "lim-2033"]
    assert store.read("lim-2031", path)["attrs"]["title"] == before
