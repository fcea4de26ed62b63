"""The checker's power: small wrong answers fail.

Relations are decided at their boundary (a 1 % move, and a 1e-6 move, of every relation in
both books fails; a sleeping top whose threshold has 3 for 4 fails); a conserved quantity the
book names is compared with the engine's own, so a constant factor fails; the sensitivity
mutants (mechbook.verify.mutate) are what the text says; a pass states its power."""

from __future__ import annotations

import copy
import re
from fractions import Fraction
from pathlib import Path

import pytest
from mutation_keys import per_key
from ruamel.yaml import YAML

from mechbook.engine.analysis import Analysis
from mechbook.model.catalog import problem_path
from mechbook.model.problem import load_problem
from mechbook.verify.answers import Part, load_answers
from mechbook.verify.checker import check_part, check_problem
from mechbook.verify.context import Context
from mechbook.verify.mutate import COUNTS, part_mutants, shift_sizes, shifted, text_mutants
from mechbook.verify.power import same_meaning

ROOT = Path(__file__).resolve().parents[1]
RELATION_QUANTITIES = ("stability_condition", "steady_exists", "stability")


def _relation_parts() -> list[tuple[Path, str]]:
    out = []
    for f in sorted((ROOT / "answers").glob("*/*.yaml")):
        data = YAML(typ="safe").load(f.read_text())
        for p in data["parts"]:
            value = (p.get("erratum") or {}).get("corrected", p.get("book"))
            if p["quantity"] in RELATION_QUANTITIES and isinstance(value, str) \
                    and re.search(r"[<>]", value) and "unsupported" not in p:
                out.append((f, p["part"]))
    return out


RELATIONS = _relation_parts()
ANSWER_FILES = sorted((ROOT / "answers").glob("*/*.yaml"))
_ANALYSES: dict = {}


def _load(answer_file: Path):
    key = load_answers(answer_file)
    if key.problem_id not in _ANALYSES:
        _ANALYSES[key.problem_id] = Analysis(load_problem(problem_path(key.problem_id, ROOT)))
    return key, _ANALYSES[key.problem_id]


def _moved(text: str, names: set[str], delta: Fraction) -> str:
    """The relation with its first parameter p replaced by (1 + δ)·p."""
    for kind, _, new, _ in text_mutants(text, names, delta):
        if kind == "parameter":
            return new
    raise AssertionError(f"no parameter in {text!r}")


def test_every_relation_of_both_books_is_found():
    assert len(RELATIONS) >= 15, RELATIONS


_ORIGINALS: dict = {}


def _original(answer_file: Path, part):
    """The part's own outcome, checked once per test process: both moves of a relation
    judge against it (the vibrating pivot's took ~9 s each time on a loaded machine)."""
    slot = (answer_file, part.name)
    if slot not in _ORIGINALS:
        _ORIGINALS[slot] = check_part(_load(answer_file)[1], part)
    return _ORIGINALS[slot]


# delta varies fastest: a relation's two moves are neighbours in the collection, and xdist
# hands out neighbours together, so the second finds the original outcome checked
@pytest.mark.slow
@pytest.mark.parametrize("delta", [Fraction(1, 100), Fraction(1, 10**6)], ids=["1e-2", "1e-6"])
@pytest.mark.parametrize("answer_file, name", RELATIONS,
                         ids=[f"{f.stem}-{n}" for f, n in RELATIONS])
def test_a_moved_boundary_fails(answer_file: Path, name: str, delta: Fraction):
    key, analysis = _load(answer_file)
    part = next(p for p in key.parts if p.name == name)
    names = set(analysis.problem.parameters) | set(key.symbols) | set(
        key.doc.data.get("abbreviations") or {})
    original = _original(answer_file, part)
    assert original.status in ("pass", "erratum"), original.detail
    assert "boundary" in original.power, original.power
    data = copy.deepcopy(part.data)
    if "erratum" in data:  # the corrected relation passes; moved, the part is no erratum
        data["erratum"]["corrected"] = _moved(data["erratum"]["corrected"], names, delta)
    else:
        data["book"] = _moved(data["book"], names, delta)
    got = check_part(analysis, Part(key, part.index, data))
    assert got.status == "fail", (got.status, got.detail)


# ---- a top outside the books: the sleeping top's threshold -------------------------------
TOP = """\
id: lim-9001
source: test
title: a symmetric top on a fixed point, in a tilt chart
parameters:
  M: {value: 1.3}
  h: {value: 0.2}
  A: {value: 0.011}
  C: {value: 0.017}
  g: {}
coordinates:
  a: {}
  b: {}
  c: {}
rigid_bodies:
  top:
    mass: M
    position: [h*sin(b), -h*sin(a)*cos(b), h*cos(a)*cos(b)]
    inertia: [[A, 0, 0], [0, A, 0], [0, 0, C]]
    rotation: [[x, a], [y, b], [z, c]]
gravity: {}
"""


