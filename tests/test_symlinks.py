"""Issue 21: problem files are regular files inside the tree. A link under problems/ or
answers/ to a file outside is refused (its contents were echoed by `list`, `check` and the
JSON), a dangling or looping link is refused with the reason instead of aborting the whole
`check` and `report`, and a link that stays inside the tree is followed."""

from __future__ import annotations

import json
import os

from hostile import check, pendulum_tree, run

SECRET = "SECRET-MARKER-4f1c"


def _links(tmp_path):
    base = pendulum_tree(tmp_path / "tree", nums=("2101", "2102"))
    outside = tmp_path / "outside.yaml"
    outside.write_text(f"id: lim-2110\nsource: {SECRET}\ntitle: {SECRET}\n")
    probs = base / "problems" / "lim"
    (probs / "2110.yaml").symlink_to(outside)
    (probs / "2111.yaml").symlink_to(probs / "nowhere.yaml")
    (probs / "2112.yaml").symlink_to(probs / "2112.yaml")
    (probs / "2113.yaml").symlink_to("/dev/zero")
    return base


REASONS = {"lim-2110": "outside", "lim-2111": "symbolic link to nothing",
           "lim-2112": "cannot be followed", "lim-2113": "outside"}


def test_list_refuses_links_that_leave_the_tree_and_shows_nothing_of_them(tmp_path):
    base = _links(tmp_path)
    result = run("--root", base, "list")
    assert result.exit_code == 1
    assert SECRET not in result.output
    lines = {ln.split()[0]: ln for ln in result.stdout.splitlines()}
    for pid, why in REASONS.items():
        assert "INVALID" in lines[pid] and why in lines[pid], lines[pid]
    assert "INVALID" not in lines["lim-2101"]


def test_check_goes_on_past_bad_links_and_leaks_nothing(tmp_path):
    base = _links(tmp_path)
    result = check(base, "--no-store", "--format", "json")
    assert result.exit_code == 1  # the refused files are errors
    assert SECRET not in result.output
    doc = json.loads(result.stdout)
    by_id = {p["id"]: p for p in doc["problems"]}
    for pid, why in REASONS.items():
        assert why in by_id[pid]["error"]
    assert [p["status"] for p in by_id["lim-2101"]["parts"]] == ["pass"]
    assert [p["status"] for p in by_id["lim-2102"]["parts"]] == ["pass"]


def test_report_goes_on_past_bad_links(tmp_path):
    base = _links(tmp_path)
    out = tmp_path / "report"
    result = run("--root", base, "report", "--serial", "--no-simulate", "--simplify-seconds",
                 "0", "--out", out)
    assert result.exit_code == 0, result.output
    assert (out / "problems" / "lim-2101.html").exists()
    page = (out / "problems" / "lim-2111.html").read_text(encoding="utf-8")
    assert "symbolic link to nothing" in page
    assert SECRET not in (out / "index.html").read_text(encoding="utf-8")


def test_an_answer_key_linked_from_outside_is_refused(tmp_path):
    base = pendulum_tree(tmp_path / "tree")
    outside = tmp_path / "key.yaml"
    key = base / "answers" / "lim" / "2101.yaml"
    outside.write_text(key.read_text())
    key.unlink()
    key.symlink_to(outside)
    result = check(base, "--no-store")
    assert result.exit_code == 1
    assert "outside" in result.output and "must stay inside the tree" in result.output


def test_links_inside_the_tree_are_followed(tmp_path):
    """A problem file linked to another file inside problems/ is followed (the target is
    named so that it is no problem file of its own)."""
    base = pendulum_tree(tmp_path / "tree")
    probs = base / "problems" / "lim"
    os.replace(probs / "2101.yaml", probs / "2101.yaml.kept")
    (probs / "2101.yaml").symlink_to(probs / "2101.yaml.kept")
    result = check(base, "--no-store")
    assert result.exit_code == 0, result.output


def test_a_linked_book_folder_that_leaves_the_tree_is_refused(tmp_path):
    base = pendulum_tree(tmp_path / "tree")
    os.replace(base / "problems" / "lim", tmp_path / "elsewhere")
    (base / "problems" / "lim").symlink_to(tmp_path / "elsewhere")
    result = check(base, "--no-store")
    assert result.exit_code == 1
    assert "outside" in result.output and "must stay inside the tree" in result.output


def test_books_yaml_linked_from_outside_the_tree_is_refused(tmp_path):
    """Issue 33 (found by the fuzzer's watch kind): books.yaml as a link to a file outside
    the tree was read, and its text shown in the error. It is held to the rule of problem
    files: read only from inside the tree."""
    base = pendulum_tree(tmp_path / "tree")
    outside = tmp_path / "outside.yaml"
    outside.write_text(f"{SECRET}\n")
    (base / "books.yaml").unlink()
    (base / "books.yaml").symlink_to(outside)
    res = run("--root", base, "list")
    assert res.exit_code == 1
    assert "outside the tree" in res.output and SECRET not in res.output
    (base / "books.yaml").unlink()
    (base / "books.yaml").symlink_to(tmp_path / "nowhere.yaml")
    res = run("--root", base, "check", "--serial", "lim-2101", "--no-store")
    assert res.exit_code == 1 and "leads nowhere" in res.output
