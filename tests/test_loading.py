"""Loading and validating problem files: duplicate and unknown keys, hostile expressions,
and errors that name the file and the line."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import pytest
from click.testing import CliRunner

from mechbook.app.cli import main
from mechbook.errors import SpecError
from mechbook.model.problem import load_problem
from mechbook.model.system import system_of
from mechbook.model.yamlio import loads

PWNED = Path("/tmp/pwned")

HEADER = """\
id: lim-{num}
source: a test problem
title: a test pendulum
"""

PENDULUM = HEADER + """\
parameters:
  m: {{value: 1.5}}
  l: {{value: 0.5}}
  g: {{}}
coordinates:
  theta: {{}}
particles:
  bob:
    mass: m
    position: [l*sin(theta), -l*cos(theta)]
gravity: {{}}
"""


def write(tmp_path: Path, text: str, num: str = "2031") -> Path:
    path = tmp_path / f"{num}.yaml"
    path.write_text(textwrap.dedent(text).format(num=num), encoding="utf-8")
    return path


def line_of(path: Path, needle: str) -> int:
    for i, line in enumerate(path.read_text().splitlines(), 1):
        if needle in line:
            return i
    raise AssertionError(f"{needle!r} not in {path}")


def test_good_file_loads(tmp_path):
    path = write(tmp_path, PENDULUM)
    problem = load_problem(path)
    assert problem.id == "lim-2031"
    assert set(problem.parameters) == {"m", "l", "g"}
    assert problem.parameters["g"].value == pytest.approx(9.81)
    assert problem.parameters["m"].value == 1.5
    assert system_of(problem).coord_names == ["theta"]


def test_duplicate_key_is_rejected_with_its_line(tmp_path):
    text = PENDULUM.replace("  l: {{value: 0.5}}\n", "  l: {{value: 0.5}}\n  m: {{value: 2}}\n")
    path = write(tmp_path, text)
    with pytest.raises(SpecError) as info:
        load_problem(path)
    err = info.value
    assert "duplicate key" in str(err)
    assert '"m"' in str(err) or "'m'" in str(err)
    assert err.file == str(path)
    assert err.line == line_of(path, "m: {value: 2}")
    assert f"{path}:{err.line}" in str(err)


def test_duplicate_top_level_key(tmp_path):
    path = write(tmp_path, PENDULUM + "gravity: {{g: 3}}\n")
    with pytest.raises(SpecError, match="duplicate key") as info:
        load_problem(path)
    assert info.value.line == line_of(path, "gravity: {g: 3}")


def test_unknown_key_is_rejected_naming_file_and_line(tmp_path):
    path = write(tmp_path, PENDULUM + "frobnicate: 3\n")
    with pytest.raises(SpecError) as info:
        load_problem(path)
    err = info.value
    assert "frobnicate" in str(err)
    assert "unknown key" in str(err)
    assert err.file == str(path)
    assert isinstance(err.line, int) and err.line >= 1
    assert str(err).startswith(f"{path}:{err.line}:")


def test_nested_unknown_key_names_its_mapping(tmp_path):
    text = PENDULUM.replace("    mass: m\n", "    mass: m\n    colour: red\n")
    path = write(tmp_path, text)
    with pytest.raises(SpecError) as info:
        load_problem(path)
    err = info.value
    assert "colour" in str(err) and "particles/bob" in str(err)
    # the line is the one of the mapping holding the key, or the key itself
    assert err.line in (line_of(path, "bob:"), line_of(path, "colour: red"))


def test_unknown_key_error_names_the_key_line(tmp_path):
    path = write(tmp_path, PENDULUM + "frobnicate: 3\n")
    with pytest.raises(SpecError) as info:
        load_problem(path)
    assert info.value.line == line_of(path, "frobnicate")


def test_missing_required_key(tmp_path):
    path = write(tmp_path, PENDULUM.replace("title: a test pendulum\n", ""))
    with pytest.raises(SpecError, match="'title' is required"):
        load_problem(path)


def test_id_must_match_file_name(tmp_path):
    path = write(tmp_path, PENDULUM)
    other = tmp_path / "2032.yaml"
    path.rename(other)
    with pytest.raises(SpecError, match="does not match the file name") as info:
        load_problem(other)
    assert info.value.line == 1


def test_yaml_syntax_error_has_line(tmp_path):
    path = write(tmp_path, PENDULUM + "kinetic: [unclosed\n")
    with pytest.raises(SpecError, match="YAML syntax error") as info:
        load_problem(path)
    assert info.value.line is not None


def test_empty_file(tmp_path):
    path = tmp_path / "2031.yaml"
    path.write_text("", encoding="utf-8")
    with pytest.raises(SpecError, match="empty"):
        load_problem(path)


def test_loads_tracks_lines():
    doc = loads("a: 1\nb:\n  c: [1, 2]\n  d:\n    - x\n    - y\n")
    assert doc.data == {"a": 1, "b": {"c": [1, 2], "d": ["x", "y"]}}
    assert doc.line(("a",)) == 1
    assert doc.line(("b", "c")) == 3
    assert doc.line(("b", "d", 1)) == 6


# ---- hostile expressions in a problem file --------------------------------------------------
HOSTILE = "__import__('os').system('touch {target}')"

HOSTILE_PROBLEM = HEADER + """\
parameters:
  m: {{value: 1.0}}