@pytest.fixture(scope="module")
def top(tmp_path_factory) -> Analysis:
    d = tmp_path_factory.mktemp("top") / "problems" / "lim"
    d.mkdir(parents=True)
    (d / "9001.yaml").write_text(TOP)
    return Analysis(load_problem(d / "9001.yaml"))


def _check_top(top: Analysis, tmp_path: Path, book: str) -> tuple[str, str, str]:
    doc = {"problem": "lim-9001", "source": "test", "parts": [{
        "part": "sleeping", "cite": "test", "quantity": "stability_condition",
        "steady": {"c": "omega3"}, "about": {"a": 0, "b": 0}, "book": book}],
        "symbols": {"omega3": {"value": 20}}}
    path = tmp_path / "key.yaml"
    YAML().dump(doc, path.open("w"))
    out = check_problem(top, load_answers(path))[0]
    return out.status, out.detail, out.power


# spinning about the vertical, the top sleeps iff C²ω3² > 4·I·M·g·h, I = A + M·h² about
# the point (Symon 11-89 has I1 about the pivot and 4)
@pytest.mark.parametrize("book, status", [
    ("omega3 > 2*sqrt((A + M*h**2)*M*g*h)/C", "pass"),
    ("omega3 > sqrt(3*(A + M*h**2)*M*g*h)/C", "fail"),  # 3 for 4: 13 % in the spin
    ("omega3 > 2*sqrt(A*M*g*h)/C", "fail"),  # the moment about the centre of mass
    ("omega3 > (1 + 1/10**6)*2*sqrt((A + M*h**2)*M*g*h)/C", "fail"),
    ("omega3 < 2*sqrt((A + M*h**2)*M*g*h)/C", "fail"),
])
def test_sleeping_top_threshold(top, tmp_path, book, status):
    got, detail, power = _check_top(top, tmp_path, book)
    assert got == status, detail
    if got == "pass":
        assert re.search(r"boundary at \d+ crossings", power), power
    else:
        assert "book says" in detail or "the engine finds" in detail, detail


# ---- conserved quantities the book names --------------------------------------------------
HEAVY_TOP = ROOT / "answers" / "symon" / "text-11-5-heavy-top.yaml"


@pytest.mark.parametrize("book, status", [
    (["p_psi = I3*(psidot + phidot*cos(theta))"], "pass"),
    (["p_psi = 2*I3*(psidot + phidot*cos(theta))"], "fail"),
    (["p_psi = (1 + 1/10**6)*I3*(psidot + phidot*cos(theta))"], "fail"),
    (["2*I3*(psidot + phidot*cos(theta))"], "pass"),  # a bare claim: its multiples hold too
    (["p_phi + p_psi = I1*phidot*sin(theta)**2 + I3*(1 + cos(theta))*(psidot + "
      "phidot*cos(theta))"], "pass"),
    (["E = I1*thetadot**2/2 + I1*phidot**2*sin(theta)**2/2 + I3*(psidot + "
      "phidot*cos(theta))**2/2 + m*g*l*cos(theta) + 5"], "pass"),  # up to a constant
    (["E = I1*thetadot**2 + I1*phidot**2*sin(theta)**2/2 + I3*(psidot + "
      "phidot*cos(theta))**2/2 + m*g*l*cos(theta)"], "fail"),
])
def test_named_conserved_quantity(book, status):
    key, analysis = _load(HEAVY_TOP)
    part = next(p for p in key.parts if p.name == "b-momenta")
    data = copy.deepcopy(part.data)
    data["book"] = book
    got = check_part(analysis, Part(key, part.index, data))
    assert got.status == status, got.detail
    if status == "pass" and "=" not in book[0]:
        assert "any function" in got.detail  # the verdict says what a bare claim is worth


def test_named_conserved_unknown_name_is_a_clear_error():
    key, analysis = _load(HEAVY_TOP)
    part = next(p for p in key.parts if p.name == "b-momenta")
    data = copy.deepcopy(part.data)
    data["book"] = ["spin = psidot + phidot*cos(theta)"]
    got = check_part(analysis, Part(key, part.index, data))
    assert got.status == "error" and "names no quantity the engine computes" in got.detail


# ---- the mutants themselves ---------------------------------------------------------------
def test_text_mutants_scale_each_number_and_parameter_once():
    got = [new for _, _, new, _ in text_mutants("m*g*l*(1 - cos(theta)) = 2*E", {"m", "g", "l"},
                                             Fraction(1, 100))]
    assert got == ["(m*(101/100))*g*l*(1 - cos(theta)) = 2*E",
                   "m*(g*(101/100))*l*(1 - cos(theta)) = 2*E",
                   "m*g*(l*(101/100))*(1 - cos(theta)) = 2*E",
                   "m*g*l*((1*(101/100)) - cos(theta)) = 2*E",
                   "m*g*l*(1 - cos(theta)) = (2*(101/100))*E"]


