"""Issue 44, item 1 and the writers of item 5: nothing written through a link, nothing
blocking on a FIFO, nothing left half-written on a full disk. Real links, FIFOs and a real
full file system (a small tmpfs, where the test may mount one), real `mechbook` processes."""

from __future__ import annotations

import hashlib
import os
import subprocess
from pathlib import Path

import pytest
from hostile import can_mount, check, mechbook, pendulum_tree, run, tmpfs


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("dangling", [False, True])
def test_schema_write_refuses_a_link_in_place_of_a_schema(tmp_path, dangling):
    outside = tmp_path / "outside"
    outside.mkdir()
    target = outside / "victim.txt"
    if not dangling:
        target.write_text("keep me\n", encoding="utf-8")
    tree = tmp_path / "tree" / "schemas"
    tree.mkdir(parents=True)
    (tree / "problem.json").symlink_to(target)
    done = mechbook("schema", "--write", tree, timeout=60)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "symbolic link" in done.stderr and "problem.json" in done.stderr
    assert "Traceback" not in done.stderr
    if dangling:
        assert not os.path.lexists(target)  # no file made at the link's target
    else:
        assert target.read_text(encoding="utf-8") == "keep me\n"
    assert (tree / "problem.json").is_symlink()
    assert sorted(p.name for p in tree.iterdir()) == ["problem.json"]  # nothing written


def test_schema_write_refuses_a_fifo_without_blocking(tmp_path):
    tree = tmp_path / "schemas"
    tree.mkdir()
    os.mkfifo(tree / "problem.json")
    done = mechbook("schema", "--write", tree, timeout=60)  # TimeoutExpired: a hang
    assert done.returncode == 1
    assert "FIFO" in done.stderr and "problem.json" in done.stderr


@pytest.mark.parametrize("kind", ["file", "link-to-file", "under-a-file"])
def test_schema_write_to_a_regular_file_is_an_error(tmp_path, kind):
    plain = tmp_path / "plain"
    plain.write_text("x", encoding="utf-8")
    where = {"file": plain, "link-to-file": tmp_path / "link",
             "under-a-file": plain / "sub"}[kind]
    if kind == "link-to-file":
        where.symlink_to(plain)
    done = mechbook("schema", "--write", where, timeout=60)
    assert done.returncode == 1, (done.returncode, done.stderr)
    assert "cannot write the schema directory" in done.stderr
    assert plain.read_text(encoding="utf-8") == "x"


def test_schema_write_on_a_full_disk_leaves_no_empty_file(tmp_path):
    if not can_mount():
        pytest.skip("mounting a tmpfs needs root")
    where = tmp_path / "small"
    try:
        with tmpfs(where, size="64k"):
            old = where / "schemas"
            old.mkdir()
            (old / "books.json").write_text('{"old": 1}\n', encoding="utf-8")
            # fill the file system to the last block
            subprocess.run(["dd", "if=/dev/zero", f"of={where / 'fill'}", "bs=4k"],
                           capture_output=True)
            done = mechbook("schema", "--write", old, timeout=60)
            assert done.returncode == 1, done.stdout + done.stderr
            assert "No space left" in done.stderr
            left = {p.name: p.stat().st_size for p in old.iterdir()}
            assert left == {"books.json": len('{"old": 1}\n')}, left  # no empty schema
            assert (old / "books.json").read_text(encoding="utf-8") == '{"old": 1}\n'
    except subprocess.CalledProcessError:
        pytest.skip("mount -t tmpfs is not permitted here")


def test_report_rebuilds_a_page_replaced_by_a_link(tmp_path):
    tree = pendulum_tree(tmp_path / "tree")
    assert check(tree).exit_code == 0
    assert run("--root", tree, "report").exit_code == 0
    page = tree / "results" / "report" / "problems" / "lim-2101.html"
    assert page.is_file() and not page.is_symlink()
    secret = tmp_path / "secret.html"
    secret.write_text("<p>outside the tree</p>\n", encoding="utf-8")
    page.unlink()
    page.symlink_to(secret)
    done = run("--root", tree, "report")
    assert done.exit_code == 0, done.output
    assert not page.is_symlink() and page.is_file()  # the page built again, in place
    assert "outside the tree" not in page.read_text(encoding="utf-8")
    assert secret.read_text(encoding="utf-8") == "<p>outside the tree</p>\n"