coordinates:
  theta: {{}}
kinetic: "{payload}"
"""


def hostile_file(tmp_path: Path, target: Path) -> Path:
    text = HOSTILE_PROBLEM.replace("{payload}", HOSTILE.replace("{target}", str(target)))
    return write(tmp_path, text)


@pytest.fixture
def no_pwned():
    """Fails a test that creates /tmp/pwned (skipped as a check if it already existed)."""
    existed = PWNED.exists()
    yield
    if not existed:
        assert not PWNED.exists(), "the hostile expression was executed"


@pytest.mark.parametrize("target", ["/tmp/pwned", "TMP"])
def test_hostile_kinetic_rejected_by_loader(tmp_path, no_pwned, target):
    marker = tmp_path / "pwned"
    target_path = marker if target == "TMP" else Path(target)
    path = hostile_file(tmp_path, target_path)
    problem = load_problem(path)  # schema-valid: an expression is only a string here
    with pytest.raises(SpecError) as info:
        system_of(problem)
    err = info.value
    assert err.file == str(path)
    assert err.line == line_of(path, "kinetic:")
    assert "kinetic" in str(err)
    assert "whitelisted" in str(err) or "not allowed" in str(err)
    assert not marker.exists()


def test_hostile_kinetic_rejected_by_cli_validate(tmp_path, no_pwned):
    marker = tmp_path / "pwned"
    for target in (PWNED, marker):
        path = hostile_file(tmp_path, target)
        result = CliRunner().invoke(main, ["validate", str(path)])
        assert result.exit_code != 0
        assert result.exception is None or isinstance(result.exception, SystemExit), \
            result.exception
        assert "invalid" in result.output
        assert f"{path}:{line_of(path, 'kinetic:')}" in result.output
        assert "kinetic" in result.output
        assert not marker.exists()


@pytest.mark.parametrize("where, payload", [
    ("potential", "m*foo(theta)"),
    ("potential", "theta.__class__"),
    ("mass", "m + os"),
    ("position", "l*sin(theta"),
    ("gravity", "2**10**9"),
])
def test_bad_expression_names_its_line(tmp_path, where, payload):
    text = PENDULUM
    if where == "potential":
        text += f'potential: "{payload}"\n'
        needle = "potential:"
    elif where == "mass":
        text = text.replace("    mass: m\n", f'    mass: "{payload}"\n')
        needle = "mass:"
    elif where == "position":
        text = text.replace("    position: [l*sin(theta), -l*cos(theta)]\n",
                            "    position:\n      - l*sin(theta)\n"
                            f'      - "{payload}"\n')
        needle = f'- "{payload}"'
    else:
        text = text.replace("gravity: {{}}\n", f'gravity:\n  g: "{payload}"\n')
        needle = f'g: "{payload}"'
    path = write(tmp_path, text)
    with pytest.raises(SpecError) as info:
        system_of(load_problem(path))
    err = info.value
    assert err.line == line_of(path, needle), str(err)
    assert err.file == str(path)
    assert payload in str(err)


def test_reserved_name_as_parameter(tmp_path):
    text = PENDULUM.replace("  g: {{}}\n", "  g: {{}}\n  sin: {{value: 1}}\n")
    path = write(tmp_path, text)
    with pytest.raises(SpecError, match="reserved") as info:
        load_problem(path)
    assert info.value.line == line_of(path, "sin: {value: 1}")


def test_coordinate_name_clash(tmp_path):
    text = PENDULUM.replace("  theta: {{}}\n", "  theta: {{}}\n  m: {{}}\n")
    path = write(tmp_path, text)
    with pytest.raises(SpecError, match="already taken") as info:
        system_of(load_problem(path))
    assert info.value.line == line_of(path, "  m: {}")


def test_cli_validate_good_file(tmp_path):
    path = write(tmp_path, PENDULUM)
    result = CliRunner().invoke(main, ["validate", str(path)])
    assert result.exit_code == 0, result.output
    assert "lim-2031 is valid" in result.output


def test_overflowing_literal_in_file_is_a_spec_error(tmp_path):
    path = write(tmp_path, PENDULUM + 'potential: "m*1e400*theta"\n')
    with pytest.raises(SpecError) as info:
        system_of(load_problem(path))
    assert info.value.line == line_of(path, "potential:")
    result = CliRunner().invoke(main, ["validate", str(path)])
    assert result.exit_code == 1
    assert isinstance(result.exception, SystemExit)


HOSTILE_KEY = """\
problem: lim-2031
source: a hostile answer key
parts:
  - part: a
    cite: test
    quantity: lagrangian
    book: "__import__('os').system('touch {target}')"
  - part: b
    cite: test
    quantity: eom
    book:
      - "thetaddot = 0"
      - "theta.__class__ = 0"
