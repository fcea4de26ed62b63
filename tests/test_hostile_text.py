"""Issue 21, text: a NUL, a lone surrogate or a control character in a problem or answer
file is refused at `validate` time with file:line (it used to pass, then crash `check`'s
HDF5 write, `list` and the JUnit XML); the problems after it are still checked; and every
output (HDF5, JSON, JUnit, terminal) is safe for any string, valid or not."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import pytest
from hostile import check, pendulum_tree, run

import mechbook.app.store as store
from mechbook.app.output.formats import junit_xml, to_json
from mechbook.app.output.text import for_terminal, for_xml, json_safe, storable
from mechbook.app.running.run import ProblemRun
from mechbook.records import Outcome, Results

# (what the YAML file holds, in a double-quoted string; what the message names)
BAD = [
    ("bead\\0hoop", "U+0000 (NUL)"),
    ("\\ud800", "lone surrogate U+D800"),
    ("red \\x1b[31malert", "U+001B (escape)"),
    ("a\\rb", "U+000D (carriage return)"),
    ("bell\\a", "U+0007"),
    ("c1 \\x85 next line", "U+0085"),
    ("\\x7f", "U+007F (delete)"),
    ("\\uffff", "noncharacter U+FFFF"),
]


@pytest.mark.parametrize("text, named", BAD)
@pytest.mark.parametrize("where", ["title", "cite", "doc"])
def test_bad_text_is_refused_at_validate_with_its_line(tmp_path, text, named, where):
    base = pendulum_tree(tmp_path, title=f'"{text}"' if where == "title" else "a title",
                         cite=f'"{text}"' if where == "cite" else "test")
    target = base / ("answers" if where == "cite" else "problems") / "lim" / "2101.yaml"
    if where == "doc":
        target.write_text(target.read_text().replace("  m: {value: 1.5}",
                                                     f'  m: {{value: 1.5, doc: "{text}"}}'))
    line = next(i for i, ln in enumerate(target.read_text().splitlines(), 1) if text in ln)
    result = run("validate", target)
    assert result.exit_code == 1
    assert f"{target}:{line}: " in result.stderr
    assert named in result.stderr and "remove it" in result.stderr
    assert "Traceback" not in result.output and result.exception is None or \
        isinstance(result.exception, SystemExit)


def test_one_bad_title_does_not_stop_the_run(tmp_path):
    """The issue: `title: "bead\\0hoop"` crashed check's HDF5 write and the problems queued
    after it were never checked. Now it is refused with its line, nothing is stored for it,
    and the others are checked and stored."""
    base = pendulum_tree(tmp_path, nums=("2101", "2102", "2103"))
    bad = base / "problems" / "lim" / "2102.yaml"
    bad.write_text(bad.read_text().replace("title: a test pendulum", 'title: "bead\\0hoop"'))
    path = tmp_path / "s.h5"
    result = check(base, "--store", path)
    assert result.exit_code == 1  # a problem could not be checked
    assert f"{bad}:3: text holds the control character U+0000 (NUL)" in result.stdout
    assert store.problems(path) == ["lim-2101", "lim-2103"]
    listed = run("--root", base, "list")
    assert listed.exit_code == 1 and "INVALID" in listed.stdout and "\0" not in listed.stdout


def test_a_surrogate_title_no_longer_crashes_list_or_report(tmp_path):
    base = pendulum_tree(tmp_path, nums=("2101", "2102"))
    bad = base / "problems" / "lim" / "2101.yaml"
    bad.write_text(bad.read_text().replace("title: a test pendulum", 'title: "\\ud800"'))
    listed = run("--root", base, "list")
    assert listed.exit_code == 1, listed.output
    assert "lone surrogate U+D800" in listed.stdout
    out = tmp_path / "report"
    result = run("--root", base, "report", "--serial", "--no-simulate", "--simplify-seconds",
                 "0", "--out", out)
    assert result.exit_code == 0, result.output
    page = (out / "problems" / "lim-2101.html").read_text(encoding="utf-8")
    assert "lone surrogate" in page  # the page says why it could not be built


def test_fullwidth_and_ligature_letters_are_not_folded_silently(tmp_path):
    base = pendulum_tree(tmp_path, mass="ｍ")
    result = run("validate", base / "problems" / "lim" / "2101.yaml")
    assert result.exit_code == 1
    assert "character 'ｍ' (U+FF4D) at column 1 would be read as 'm'" in result.stderr


@pytest.mark.parametrize("literal", ["0x" + "f" * 300, "0o" + "7" * 300, "0b" + "1" * 400,
                                     "0x" + "f" * 90])
def test_long_hex_octal_binary_literals_are_refused_not_a_traceback(tmp_path, literal):
    """The issue: a hex literal of a few hundred digits raised OverflowError and `list`
    stopped."""
    base = pendulum_tree(tmp_path, nums=("2101", "2102"))
    bad = base / "problems" / "lim" / "2101.yaml"
    bad.write_text(bad.read_text().replace("  l: {value: 0.5}", f"  l: {{value: {literal}}}"))
    result = run("validate", bad)
    assert result.exit_code == 1 and f"{bad}:6:" in result.stderr, result.output
    listed = run("--root", base, "list")
    assert listed.exit_code == 1
    assert "lim-2102" in listed.stdout and "INVALID" in listed.stdout


# ---- every output is safe for any string --------------------------------------------------
HOSTILE = ["bead\0hoop", "\ud800 lone", "\x1b[2J\x1b[31mred", "a\rb", "\x85\x9b",
           "\u202eevil", "\ufffe", "ok: ω² = k/m"]


def _run_with(text: str) -> ProblemRun:
    outcome = Outcome("lim-2101", "a", "eom", text, "fail", "numeric", text, 0.1)
    return ProblemRun("lim-2101", [outcome], notes=[text])


@pytest.mark.parametrize("text", HOSTILE)
def test_hdf5_keeps_any_string(tmp_path, text):
    from test_store import make_record

    rec = make_record(tmp_path)
    rec.title = rec.source = text
    rec.outcomes[0].cite = rec.outcomes[0].detail = text
    rec.results = [Results("main", {"x": text}, {}, {"n": text})]
    path = store.write([rec], tmp_path / "s.h5")
    got = store.read("lim-2031", path)
    assert got["attrs"]["title"] == storable(text)
    assert storable(text) == text or "\\" in storable(text)
    with h5py.File(path) as f:
        assert f["problems/lim-2031"].attrs["title"] == storable(text)


@pytest.mark.parametrize("text", HOSTILE)
def test_json_and_junit_are_well_formed_for_any_string(tmp_path, text):
    runs = [_run_with(text)]
    doc = json_safe(to_json(runs, tmp_path, None))
    encoded = json.dumps(doc, ensure_ascii=False).encode("utf-8")  # no surrogate left
    assert json.loads(encoded)["problems"][0]["parts"][0]["cite"] == json_safe(text)
    xml = tmp_path / "out.xml"
    junit_xml(runs).write(xml, encoding="utf-8", xml_declaration=True)
    root = ET.parse(xml).getroot()  # a malformed document raises here
    failure = root.find("testsuite/testcase/failure")
    assert failure is not None and failure.get("message") == for_xml(text)


@pytest.mark.parametrize("text", HOSTILE)
def test_the_terminal_never_gets_a_control_character(text):
    shown = for_terminal(text)
    assert not any(ord(c) < 32 and c not in "\t\n" or 0x7F <= ord(c) <= 0x9F or
                   0x202A <= ord(c) <= 0x202E or 0xD800 <= ord(c) <= 0xDFFF for c in shown)


def test_show_escapes_what_an_old_store_holds(tmp_path):
    """A store written before the text checks (or by hand) with an escape sequence in a
    detail: `show` prints it as an escape, never sends it to the terminal."""
    from test_store import make_record

    path = store.write([make_record(tmp_path)], tmp_path / "s.h5")
    with h5py.File(path, "r+") as f:
        f["problems/lim-2031/checks/a"].attrs["detail"] = "\x1b]0;pwned\x07\x1b[2J gone"
        f["problems/lim-2031"].attrs["title"] = "\x1b[31mred"
    result = run("show", "lim-2031", "--store", path)
    assert result.exit_code == 0, result.output
    assert "\x1b" not in result.output and "\x07" not in result.output
    assert "\\x1b]0;pwned\\x07\\x1b[2J gone" in result.output


def test_committed_files_hold_only_valid_text():
    """The text rule refuses nothing the book's files hold (every committed file loads)."""
    from mechbook.model.yamlio import load

    root = Path(__file__).resolve().parents[1]
    for path in sorted((root / "problems").glob("*/*.yaml")) + \
            sorted((root / "answers").glob("*/*.yaml")):
        load(path)
