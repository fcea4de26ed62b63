"""Issue 33, the report's page list (`.pages.json`): a file anyone can replace. A FIFO hung
`mechbook report` on 0834a76, a link to /dev/zero ended in a MemoryError, JSON nested deep
in a RecursionError, entries of the wrong shape in an AttributeError. Now each is no page
list (a warning; every page is built again) and the report is written. Real `mechbook
report` processes (pages in the process, --serial) with their address space bounded."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from hostile import check, mechbook, pendulum_tree


@pytest.fixture
def tree(tmp_path) -> Path:
    base = pendulum_tree(tmp_path / "tree")
    assert check(base).exit_code == 0
    return base


def _report(tree: Path):
    return mechbook("--root", tree, "report", "--serial", "--no-simulate", cwd=tree,
                    timeout=180)


def _plant(tree: Path, how: str) -> Path:
    out = tree / "results" / "report"
    out.mkdir(parents=True, exist_ok=True)
    path = out / ".pages.json"
    if how == "fifo":
        os.mkfifo(path)
    elif how == "devzero":
        path.symlink_to("/dev/zero")
    elif how == "directory":
        path.mkdir()
    elif how == "nested":
        path.write_text("[" * 200_000 + "]" * 200_000)
    elif how == "shapes":
        path.write_text(json.dumps({"format": 1, "pages": {
            "lim-2101": {"key": "x", "index": "not a mapping"},
            "lim-2102": {"key": 5, "index": {"parts": [7, {"part": ["a"]}]}},
            "lim-2103": "an entry"}}))
    elif how == "bytes":
        path.write_bytes(b"\xff\xfe" * 1000)
    return path


@pytest.mark.parametrize("how, warned", [("fifo", "it is a FIFO"),
                                         ("devzero", "it is a character device"),
                                         ("directory", "it is a directory"),
                                         ("nested", "nested more than 32 levels"),
                                         ("shapes", "not what a report writes"),
                                         ("bytes", "not usable")])
def test_a_hostile_page_list_is_no_page_list(tree, how, warned):
    path = _plant(tree, how)
    res = _report(tree)
    text = res.stdout + res.stderr
    assert res.returncode == 0, text
    assert "Traceback" not in text and "MemoryError" not in text
    assert f"warning: the report's page list {path}" in res.stderr, res.stderr
    assert warned in res.stderr, res.stderr
    assert "report written to" in res.stdout
    page = tree / "results" / "report" / "problems" / "lim-2101.html"
    assert "lim-2101" in page.read_text("utf-8")
    if how not in ("directory",):  # a directory in its place stays (said so); else replaced
        assert json.loads(path.read_text("utf-8"))["pages"]["lim-2101"]["key"]


def test_report_files_are_replaced_never_written_through_a_link(tree, tmp_path):
    """A link planted in place of a page, the index or the page list: the report's own
    file replaces the link; what it pointed to is left as it was."""
    victim = tmp_path / "victim.txt"
    victim.write_text("untouched")
    out = tree / "results" / "report"
    (out / "problems").mkdir(parents=True)
    for name in ("index.html", ".pages.json", "problems/lim-2101.html"):
        (out / name).symlink_to(victim)
    res = _report(tree)
    assert res.returncode == 0, res.stderr
    assert victim.read_text() == "untouched"
    for name in ("index.html", ".pages.json", "problems/lim-2101.html"):
        assert not (out / name).is_symlink()
