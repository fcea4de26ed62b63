"""Issue 33, `mechbook init DIR`: nothing written through a link or outside DIR, '' is no
directory, an overlong name is a message. Real `mechbook init` processes, real links."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hostile import mechbook

STARTER = sorted([".gitignore", "Makefile", "README.md", "answers/mybook/1.1.yaml",
                  "books.yaml", "problems/mybook/1.1.yaml",
                  *(f"schemas/{name}.json" for name in ("problem", "answers", "books",
                                                        "check-result"))])


def _files(top: Path) -> list[str]:
    return sorted(str(p.relative_to(top)) for p in top.rglob("*")
                  if p.is_file() or p.is_symlink())


def _refused(res, *needles: str) -> None:
    assert res.returncode == 1, (res.stdout, res.stderr)
    assert "Traceback" not in res.stderr, res.stderr
    for needle in needles:
        assert needle in res.stderr, res.stderr


@pytest.mark.parametrize("where", ["books.yaml", "Makefile", "problems/mybook/1.1.yaml"])
def test_a_dangling_link_under_dir_is_not_written_through(tmp_path, where):
    outside = tmp_path / "outside"
    outside.mkdir()
    target = tmp_path / "tree"
    link = target / where
    link.parent.mkdir(parents=True)
    link.symlink_to(outside / "planted")
    _refused(mechbook("init", target, cwd=tmp_path), str(link), "exists already")
    assert list(outside.iterdir()) == []
    assert _files(target) == [where], "a refused init wrote files before refusing"


@pytest.mark.parametrize("folder", ["problems", "answers", "problems/mybook"])
def test_a_linked_folder_under_dir_is_not_written_through(tmp_path, folder):
    outside = tmp_path / "outside"
    outside.mkdir()
    target = tmp_path / "tree"
    (target / folder).parent.mkdir(parents=True, exist_ok=True)
    (target / folder).symlink_to(outside, target_is_directory=True)
    _refused(mechbook("init", target, cwd=tmp_path), f"{target / folder} is a symbolic link")
    assert list(outside.iterdir()) == []
    assert not (target / "books.yaml").exists()


def test_an_empty_name_is_no_directory(tmp_path):
    """`init ''` wrote the starter tree into the current directory."""
    _refused(mechbook("init", "", cwd=tmp_path), "no directory named")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["a" * 300, "x/" + "b" * 300, "c" * 5000])
def test_an_overlong_name_is_a_message(tmp_path, name):
    """A 300-character name ended in an OSError traceback."""
    res = mechbook("init", name, cwd=tmp_path)
    _refused(res, "cannot write")
    assert list(tmp_path.iterdir()) == [], "a refused init left folders behind"


def test_dir_that_is_a_dangling_link_or_a_file_is_refused(tmp_path):
    (tmp_path / "gone").symlink_to(tmp_path / "nowhere")
    _refused(mechbook("init", "gone", cwd=tmp_path), "symbolic link to nothing")
    assert not (tmp_path / "nowhere").exists()
    os.mkfifo(tmp_path / "fifo")
    _refused(mechbook("init", "fifo", cwd=tmp_path), "not a directory")


def test_dir_named_through_a_link_to_a_directory_is_the_users_choice(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "named").symlink_to(real, target_is_directory=True)
    res = mechbook("init", "named", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert _files(real) == STARTER
