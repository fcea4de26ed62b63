"""The exit statuses (issue 43 item 4): a script tells "a part failed" (1) from "no such
problem / nothing selected" (5) and from a usage error (4), as with pytest; every status is
in `--help` and in the docs; counts are singular when one; `init` writes a README and a
.gitignore for results/."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
from click.testing import CliRunner

import mechbook
from mechbook.app.cli import main
from mechbook.app.cli.statuses import FAILED, NOTHING_SELECTED, OK, TABLE, USAGE
from mechbook.core.words import plural
from mechbook.errors import NothingSelectedError

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def tree(tmp_path_factory) -> Path:
    """The starter tree (passes) with mybook-1.2, whose key is 1 % off (a fail)."""
    base = tmp_path_factory.mktemp("statuses") / "tree"
    assert CliRunner().invoke(main, ["init", str(base)]).exit_code == 0
    for kind in ("problems", "answers"):
        text = (base / kind / "mybook" / "1.1.yaml").read_text("utf-8")
        text = text.replace("mybook-1.1", "mybook-1.2")
        if kind == "answers":
            text = text.replace('"sqrt(k/m)"', '"1.01*sqrt(k/m)"')
        (base / kind / "mybook" / "1.2.yaml").write_text(text, "utf-8")
    return base


def run(base: Path, *args: str):
    return CliRunner().invoke(main, ["--root", str(base), *args])


def test_the_statuses_are_distinct_and_as_pytest():
    codes = [code for code, _ in TABLE]
    assert len(set(codes)) == len(codes)
    assert (OK, FAILED, USAGE, NOTHING_SELECTED) == (0, 1, 4, 5)  # pytest's 0, 1, 4, 5


@pytest.mark.slow  # two checks of the starter problem
def test_pass_fail_and_nothing_selected_differ(tree):
    assert run(tree, "check", "--serial", "--no-store", "mybook-1.1").exit_code == OK
    failed = run(tree, "check", "--serial", "--no-store", "mybook-1.2")
    assert failed.exit_code == FAILED, failed.output
    for args in (["mybook-9"], ["otherbook"], ["zz-*"], ["mybook-1.1", "mybook-7"]):
        res = run(tree, "check", "--serial", "--no-store", *args)
        assert res.exit_code == NOTHING_SELECTED, (args, res.output)
        assert "Traceback" not in res.output
    missing = run(tree, "check", "--no-store", "mybook-9")
    assert "no problem mybook-9" in missing.output
    assert "`mechbook list` shows" in missing.output


@pytest.mark.parametrize("command", [["solve"], ["simulate", "--no-store"], ["watch"],
                                     ["report"], ["sweep", "--param", "k=1:2:3",
                                                  "--no-store"]])
def test_every_command_says_no_such_problem_with_its_status(tree, command):
    res = run(tree, command[0], "mybook-9", *command[1:])
    assert res.exit_code == NOTHING_SELECTED, res.output
    assert "no problem mybook-9" in res.output and "`mechbook list` shows" in res.output


@pytest.mark.parametrize("args", [["--bogus"], ["check", "--bogus"], ["check", "-j", "x"],
                                  ["check", "--serial", "-j", "2"], ["schema"],
                                  ["list", "extra"], ["check", "bad..id", "--no-store"],
                                  ["simulate", "lim-2031/x", "--no-store"],
                                  ["show", "Lim-1"]])
def test_a_usage_error_exits_4(tree, args):
    res = run(tree, *args)
    assert res.exit_code == USAGE, (args, res.exit_code, res.output)


def test_a_real_process_exits_with_the_statuses(tree):
    """Through the console script's own exit (not only CliRunner's)."""
    import sys

    def status(*args: str) -> int:
        return subprocess.run([sys.executable, "-m", "mechbook", "--root", str(tree), *args],
                              capture_output=True, timeout=300).returncode

    assert status("check", "mybook-9", "--no-store") == NOTHING_SELECTED
    assert status("check", "--bogus") == USAGE


def test_every_status_is_in_help_and_in_the_docs():
    shown = run(ROOT, "--help").output + run(ROOT, "check", "--help").output
    docs = (ROOT / "docs" / "reliability.md").read_text("utf-8")
    readme = (ROOT / "README.md").read_text("utf-8")
    for code, _ in TABLE:
        assert re.search(rf"^\s+{code}\s+\S", shown, re.M), f"--help lacks {code}"
        assert re.search(rf"^\| `?{code}`? \|", docs, re.M), f"docs/reliability.md lacks {code}"
        assert f"{code}" in readme.split("## Exit status", 1)[1].split("\n## ", 1)[0]


def test_the_api_says_what_the_command_line_says(tree):
    with pytest.raises(NothingSelectedError) as err:
        mechbook.load("mybook-9", tree)
    text = str(err.value)
    assert text.startswith("no problem mybook-9 (no file ") and "`mechbook list` shows" in text
    assert "cannot read file" not in text
    assert isinstance(err.value, KeyError)  # a NotFoundError: callers catching one still do


# ---- plurals -----------------------------------------------------------------------------------
def test_plural():
    assert [plural(n, "point") for n in (0, 1, 2)] == ["0 points", "1 point", "2 points"]
    assert plural(1, "body", "bodies") == "1 body" and plural(3, "body", "bodies") == "3 bodies"


@pytest.mark.slow  # a check of the starter problem
def test_one_problem_is_one_problem(tree):
    res = run(tree, "check", "--serial", "--no-store", "mybook-1.1")
    assert "1 problem, 3 parts: 3 pass" in res.output, res.output
    assert "1 problems" not in res.output
    listed = run(tree, "validate", str(tree / "answers" / "mybook" / "1.1.yaml"))
    assert "(3 parts)" in listed.output, listed.output


def test_a_method_names_one_point_in_the_singular():
    import sympy as sp

    from mechbook.verify.compare import Sampler, equal

    x = sp.Symbol("x", positive=True)
    verdict = equal(x, 2 * x, Sampler({x: 1.0}), symbolic=False)
    assert not verdict.ok and verdict.method == "numeric(1 point)", verdict.method


# ---- the starter tree --------------------------------------------------------------------------
def test_init_writes_a_readme_and_a_gitignore(tree):
    readme = (tree / "README.md").read_text("utf-8")
    for said in ("mechbook check", "problems/", "answers/", "results/", "make watch"):
        assert said in readme, said
    ignored = (tree / ".gitignore").read_text("utf-8").splitlines()
    assert "results/" in ignored


def test_the_gitignore_keeps_results_out_of_git(tree, tmp_path):
    """Checked by git itself, where git is installed: results/ ignored, the files not."""
    import shutil

    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    copy = tmp_path / "copy"
    shutil.copytree(tree, copy)
    (copy / "results").mkdir(exist_ok=True)
    (copy / "results" / "mechbook.h5").write_bytes(b"")
    subprocess.run(["git", "init", "-q", str(copy)], check=True)

    def ignored(rel: str) -> bool:
        return subprocess.run(["git", "-C", str(copy), "check-ignore", "-q", rel]).returncode == 0

    assert ignored("results/mechbook.h5")
    assert not ignored("problems/mybook/1.1.yaml") and not ignored("README.md")
