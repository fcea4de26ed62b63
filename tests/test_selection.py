"""The command line as pytest users and authors expect (issue 34 item 6): problems chosen
by pattern or by book, `-x/--exitfirst`, `--lf/--last-failed`, and the JSON Schemas handed
to an editor (`mechbook schema`, and the modelines `mechbook init` writes)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import jsonschema
import pytest
from click.testing import CliRunner

from mechbook.app.cli import main
from mechbook.model.yamlio import load as load_yaml


@pytest.fixture
def tree(tmp_path) -> Path:
    """The starter tree with three problems: mybook-1.1 and 1.3 pass, 1.2's key is wrong
    (a frequency 1 % off: a fail)."""
    base = tmp_path / "tree"
    assert CliRunner().invoke(main, ["init", str(base)]).exit_code == 0
    for num, key_edit in (("1.2", True), ("1.3", False)):
        for kind in ("problems", "answers"):
            text = (base / kind / "mybook" / "1.1.yaml").read_text("utf-8")
            text = text.replace("mybook-1.1", f"mybook-{num}")
            if kind == "answers" and key_edit:
                text = text.replace('"sqrt(k/m)"', '"1.01*sqrt(k/m)"')
            (base / kind / "mybook" / f"{num}.yaml").write_text(text, "utf-8")
    return base


def check(base: Path, *args: str):
    return CliRunner().invoke(main, ["--root", str(base), "check", "--serial", *args])


def checked(result) -> list[str]:
    """The problem ids of the outcome table, in its order."""
    return sorted({line.split()[0] for line in result.stdout.splitlines()
                   if line.startswith("mybook-")})


def test_problems_by_pattern_and_by_book(tree):
    assert checked(check(tree, "mybook-1.[13]", "--no-store")) == ["mybook-1.1",
                                                                  "mybook-1.3"]
    both = check(tree, "mybook", "--no-store")
    assert checked(both) == ["mybook-1.1", "mybook-1.2", "mybook-1.3"]
    assert both.exit_code == 1  # 1.2 fails
    for arg, said in (("other-*", "no problem id matches 'other-*'"),
                      ("other", "no problem of book 'other'")):
        res = check(tree, arg, "--no-store")
        assert res.exit_code == 5 and said in res.output and "books there: mybook" in \
            res.output, res.output


def test_exitfirst_stops_at_the_first_failure(tree):
    res = check(tree, "-x", "--no-store", "mybook-1.1", "mybook-1.2", "mybook-1.3")
    assert res.exit_code == 1
    assert checked(res) == ["mybook-1.1", "mybook-1.2"]
    assert "stopped at the first failure (-x): 1 problem(s) not checked: mybook-1.3" in \
        res.stderr


@pytest.mark.slow  # worker processes
def test_exitfirst_stops_the_worker_pool(tree):
    res = CliRunner().invoke(main, ["--root", str(tree), "check", "-x", "-j", "1",
                                    "--no-store", "mybook-1.2", "mybook-1.1", "mybook-1.3"])
    assert res.exit_code == 1 and checked(res) == ["mybook-1.2"], res.output
    assert "2 problem(s) not checked" in res.stderr


def test_last_failed_reruns_only_the_failures(tree):
    first = check(tree)
    assert first.exit_code == 1
    again = check(tree, "--lf")
    assert checked(again) == ["mybook-1.2"], again.output
    assert "checking the 1 of 3 problem(s) that failed when last checked" in again.stderr
    key = tree / "answers" / "mybook" / "1.2.yaml"
    key.write_text(key.read_text("utf-8").replace("1.01*sqrt", "sqrt"), "utf-8")
    fixed = check(tree, "--lf")
    assert fixed.exit_code == 0 and checked(fixed) == ["mybook-1.2"], fixed.output
    rest = check(tree, "--lf")
    assert "no problem failed when last checked: checking all 3" in rest.stderr
    assert checked(rest) == ["mybook-1.1", "mybook-1.2", "mybook-1.3"]


@pytest.mark.parametrize("kind", ["fifo", "devzero", "deep"])
def test_a_hostile_record_of_failures_is_not_followed(tree, kind):
    """The record beside the store is anyone's to replace: a FIFO (reading would wait for
    ever), a link to /dev/zero (reading would never end) or JSON nested too deep reads as
    no record, and the next run replaces it with a file of its own."""
    assert check(tree).exit_code == 1
    record = tree / "results" / ".mechbook.h5.lastfailed.json"
    assert json.loads(record.read_text("utf-8")) == {"failed": ["mybook-1.2"]}
    record.unlink()
    if kind == "fifo":
        os.mkfifo(record)
    elif kind == "devzero":
        record.symlink_to("/dev/zero")
    else:
        record.write_text("[" * 100_000 + "]" * 100_000, "utf-8")
    res = check(tree, "--lf")
    assert "no problem failed when last checked: checking all 3" in res.stderr
    assert record.is_file() and not record.is_symlink()
    assert json.loads(record.read_text("utf-8")) == {"failed": ["mybook-1.2"]}


def test_schema_prints_and_writes(tmp_path):
    runner = CliRunner()
    shown = runner.invoke(main, ["schema", "problem"])
    assert shown.exit_code == 0 and json.loads(shown.stdout)["title"] == "mechbook problem"
    answers = json.loads(runner.invoke(main, ["schema", "answers"]).stdout)
    assert "frequencies" in answers["$defs"]["part"]["properties"]["quantity"]["enum"]
    written = runner.invoke(main, ["schema", "--write", str(tmp_path / "s")])
    assert written.exit_code == 0
    assert sorted(p.name for p in (tmp_path / "s").iterdir()) == [
        "answers.json", "books.json", "check-result.json", "problem.json"]
    assert runner.invoke(main, ["schema"]).exit_code == 4  # neither: a usage error


def test_init_hands_the_schemas_to_the_editor(tmp_path):
    """Each file `init` writes names its schema on the first line, by a path relative to
    the file that exists; the file is valid under it, and a misspelt key is not (what the
    editor underlines while one types)."""
    base = tmp_path / "mine"
    assert CliRunner().invoke(main, ["init", str(base)]).exit_code == 0
    for rel in ("books.yaml", "problems/mybook/1.1.yaml", "answers/mybook/1.1.yaml"):
        path = base / rel
        first = path.read_text("utf-8").splitlines()[0]
        assert first.startswith("# yaml-language-server: $schema="), first
        schema_file = (path.parent / first.split("=", 1)[1]).resolve()
        assert schema_file.parent == (base / "schemas").resolve()
        schema = json.loads(schema_file.read_text("utf-8"))
        data = load_yaml(path).data
        jsonschema.validate(data, schema)
        wrong = dict(data, titel="x") if "books" not in data else {"books": [
            dict(data["books"][0], auther="x")]}
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(wrong, schema)