def test_shift_moves_the_value_or_the_boundary():
    assert shifted("a*x**2", Fraction(3), Fraction(1, 100)) == "(a*x**2) + (3/100)"
    assert shifted("x < 2*a", Fraction(2), Fraction(1, 100)) == "x < (2*a) + (1/50)"
    assert shifted("p = 2*a", Fraction(2), Fraction(1, 100)) == "p = (2*a) + (1/50)"


def test_discrete_values_get_their_nearest_wrong_value():
    got = [(m.label, m.value) for m in part_mutants(
        {"n": 3, "stable": True, "v": "stable"}, ("book",), set(), Fraction(1, 100),
        counts=True)]
    assert ("count + 1", 4) in got and ("count - 1", 2) in got
    assert ("flag flipped", False) in got
    assert ("stable -> unstable", "unstable") in got


# ---- the 1e-2 class over every answer part of both books ----------------------------------
def _get(data, path):
    for p in path:
        data = data[p]
    return data


def _put(data, path, value):
    _get(data, path[:-1])[path[-1]] = value


@pytest.mark.parametrize("answer_file", per_key(ANSWER_FILES, pytest.mark.slow))
def test_every_one_percent_mutant_fails(answer_file: Path):
    """Every number and every parameter occurrence of every passing part's value scaled by
    1.01, the value shifted by 1 % of its size, a count moved by one, a flag or verdict
    flipped (a part with `estimate:` at twice its stated precision): the checker must reject
    each mutant, unless it provably means the same (mechbook.verify.power.same_meaning: a
    factor that cancels, a constant the quantity is defined up to, a relation with the same
    truth everywhere). The same mutants as bench/power.py's δ = 1e-2 class."""
    key, analysis = _load(answer_file)
    names = set(analysis.problem.parameters) | set(key.symbols) | set(
        key.doc.data.get("abbreviations") or {})
    survivors, tried = [], 0
    for part in key.parts:
        original = check_part(analysis, part)
        if original.status not in ("pass", "erratum"):
            continue
        erratum = "erratum" in part.data
        root = ("erratum", "corrected") if erratum else ("book",)
        value = _get(part.data, root)
        ctx = Context(analysis, part)
        est = part.data.get("estimate")
        delta = Fraction(2 * est["rtol"]).limit_denominator(10**9) if est else Fraction(1, 100)
        for m in part_mutants(value, root, names, delta, shift_sizes(ctx, value, root),
                              counts=part.quantity in COUNTS):
            tried += 1
            data = copy.deepcopy(part.data)
            _put(data, m.path, m.value)
            got = check_part(analysis, Part(key, part.index, data))
            killed = got.status != "erratum" if erratum else got.status in ("fail", "error")
            if killed:
                continue
            why = same_meaning(ctx, m.path, _get(part.data, m.path), m.value, m.token)

            if not why:
                survivors.append(f"{part.name} [{part.quantity}] {'/'.join(map(str, m.path))}: "
                                 f"{m.label}: {got.status} {got.detail[:200]}")
    assert not survivors, f"{len(survivors)} of {tried} mutants passed:\n  " + \
        "\n  ".join(survivors)


# ---- a region of phase space, at its boundary ----------------------------------------------
@pytest.mark.parametrize("new, status", [
    ("-b < p_z + m*g*t < b", "pass"),
    ("-(b*(1000001/1000000)) < p_z + m*g*t < b", "fail"),  # one side moved by 1e-6 of b
    ("-b < p_z + (m*(1000001/1000000))*g*t < b", "fail"),  # the shift moved by 1e-6
])
def test_phase_region_boundary(new, status):
    key, analysis = _load(ROOT / "answers" / "symon" / "09-33.yaml")
    part = next(p for p in key.parts if p.name == "region")
    data = copy.deepcopy(part.data)
    data["book"][0] = new
    got = check_part(analysis, Part(key, part.index, data))
    assert got.status == status, got.detail
    if status == "pass":
        assert "boundary at" in got.power, got.power


@pytest.mark.mutation
def test_a_function_of_the_stated_integrals_means_the_same_and_nothing_else_does():
    """Symon 11-6 (b) states |ω|² and ωz conserved: |ω|² with ωz's exponent moved by 1 % is
    a function of the two and is conserved too (a pass that means the same); ωx² is not a
    function of them, and is not excused."""
    from mechbook.verify.context import Context
    from mechbook.verify.power import is_function_of

    key, analysis = _load(ROOT / "answers" / "symon" / "11-06.yaml")
    part = next(p for p in key.parts if p.name == "b-magnitude")
    ctx = Context(analysis, part)
    q = ctx.quantity
    names = q.names(ctx) if q.names else ctx.names

    def parse(text):
        return ctx.parse(text, ("book", 0), names=names)

    stated = [parse("wx**2 + wy**2 + wz**2"), parse("wz")]
    assert is_function_of(parse("wx**2 + wy**2 + wz**(101/50)"), stated, ctx)
    assert not is_function_of(parse("wx**2"), stated, ctx)
    assert not is_function_of(parse("wx**2 + wy**2"), stated[1:], ctx)
