"""The fast reading (libyaml) gives exactly what the round-trip parser gives, or gives up.

Every committed file, a list of scalars on which YAML 1.1 and 1.2 disagree, and 300
mutated and hostile files from the fuzzer are read both ways: the data (values and their
types) or the error message must be the same.
"""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from mechbook.errors import SpecError
from mechbook.model import yamlio
from mechbook.model.fastyaml import fast_data
from mechbook.model.input_limits import check_events

ROOT = Path(__file__).resolve().parents[1]


def _typed(x):
    if isinstance(x, dict):
        return {k: _typed(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_typed(v) for v in x]
    if x is None or isinstance(x, bool):
        return x
    if isinstance(x, int):
        return ("int", int(x))
    if isinstance(x, float):
        return ("float", float(x))
    return ("str", str(x))


def _old(text: str):
    """The round-trip parser alone: what every file went through before."""
    try:
        raw = yamlio._round_trip(text, "f.yaml")
        if raw is None:
            raise SpecError("file is empty", "f.yaml", 1)
        return _typed(yamlio.Document(raw, "f.yaml").data)
    except SpecError as exc:
        return ("error", str(exc))


def _new(text: str):
    try:
        return _typed(yamlio.loads(text, "f.yaml").data)
    except SpecError as exc:
        return ("error", str(exc))


@pytest.mark.slow
def test_every_committed_file_is_read_fast_and_the_same():
    files = [*sorted(ROOT.glob("problems/*/*.yaml")), *sorted(ROOT.glob("answers/*/*.yaml")),
             ROOT / "books.yaml"]
    assert len(files) > 300
    for path in files:
        text = path.read_text("utf-8")
        fast = fast_data(text, str(path), check_events)
        assert fast is not None, f"{path}: the fast reading gave up"
        assert _typed(fast) == _old(text), path


SCALARS = ["0", "-0", "+5", "017", "0o17", "0x1F", "0b101", "1_000", "1.", ".5", ".5e3",
           ".5e+3", "1e5", "1E-5", "-2.5e-3", "+.inf", ".NaN", "1:30", "1:30.5", "yes", "no",
           "on", "Off", "y", "n", "true", "False", "TRUE", "~", "null", "Null", "NULL", "",
           "2020-01-01", "2001-12-14t21:59:43.10-05:00", "<<", "=", "m*g*l", "-m*g*l",
           "2*pi", "0.5*m*l**2", "1e400", "9" * 120, "x: y", "- a", "'q'", '"q\\tx"']


@pytest.mark.parametrize("scalar", SCALARS)
def test_scalars_where_the_parsers_might_disagree(scalar):
    for text in (f"a: {scalar}\n", f"- {scalar}\n", f"{scalar}: 1\n", f"a: [{scalar}, 2]\n"):
        assert _new(text) == _old(text), text


def test_duplicate_keys_merge_keys_and_directives_take_the_round_trip_path():
    for text in ("a: 1\na: 2\n", "a: &x {b: 1}\nc: *x\n", "<<: {b: 1}\n",
                 "%YAML 1.1\n---\na: yes\n", "a: !!binary aGVsbG8=\n", "a: 1\n---\nb: 2\n",
                 "a:\n\tb: 1\n", "a: [1, 2\n", "a: \x07\n"):
        assert fast_data(text, "f.yaml", check_events) is None, text
        assert _new(text) == _old(text), text
    for text in ("\ufeffa: 1\n", "a: 1\r\nb: 2\r\n", "a: 'it''s'\n", "a: >\n  x\n  y\n"):
        assert _new(text) == _old(text), text


def test_lines_are_found_when_an_error_needs_them():
    doc = yamlio.loads("a: 1\nb:\n  c: [1, 2]\n  d:\n    - x\n    - y\n", "f.yaml")
    assert doc._raw is None  # read by libyaml: no round-trip nodes yet
    assert doc.line(("b", "d", 1)) == 6 and doc.line(("b", "c")) == 3
    err = doc.error(("b", "d"), "bad")
    assert err.line == 4 and str(err).startswith("f.yaml:4: b/d: bad")


@pytest.mark.slow
def test_mutated_and_hostile_files_read_the_same_both_ways():
    import fuzz

    pool = fuzz.seeds(ROOT)
    kinds = ["text", "structure", "hostile", "counts", "strings"]
    compared = 0
    for index in range(300):
        case = fuzz.generate(index, 20260523, pool, kinds)
        text = case.files.get(case.target)
        if case.special or text is None:
            continue
        if isinstance(text, bytes):
            try:
                text = text.decode("utf-8")
            except UnicodeDecodeError:
                continue
        if len(text) > yamlio.MAX_FILE_BYTES:
            continue
        assert _new(text) == _old(text), (index, case.kind, text[:300])
        compared += 1
    assert compared > 220


def test_a_text_mutation_is_read_the_same(tmp_path):
    """A smaller, seeded sweep of single-character edits around YAML's syntax."""
    rng = random.Random(5)
    base = (ROOT / "problems" / "lim" / "2031.yaml").read_text("utf-8")
    chars = list(":{}[],&*!|>'\"#%@`-? \t\n0.e+_")
    for _ in range(150):
        text = list(base)
        for _ in range(rng.randint(1, 3)):
            text.insert(rng.randrange(len(text)), rng.choice(chars))
        text = "".join(text)
        assert _new(text) == _old(text), text