def test_books_yaml_linked_outside_writes_nothing_there(tmp_path):
    tree = pendulum_tree(tmp_path / "tree")
    outside = tmp_path / "outside"
    outside.mkdir()
    (tree / "books.yaml").rename(outside / "books.yaml")
    (tree / "books.yaml").symlink_to(outside / "books.yaml")
    before = _digest(outside / "books.yaml")
    for args in (["check", "--serial", "--no-crosscheck"], ["report"], ["validate"],
                 ["schema", "--write", tree / "schemas"]):
        done = mechbook("--root", tree, *args, cwd=tree, timeout=120)
        assert "Traceback" not in done.stderr, done.stderr
    assert sorted(p.name for p in outside.iterdir()) == ["books.yaml"]
    assert _digest(outside / "books.yaml") == before


def test_watch_writes_nothing_through_a_key_replaced_by_a_link(tmp_path):
    tree = pendulum_tree(tmp_path / "tree")
    outside = tmp_path / "outside.yaml"
    key = tree / "answers" / "lim" / "2101.yaml"
    outside.write_text(key.read_text(encoding="utf-8").replace("test key", "outside key"),
                       encoding="utf-8")
    before = _digest(outside)
    key.unlink()
    key.symlink_to(outside)
    done = mechbook("--root", tree, "watch", "lim-2101", "--no-crosscheck", "--runs", "1",
                    cwd=tree, timeout=60)
    assert "outside" in done.stdout + done.stderr, done.stdout + done.stderr
    assert _digest(outside) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["outside.yaml", "tree"]


@pytest.mark.parametrize("plant", ["link", "dangling", "fifo"])
def test_the_side_file_is_never_written_through_a_link_or_into_a_fifo(tmp_path, plant):
    """The side file's name is guessable (<store>.unsaved-<time>-<pid>.jsonl): a link or a
    FIFO planted there is refused (OSError: the next place is tried), never followed or
    waited on."""
    from mechbook.app.store.unsaved import append_line

    victim = tmp_path / "victim.txt"
    victim.write_text("keep me\n", encoding="utf-8")
    path = tmp_path / "mechbook.h5.unsaved-x.jsonl"
    if plant == "link":
        path.symlink_to(victim)
    elif plant == "dangling":
        path.symlink_to(tmp_path / "made-here")
    else:
        os.mkfifo(path)
    with pytest.raises(OSError):
        append_line(path, '{"a": 1}\n')  # a FIFO without a reader: no block (O_NONBLOCK)
    assert victim.read_text(encoding="utf-8") == "keep me\n"
    assert not (tmp_path / "made-here").exists()


def test_schema_write_past_the_file_size_limit_leaves_no_empty_file(tmp_path):
    """The full disk without a mount: RLIMIT_FSIZE of 8 KiB (the answers schema is ~44 KB),
    SIGXFSZ ignored so that the write fails with EFBIG as on a full disk."""
    import resource
    import signal
    import sys

    from hostile import ROOT

    old = tmp_path / "schemas"
    old.mkdir()
    (old / "answers.json").write_text('{"old": 1}\n', encoding="utf-8")

    def small_files() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        resource.setrlimit(resource.RLIMIT_FSIZE, (8192, 8192))

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
    done = subprocess.run([sys.executable, "-m", "mechbook", "schema", "--write", str(old)],
                          capture_output=True, text=True, timeout=120, env=env,
                          preexec_fn=small_files)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "File too large" in done.stderr, done.stderr
    assert "Traceback" not in done.stderr
    import json

    for path in old.iterdir():  # nothing empty, nothing half-written: whole JSON or absent
        json.loads(path.read_text(encoding="utf-8"))
    assert (old / "answers.json").read_text(encoding="utf-8") == '{"old": 1}\n'