"""


def test_hostile_answer_key_rejected(tmp_path, no_pwned):
    root = Path(__file__).resolve().parents[1]
    marker = tmp_path / "pwned"
    (tmp_path / "problems" / "lim").mkdir(parents=True)
    (tmp_path / "answers" / "lim").mkdir(parents=True)
    (tmp_path / "problems" / "lim" / "2031.yaml").write_text(
        (root / "problems" / "lim" / "2031.yaml").read_text())
    key = tmp_path / "answers" / "lim" / "2031.yaml"
    key.write_text(HOSTILE_KEY.replace("{target}", str(marker)))
    result = CliRunner().invoke(main, ["validate", str(key)])
    assert result.exit_code == 1
    assert f"{key}:{line_of(key, 'book: ')}" in result.output
    result = CliRunner().invoke(main, ["--root", str(tmp_path), "check", "lim-2031",
                                       "--no-store", "--format", "json"])
    assert result.exit_code == 1
    # the JSON document alone (click < 8.2's runner mixes the progress lines of stderr in)
    text = result.stdout
    (problem,) = json.loads(text[text.index("{"): text.rindex("}") + 1])["problems"]
    parts = {p["part"]: p for p in problem["parts"]}
    assert parts["a"]["status"] == "error"
    assert f"{key}:{line_of(key, 'book: ')}" in parts["a"]["detail"]
    assert parts["b"]["status"] == "error"
    assert f"{key}:{line_of(key, '__class__')}" in parts["b"]["detail"]
    assert not marker.exists()
