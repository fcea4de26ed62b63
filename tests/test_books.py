"""Books declared in data: books.yaml, ids <book>-<number>, and a third book added to a
scratch tree without any code change."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from mechbook.app.cli import main
from mechbook.errors import MechbookError, SpecError
from mechbook.model.books import book_of, books, load_books, split_id
from mechbook.model.catalog import all_ids, problem_path
from mechbook.model.problem import load_problem

ROOT = Path(__file__).resolve().parents[1]

THIRD_BOOKS = """\
books:
  - id: toy
    short: Toy
    title: A Toy Book of Oscillators
    author: Nobody in Particular
    edition: 1st edition
    numbers: "[0-9]+[.][0-9]+"
    example: "1.1"
"""

# A block of mass m on a horizontal spring of stiffness k (x from the spring's natural length)
TOY_PROBLEM = """\
id: toy-3.2
source: A Toy Book of Oscillators, problem 3.2
title: Block on a horizontal spring
description: A block slides without friction on a table, held by a spring to a wall.
parameters:
  m: {doc: mass of the block, value: 2.0}
  k: {doc: stiffness of the spring, value: 8.0}
coordinates:
  x: {doc: stretch of the spring}
kinetic: m*xdot**2/2
potential: k*x**2/2
compute: [lagrangian, eom, equilibria, small_oscillations]
"""

# by hand: L = m xdot^2/2 - k x^2/2, Lagrange: m xddot + k x = 0, omega = sqrt(k/m)
TOY_ANSWERS = """\
problem: toy-3.2
source: A Toy Book of Oscillators, problem 3.2
parts:
  - part: a
    cite: Toy 3.2 (a), the Lagrangian
    quantity: lagrangian
    book: "m*xdot**2/2 - k*x**2/2"
  - part: b
    cite: Toy 3.2 (b), the equation of motion
    quantity: eom
    book: ["m*xddot + k*x = 0"]
  - part: c
    cite: Toy 3.2 (c), the angular frequency
    quantity: frequencies
    about: {x: 0}
    book: ["{omega}"]
"""


def third_book_tree(tmp: Path, omega: str = "sqrt(k/m)") -> Path:
    """A scratch tree: the repository's books.yaml plus the toy book, one toy problem."""
    (tmp / "books.yaml").write_text((ROOT / "books.yaml").read_text(encoding="utf-8")
                                    + THIRD_BOOKS.removeprefix("books:\n"), encoding="utf-8")
    (tmp / "problems" / "toy").mkdir(parents=True)
    (tmp / "answers" / "toy").mkdir(parents=True)
    (tmp / "problems" / "toy" / "3.2.yaml").write_text(TOY_PROBLEM, encoding="utf-8")
    (tmp / "answers" / "toy" / "3.2.yaml").write_text(TOY_ANSWERS.replace("{omega}", omega),
                                                      encoding="utf-8")
    return tmp


def run(*args: str):
    return CliRunner().invoke(main, list(args))


@pytest.mark.slow
def test_the_repository_declares_every_book_it_holds():
    declared = books(ROOT)
    assert {"lim", "symon"} <= set(declared)
    for pid in all_ids(ROOT):
        assert book_of(pid, ROOT) is not None, pid
        assert load_problem(problem_path(pid, ROOT)).id == pid


@pytest.mark.parametrize("pid, parts", [("lim-2031", ("lim", "2031")),
                                        ("symon-09-12", ("symon", "09-12")),
                                        ("symon-text-9-7-rotating-hoop",
                                         ("symon", "text-9-7-rotating-hoop")),
                                        ("toy-3.2", ("toy", "3.2"))])
def test_split_id(pid, parts):
    assert split_id(pid) == parts


@pytest.mark.parametrize("pid", ["lim", "lim-", "-2031", "Lim-2031", "lim-../2031",
                                 "lim-20/31", "lim-2031.", "lim-.2031", "lim-20..31", "",
                                 "lim 2031"])
def test_malformed_ids_are_refused(pid):
    with pytest.raises(MechbookError, match="bad problem id"):
        split_id(pid)


def test_undeclared_book_and_wrong_number_are_refused():
    with pytest.raises(MechbookError, match="book 'toy' is not declared"):
        problem_path("toy-3.2", ROOT)
    with pytest.raises(MechbookError, match="does not look like a problem number of Lim"):
        problem_path("lim-203", ROOT)
    with pytest.raises(MechbookError, match="Symon"):
        problem_path("symon-9-12", ROOT)


