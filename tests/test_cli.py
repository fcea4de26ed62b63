"""The `mechbook` command line, driven through click's CliRunner."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

import mechbook.app.store as store
from mechbook import __version__
from mechbook.app.cli import main

ROOT = Path(__file__).resolve().parents[1]
COMMANDS = sorted(main.commands)


def run(*args: str):
    return CliRunner().invoke(main, list(args))


def test_commands_exist():
    assert {"list", "solve", "check", "validate", "show"} <= set(COMMANDS)


@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_main_help(flag):
    result = run(flag)
    assert result.exit_code == 0
    assert "Usage:" in result.output
    for name in COMMANDS:
        assert name in result.output


@pytest.mark.parametrize("name", COMMANDS)
def test_command_help(name):
    result = run(name, "--help")
    assert result.exit_code == 0, result.output
    assert result.output.startswith(f"Usage: main {name}") or f" {name} " in result.output
    first_line = (main.commands[name].help or "").strip().splitlines()[0]
    assert first_line.split()[0] in result.output


def test_version():
    result = run("--version")
    assert result.exit_code == 0
    assert __version__ in result.output


@pytest.mark.slow
def test_list():
    result = run("--root", str(ROOT), "list")
    assert result.exit_code == 0, result.output
    line = next(ln for ln in result.output.splitlines() if ln.startswith("lim-2031"))
    assert "parts" in line
    assert "Bead on a hoop" in line
    assert "INVALID" not in line


def test_list_marks_invalid_files(tmp_path):
    (tmp_path / "problems" / "lim").mkdir(parents=True)
    (tmp_path / "problems" / "lim" / "2099.yaml").write_text("id: lim-2099\nfoo: [\n")
    result = run("--root", str(tmp_path), "list")
    assert result.exit_code == 1  # listed, marked, and the status says something is wrong
    assert "lim-2099" in result.output
    assert "INVALID" in result.output
    assert "no answer key" in result.output


@pytest.mark.slow
def test_check_lim_2031_writes_store(tmp_path):
    path = tmp_path / "out.h5"
    result = run("--root", str(ROOT), "check", "lim-2031", "--store", str(path))
    assert result.exit_code == 0, result.output
    out = result.output
    assert "problem" in out and "outcome" in out  # the table header
    rows = [ln for ln in out.splitlines() if ln.startswith("lim-2031 ")]
    assert len(rows) >= 5
    assert all(" pass " in ln for ln in rows), out
    assert "1 problem," in out and "1 problems" not in out
    assert f"results written to {path}" in out
    got = store.read("lim-2031", path)
    assert [c["status"] for c in got["checks"]] == ["pass"] * len(rows)
    assert got["systems"]["main"]["symbolic"]["lagrangian"]
    # and `show` reads back what `check` wrote
    shown = run("--root", str(ROOT), "show", "lim-2031", "--store", str(path))
    assert shown.exit_code == 0, shown.output
    assert "Bead on a hoop" in shown.output
    assert "lagrangian:" in shown.output
    assert "a-lagrangian" in shown.output


@pytest.mark.slow
def test_check_no_store(tmp_path):
    path = tmp_path / "out.h5"
    result = run("--root", str(ROOT), "check", "lim-2031", "--store", str(path), "--no-store")
    assert result.exit_code == 0, result.output
    assert not path.exists()
    assert "results written" not in result.output


def _tree_with_answer(tmp_path: Path, answer_text: str) -> Path:
    (tmp_path / "problems" / "lim").mkdir(parents=True)
    (tmp_path / "answers" / "lim").mkdir(parents=True)
    shutil.copy(ROOT / "problems" / "lim" / "2031.yaml", tmp_path / "problems" / "lim")
    (tmp_path / "answers" / "lim" / "2031.yaml").write_text(answer_text, encoding="utf-8")
    return tmp_path


WRONG_KEY = """\
problem: lim-2031
source: a wrong answer key
parts:
  - part: wrong
    cite: test
    quantity: eom
    book: ["b*thetaddot + b*omega**2*sin(theta)*cos(theta) - g*sin(theta) = 0"]
  - part: right
    cite: test
    quantity: eom
    book: ["b*thetaddot - b*omega**2*sin(theta)*cos(theta) - g*sin(theta) = 0"]
