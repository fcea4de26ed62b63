"""Warm runs: stored outcomes are reused only while problem, answer key and engine are unchanged."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from mechbook.app.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _tree(tmp_path: Path) -> Path:
    for sub in ("problems/lim", "answers/lim"):
        (tmp_path / sub).mkdir(parents=True)
        shutil.copy(ROOT / sub / "2031.yaml", tmp_path / sub / "2031.yaml")
    return tmp_path


@pytest.mark.slow
def test_second_run_is_cached_and_a_changed_key_is_not(tmp_path):
    tree = _tree(tmp_path)
    runner = CliRunner()
    args = ["--root", str(tree), "check", "lim-2031"]
    first = runner.invoke(main, args)
    assert first.exit_code == 0, first.output
    assert "(cached" not in first.output
    second = runner.invoke(main, args)
    assert second.exit_code == 0
    assert "(cached" in second.output and "6 pass" in second.output
    key = tree / "answers/lim/2031.yaml"
    key.write_text(key.read_text().replace('book: "omega < Omega"', 'book: "omega > Omega"'))
    third = runner.invoke(main, args)
    assert "(cached" not in third.output
    assert third.exit_code == 1 and "fail" in third.output
    fresh = runner.invoke(main, [*args, "--fresh"])
    assert "(cached" not in fresh.output


def test_the_engine_fingerprint_covers_every_stage(monkeypatch, tmp_path):
    """A change to any stage's source (not only the app's) invalidates stored results: the
    fingerprint of a copy of the package changes when an engine module changes."""
    import mechbook.app.fingerprint as fp

    copy = tmp_path / "mechbook"
    shutil.copytree(ROOT / "mechbook", copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(fp, "__file__", str(copy / "app" / "fingerprint.py"))
    fp.engine_sha256.cache_clear()
    before = fp.engine_sha256()
    lagrange = copy / "engine" / "lagrange.py"
    lagrange.write_text(lagrange.read_text() + "\n# changed\n")
    fp.engine_sha256.cache_clear()
    try:
        assert fp.engine_sha256() != before
    finally:
        fp.engine_sha256.cache_clear()
