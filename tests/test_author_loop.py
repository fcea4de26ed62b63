"""The author's loop (issue 23): errors that say how to fix, an answer key's names resolved
by `validate`, warnings as notes and never on the terminal, `mechbook init`, the "no
problems/" message, and results that display as mathematics in a notebook."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from mechbook.app.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _tree(tmp: Path, problem_edit=None, answer_edit=None) -> tuple[Path, Path]:
    """A scratch tree with lim-2031, its files edited by the given functions of their text."""
    shutil.copy(ROOT / "books.yaml", tmp / "books.yaml")
    out = []
    for kind, edit in (("problems", problem_edit), ("answers", answer_edit)):
        dest = tmp / kind / "lim" / "2031.yaml"
        dest.parent.mkdir(parents=True, exist_ok=True)
        text = (ROOT / kind / "lim" / "2031.yaml").read_text("utf-8")
        dest.write_text(edit(text) if edit else text, "utf-8")
        out.append(dest)
    return out[0], out[1]


def _validate(*paths: Path):
    return CliRunner().invoke(main, ["validate", *map(str, paths)])


def _line(path: Path, needle: str) -> int:
    for i, line in enumerate(path.read_text("utf-8").splitlines(), 1):
        if needle in line:
            return i
    raise AssertionError(needle)


def test_an_unknown_quantity_names_the_nearest(tmp_path):
    _, key = _tree(tmp_path, answer_edit=lambda t: t.replace("quantity: frequencies",
                                                              "quantity: frequency"))
    res = _validate(key)
    assert res.exit_code == 1
    assert "did you mean 'frequencies'" in res.output
    assert f"{key}:{_line(key, 'quantity: frequency')}" in res.output
    assert "'characteristic_polynomial'" not in res.output  # not all 51 listed


def test_a_caret_is_told_to_be_a_double_star(tmp_path):
    _, key = _tree(tmp_path, answer_edit=lambda t: t.replace("1 - g**2/", "1 - g^2/"))
    res = _validate(key)
    assert res.exit_code == 1 and "write '**'" in res.output and "^" in res.output
    assert f"{key}:{_line(key, 'omega*sqrt(1 - g^2')}" in res.output


def test_indentation_mistakes_say_indentation(tmp_path):
    cases = {
        "under": lambda t: t.replace("\n  m: {doc", "\nm: {doc"),
        "over": lambda t: t.replace("\n  m: {doc", "\n    m: {doc"),
        "all-under": lambda t: t.replace("\n  m: {doc", "\nm: {doc")
                                .replace("\n  b: {doc", "\nb: {doc")
                                .replace("\n  omega: {doc", "\nomega: {doc")
                                .replace("\n  g: {doc", "\ng: {doc"),
        "scalar": lambda t: t.replace(
            "coordinates:\n  theta: {doc: angle of the bead from the upward vertical "
            "through the hoop centre}", "coordinates: theta"),
    }
    for name, edit in cases.items():
        sub = tmp_path / name
        sub.mkdir()
        problem, _ = _tree(sub, problem_edit=edit)
        res = _validate(problem)
        assert res.exit_code == 1, (name, res.output)
        assert "indent" in res.output, (name, res.output)
        assert f"{problem}:" in res.output and "Traceback" not in res.output


def test_unknown_names_functions_and_keys_name_the_nearest(tmp_path):
    for name, edit, needle in (
            ("name", lambda t: t.replace("b*cos(theta)]", "b*cos(thetta)]"),
             "did you mean 'theta'?"),
            ("function", lambda t: t.replace("b*cos(theta)]", "b*coss(theta)]"),
             "did you mean 'cos'?"),
            ("key", lambda t: t.replace("gravity: {}", "gravty: {}"),
             "did you mean 'gravity'?")):
        sub = tmp_path / name
        sub.mkdir()
        problem, _ = _tree(sub, problem_edit=edit)
        res = _validate(problem)
        assert res.exit_code == 1 and needle in res.output, (name, res.output)


def test_validate_refuses_a_name_the_problem_does_not_declare(tmp_path):
    """`about: {rr: 0}` named no coordinate and used to be reported valid."""
    _, key = _tree(tmp_path, answer_edit=lambda t: t.replace(
        "quantity: stability_condition\n    about: {theta: pi}",
        "quantity: stability_condition\n    about: {rr: 0}"))
    res = _validate(key)
    assert res.exit_code == 1, res.output
    assert f"{key}:{_line(key, 'about: {rr: 0}')}" in res.output
    assert "'rr' is not a coordinate" in res.output and "theta" in res.output
    for edit, needle in ((lambda t: t.replace("about: {theta: pi}\n    define: {alpha",
                                              "about: {thetaa: pi}\n    define: {alpha"),
                          "did you mean 'theta'?"),
                         (lambda t: t.replace("define: {alpha: theta - pi}",
                                              "define: {omega: theta - pi}"),
                          "'omega' is already a name")):
        sub = tmp_path / str(abs(hash(needle)))
        sub.mkdir()
        _, key = _tree(sub, answer_edit=edit)
        res = _validate(key)
        assert res.exit_code == 1 and needle in res.output, res.output


@pytest.mark.slow
def test_every_committed_answer_key_resolves_its_names():
    from mechbook.app.authoring.validate import validate_file

    for key in sorted(ROOT.glob("answers/*/*.yaml")):
        assert "is valid" in validate_file(key), key


def test_a_broken_problem_is_reported_once(tmp_path):
    problem, key = _tree(tmp_path, problem_edit=lambda t: t.replace("b*cos(theta)]",
                                                                    "b*cos(thetta)]"))
    res = _validate(problem, key)
    assert res.output.count("did you mean 'theta'") == 1, res.output
    assert "its problem file" in res.output and "is invalid (above)" in res.output


def test_warnings_become_notes_and_never_reach_the_terminal(tmp_path, monkeypatch):
    """A NumPy overflow and a SymPy-style deprecation inside a part's check become notes
    of the problem naming the part (in the JSON), and nothing reaches stderr."""
    import warnings

    import numpy as np

    import mechbook.verify.checker as checker

    real = checker.check_part

    def noisy(analysis, part, *args, **kwargs):
        np.exp(np.array([1000.0]))  # RuntimeWarning: overflow encountered in exp
        warnings.warn("this call is deprecated", DeprecationWarning, stacklevel=1)
        return real(analysis, part, *args, **kwargs)

    monkeypatch.setattr(checker, "check_part", noisy)
    _tree(tmp_path)
    try:  # click 8.1 mixes stderr into the output unless told not to; 8.2 keeps it apart
        runner = CliRunner(mix_stderr=False)
    except TypeError:
        runner = CliRunner()
    res = runner.invoke(main, ["--root", str(tmp_path), "check", "lim-2031", "--serial",
                                    "--no-store", "--no-crosscheck", "--format", "json"])
    assert res.exit_code == 0, res.output
    assert "Warning" not in res.stderr, res.stderr
    (entry,) = json.loads(res.stdout)["problems"]
    notes = " | ".join(entry["notes"])
    assert "RuntimeWarning in test_author_loop: overflow encountered in exp" in notes, notes
    assert "DeprecationWarning in test_author_loop: this call is deprecated" in notes
    assert "part a-lagrangian (lagrangian)" in notes  # the stage: which part


def test_outside_a_tree_the_message_names_root_and_init(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("MECHBOOK_ROOT", raising=False)
    res = CliRunner().invoke(main, ["list"])
    assert res.exit_code == 1
    assert "--root" in res.output and "mechbook init" in res.output


def test_init_starts_a_tree_that_check_passes(tmp_path):
    target = tmp_path / "mine"
    res = CliRunner().invoke(main, ["init", str(target)])
    assert res.exit_code == 0, res.output
    for rel in ("books.yaml", "problems/mybook/1.1.yaml", "answers/mybook/1.1.yaml",
                "Makefile"):
        assert (target / rel).is_file(), rel
    checked = CliRunner().invoke(main, ["--root", str(target), "check", "--serial"])
    assert checked.exit_code == 0, checked.output
    assert "3 parts: 3 pass" in checked.output
    again = CliRunner().invoke(main, ["init", str(target)])
    assert again.exit_code == 1 and "exists already" in again.output


def test_results_display_as_mathematics_in_a_notebook():
    import mechbook

    p = mechbook.load("lim-2031", ROOT)
    eom = p.eom
    assert isinstance(eom, list) and len(eom) == 1
    assert r"\ddot{\theta}" in eom._repr_latex_() and "<math" in eom._repr_html_()
    freqs = p.frequencies(about={"theta": "acos(-g/(b*omega**2))"})
    assert isinstance(freqs, list) and r"\sqrt" in freqs._repr_latex_()
    momenta = p.momenta
    assert isinstance(momenta, dict) and r"p_{\theta}" in momenta._repr_latex_()
    assert p.equilibria[0] == {p.system().coordinates[0]: 0}
    assert "<math" in p.equilibria._repr_html_()