"""


def test_check_exits_nonzero_on_fail(tmp_path):
    base = _tree_with_answer(tmp_path, WRONG_KEY)
    result = run("--root", str(base), "check", "lim-2031", "--no-store", "--format", "json")
    assert result.exit_code == 1
    (problem,) = json.loads(result.stdout)["problems"]
    statuses = {p["part"]: p["status"] for p in problem["parts"]}
    assert statuses["wrong"] == "fail"
    assert statuses["right"] == "pass"
    assert "1 failure(s)" in result.stderr


def test_check_unknown_problem(tmp_path):
    """An id with no problem file is refused before anything runs (a typo in a list of
    ids must not cost a whole batch)."""
    result = run("--root", str(ROOT), "check", "lim-2031", "lim-9999", "--no-store")
    assert result.exit_code == 5  # nothing selected: not a part that failed (1)
    assert "no problem lim-9999" in result.output
    assert "lim-2031 " not in result.output  # nothing was checked


def test_validate_good_files():
    problem = ROOT / "problems" / "lim" / "2031.yaml"
    answers = ROOT / "answers" / "lim" / "2031.yaml"
    result = run("validate", str(problem), str(answers))
    assert result.exit_code == 0, result.output
    assert "problem lim-2031 is valid" in result.output
    assert "answer key for lim-2031 is valid" in result.output


def test_validate_reports_each_bad_file(tmp_path):
    good = ROOT / "problems" / "lim" / "2031.yaml"
    bad = tmp_path / "2031.yaml"
    bad.write_text(good.read_text().replace("gravity: {}", "gravity: {}\ngravity: {}"))
    result = run("validate", str(good), str(bad))
    assert result.exit_code == 1
    assert "problem lim-2031 is valid" in result.output
    assert "invalid" in result.output and "duplicate key" in result.output


def test_validate_needs_a_file():
    result = run("validate")
    assert result.exit_code != 0
    result = run("validate", "/nonexistent/file.yaml")
    assert result.exit_code != 0


@pytest.mark.slow
def test_solve(tmp_path):
    result = run("--root", str(ROOT), "solve", "lim-2031", "--no-simplify")
    assert result.exit_code == 0, result.output
    assert result.output.startswith("lim-2031: Bead on a hoop")
    assert "lagrangian:" in result.output
    assert "accelerations:" in result.output


def test_solve_unknown_problem():
    result = run("--root", str(ROOT), "solve", "lim-9999")
    assert result.exit_code != 0
    assert "Error" in result.output


@pytest.mark.slow
def test_every_committed_file_validates():
    """Every problem and answer file in the tree passes `validate` (a first integral written
    "... = constant" included)."""
    files = sorted(map(str, (ROOT / "problems").glob("*/*.yaml"))) + \
        sorted(map(str, (ROOT / "answers").glob("*/*.yaml")))
    result = run("validate", *files)
    assert result.exit_code == 0, result.output
    assert result.output.count(" is valid") == len(files)


def test_validate_names_a_missing_system(tmp_path):
    """A part of a several-system problem that names no system is an error with its line."""
    (tmp_path / "answers" / "lim").mkdir(parents=True)
    (tmp_path / "problems" / "lim").mkdir(parents=True)
    shutil.copy(ROOT / "problems" / "lim" / "2043.yaml", tmp_path / "problems" / "lim")
    text = (ROOT / "answers" / "lim" / "2043.yaml").read_text()
    bad = tmp_path / "answers" / "lim" / "2043.yaml"
    bad.write_text(text.replace("    system: general\n", "", 1))
    result = run("validate", str(bad))
    assert result.exit_code == 1
    assert "Traceback" not in result.output
    assert "2043.yaml:" in result.output and "system" in result.output