def test_a_file_whose_id_does_not_fit_its_place_is_refused(tmp_path):
    tree = third_book_tree(tmp_path)
    bad = tree / "problems" / "toy" / "3.3.yaml"
    bad.write_text(TOY_PROBLEM, encoding="utf-8")  # says toy-3.2
    with pytest.raises(SpecError, match=r"3\.3\.yaml:1: id: id 'toy-3.2' does not match"):
        load_problem(bad)
    (tree / "problems" / "nobook").mkdir()
    other = tree / "problems" / "nobook" / "3.2.yaml"
    other.write_text(TOY_PROBLEM.replace("toy-3.2", "nobook-3.2"), encoding="utf-8")
    with pytest.raises(SpecError, match="book 'nobook' is not declared"):
        load_problem(other)


@pytest.mark.parametrize("change, message", [
    (("numbers: \"[0-9]+[.][0-9]+\"", "numbers: \"[0-9\""), "not a regular expression"),
    (("example: \"1.1\"", "example: \"A\""), "does not match"),
    (("id: toy", "id: Toy"), "does not match"),
    (("  - id: toy", "  - id: lim"), "declared twice"),
])
def test_a_bad_books_file_names_its_line(tmp_path, change, message):
    tree = third_book_tree(tmp_path)
    text = (tree / "books.yaml").read_text(encoding="utf-8")
    (tree / "books.yaml").write_text(text.replace(*change), encoding="utf-8")
    with pytest.raises(SpecError, match=message) as err:
        load_books(tree / "books.yaml")
    assert "books.yaml:" in str(err.value)


def test_a_third_book_is_checked_without_code_changes(tmp_path):
    """The toy book is only data: its problem lists, validates and checks, every part passes,
    and the store and the JSON output carry its id."""
    tree = third_book_tree(tmp_path)
    listed = run("--root", str(tree), "list")
    assert listed.exit_code == 0, listed.output
    assert "toy-3.2" in listed.output and "3 parts" in listed.output
    valid = run("validate", str(tree / "problems/toy/3.2.yaml"), str(tree / "answers/toy/3.2.yaml"))
    assert valid.exit_code == 0, valid.output
    checked = run("--root", str(tree), "check", "toy-3.2", "--serial", "--store",
                  str(tree / "out.h5"))
    assert checked.exit_code == 0, checked.output
    rows = [ln for ln in checked.output.splitlines() if ln.startswith("toy-3.2 ")]
    assert len(rows) == 3 and all(" pass " in ln for ln in rows), checked.output


def test_a_wrong_answer_in_the_third_book_fails(tmp_path):
    tree = third_book_tree(tmp_path, omega="sqrt(2*k/m)")
    checked = run("--root", str(tree), "check", "toy-3.2", "--serial", "--no-store",
                  "--no-crosscheck")
    assert checked.exit_code == 1
    row = next(ln for ln in checked.output.splitlines() if ln.startswith("toy-3.2 ")
               and " c " in ln)
    assert " fail " in row


# ---- one id grammar (mechbook.model.ids), used by the catalog, books.yaml and the schema ----
GOOD_IDS = ["lim-2031", "symon-09-12", "symon-text-9-7-rotating-hoop", "toy-3.2", "x-a_b",
            "a" * 40 + "-1", "x-" + "1" * 80]
BAD_IDS = ["lim", "lim-", "-2031", "Lim-2031", "lim-../2031", "lim-20/31", "lim-2031.",
           "lim-.2031", "lim-20..31", "", "lim 2031", "lim_x-1", "lim-20__31", "lim-2031\n",
           "a" * 41 + "-1", "x-" + "1" * 81, "lim-a\\b", "/etc/passwd", "x-_1"]


@pytest.mark.parametrize("pid", GOOD_IDS + BAD_IDS)
def test_one_id_grammar_everywhere(pid):
    """The catalog's check, the books' split and the problem schema's pattern accept and
    refuse the same ids (before, catalog took '_' in a book and '..'-free runs of
    separators that books then refused: two messages for one mistake)."""
    import re

    from mechbook.model.catalog import check_id
    from mechbook.model.schema import bundled

    good = pid in GOOD_IDS
    pattern = bundled("problem")["properties"]["id"]["pattern"]
    assert bool(re.search(pattern, pid)) == good
    for check in (check_id, split_id):
        if good:
            check(pid)
        else:
            with pytest.raises(MechbookError, match="bad problem id"):
                check(pid)
