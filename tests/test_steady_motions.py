"""Steady motions in general (mechbook.engine.steady, .steady_search): uniform motions that
solve the equations, counts, stability over parameter space, existence conditions, steady motions
kept unreduced, restricted parameters, arbitrary functions. Small hand-solved systems, each
check also shown to fail a wrong value."""

from __future__ import annotations

import json
from pathlib import Path

import sympy as sp
from systems import load_analysis as load

from mechbook.engine.analysis import Analysis
from mechbook.errors import SpecError
from mechbook.records import ProofPolicy
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

ORBIT = """\
id: lim-9401
source: test
title: particle on a spring of natural length a, moving in a plane
parameters:
  m: {value: 0.8}
  k: {value: 3.0}
  a: {value: 0.5}
coordinates:
  r: {}
  phi: {}
particles:
  p: {mass: m, position: [r*cos(phi), r*sin(phi)]}
potential: k*(r - a)**2/2
"""

DOUBLE_WELL = """\
id: lim-9402
source: test
title: particle in a double well
parameters:
  m: {value: 1.0}
  c: {value: 1.0}
coordinates:
  x: {}
particles:
  p: {mass: m, position: [x]}
potential: c*(x**4/4 - x**2/2)
"""

ARBITRARY = """\
id: lim-9403
source: test
title: particle in an arbitrary potential F(x)
parameters:
  m: {value: 1.3}
functions:
  F: {degree: 5}
coordinates:
  x: {}
particles:
  p: {mass: m, position: [x]}
potential: F(x)
"""


def status(tmp_path: Path, an: Analysis, part: dict, symbols: dict | None = None) -> str:
    d = tmp_path / "answers" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    f = d / f"{an.problem.id.split('-')[1]}.yaml"
    doc = {"problem": an.problem.id, "source": "test", "parts": [{"cite": "t", **part}]}
    if symbols:
        doc["symbols"] = symbols
    f.write_text(json.dumps(doc))
    out = check_problem(an, load_answers(f))[0]
    return out.status


R0 = {"r0": {"value": 1.2}}
RATE = "sqrt(k*(r0 - a)/(m*r0))"  # m r w**2 = k (r - a)


def test_steady_motion_of_an_orbit(tmp_path):
    an = load(tmp_path, ORBIT, "9401")
    part = {"part": "s", "quantity": "steady_motion", "assume": ["r0 > a"],
            "book": {"at": {"r": "r0"}, "rates": {"phi": RATE}}}
    assert status(tmp_path, an, part, R0) == "pass"
    wrong = dict(part, book={"at": {"r": "r0"}, "rates": {"phi": f"2*{RATE}"}})
    assert status(tmp_path, an, wrong, R0) == "fail"


def test_steady_exists_only_outside_the_natural_length(tmp_path):
    an = load(tmp_path, ORBIT, "9401")
    part = {"part": "e", "quantity": "steady_exists", "unknown": "phi",
            "about": {"r": "r0"}, "book": "r0 > a"}
    assert status(tmp_path, an, part, R0) == "pass"
    assert status(tmp_path, an, dict(part, book="r0 < a"), R0) == "fail"


def test_stability_always_and_the_unreduced_exponents(tmp_path):
    """About a circular orbit on the spring, Routh's reduction leaves one radial mode with
    omega**2 = k/m + 3*w**2 (w the orbit rate): always stable. Kept unreduced the exponents
    are +-i*that, and 0 twice (the azimuth: a turned orbit, and one of another rate)."""
    an = load(tmp_path, ORBIT, "9401")
    steady = {"steady": {"phi": RATE}, "about": {"r": "r0"}, "assume": ["r0 > a"]}
    assert status(tmp_path, an, {"part": "s", "quantity": "stability", **steady,
                                 "book": "stable"}, R0) == "pass"
    assert status(tmp_path, an, {"part": "s", "quantity": "stability", **steady,
                                 "book": "unstable"}, R0) == "fail"
    radial = f"sqrt(k/m + 3*({RATE})**2)"
    exps = {"part": "x", "quantity": "exponents", **steady, "reduce": False,
            "book": [f"sqrt(-1)*{radial}", f"-sqrt(-1)*{radial}", "0", "0"]}
    assert status(tmp_path, an, exps, R0) == "pass"
    assert status(tmp_path, an, dict(exps, book=[f"sqrt(-1)*{radial}",
                                                 f"-sqrt(-1)*{radial}"]), R0) == "fail"
    assert status(tmp_path, an, {"part": "f", "quantity": "frequencies", **steady,
                                 "book": [radial]}, R0) == "pass"


def test_counting_equilibria_and_their_stability(tmp_path):
    an = load(tmp_path, DOUBLE_WELL, "9402")
    part = {"part": "n", "quantity": "equilibrium_count", "search": {"x": [-3, 3]},
            "book": 3}
    assert status(tmp_path, an, part) == "pass"
    assert status(tmp_path, an, dict(part, book=2)) == "fail"
    middle = dict(part, search={"x": [-0.5, 0.5]}, book=1, stable=False)
    assert status(tmp_path, an, middle) == "pass"
    assert status(tmp_path, an, dict(middle, stable=True)) == "fail"
    sides = dict(part, search=[{"x": [-3, -0.5]}, {"x": [0.5, 3]}], book=2, stable=True)
    assert status(tmp_path, an, sides) == "pass"


def test_restrict_puts_the_parameters_on_a_surface(tmp_path):
    """The double well's bottom x = 1 is an equilibrium; x = a is one only on the surface
    a = 1 (restrict), and a check there must pass; off it, fail."""
    an = load(tmp_path, DOUBLE_WELL, "9402")
    part = {"part": "e", "quantity": "equilibrium", "book": {"at": {"x": "a"}}}
    assert status(tmp_path, an, dict(part, restrict={"a": "1"}),
                  {"a": {"value": 1.3}}) == "pass"
    assert status(tmp_path, an, part, {"a": {"value": 1.3}}) == "fail"
    freq = {"part": "f", "quantity": "frequencies", "about": {"x": "a"},
            "restrict": {"a": "1"}, "book": ["sqrt(2*c/m)"]}
    assert status(tmp_path, an, freq, {"a": {"value": 1.3}}) == "pass"


def test_an_arbitrary_function_and_diff(tmp_path):
    """V = F(x), F arbitrary: the equation of motion is m*x'' + F'(x) = 0 for every F."""
    an = load(tmp_path, ARBITRARY, "9403")
    names = an.problem.parameters
    assert [n for n in names if n.startswith("F_c")] == [f"F_c{k}" for k in range(6)]
    part = {"part": "e", "quantity": "eom", "book": ["m*xddot + diff(F(x), x) = 0"]}
    assert status(tmp_path, an, part) == "pass"
    assert status(tmp_path, an, dict(part, book=["m*xddot + 2*diff(F(x), x) = 0"])) == \
        "fail"
    # the function's value at a point, as an answer may write it, is its polynomial
    sys = an.system()
    F = sys.names["F"]
    a = sp.Symbol("a")
    assert sp.expand(sp.diff(F(a), a) - sum(k * names[f"F_c{k}"].symbol * a**(k - 1)
                                            for k in range(1, 6))) == 0


def test_diff_refuses_a_non_name(tmp_path):
    bad = ARBITRARY.replace("potential: F(x)", "potential: diff(F(x), 2*x)")
    try:
        load(tmp_path, bad, "9404").system()
    except SpecError as exc:
        assert "declared name" in str(exc)
    else:  # pragma: no cover
        raise AssertionError("diff with respect to an expression was accepted")


def test_proving_a_gyroscopic_frequency_whose_point_is_the_keys(tmp_path):
    """`--prove` on the unreduced orbit (gyroscopic: C ≠ 0): the secular equation's roots in
    ω are ±radial and 0 twice, with the key's own r0 in them. Choosing the real,
    non-negative roots must evaluate them at the sampled point, r0 included (the system's
    own values do not name r0: this raised "Cannot convert expression to float" for three
    book parts), and ω = 0, a double root, is one zero frequency. The proof then passes,
    and a 1e-6 wrong radial frequency still fails."""
    an = load(tmp_path, ORBIT, "9401")
    radial = f"sqrt(k/m + 3*({RATE})**2)"
    part = {"part": "f", "quantity": "frequencies", "steady": {"phi": RATE},
            "about": {"r": "r0"}, "assume": ["r0 > a"], "reduce": False}

    def outcome(book: list[str]):
        d = tmp_path / "answers" / "lim"
        d.mkdir(parents=True, exist_ok=True)
        f = d / "9401.yaml"
        f.write_text(json.dumps({"problem": an.problem.id, "source": "test", "symbols": R0,
                                 "parts": [{"cite": "t", **part, "book": book}]}))
        return check_problem(an, load_answers(f), ProofPolicy(True, 10.0))[0]

    both = outcome([radial, "0"])
    assert (both.status, both.method) == ("pass", "symbolic"), both.detail
    assert outcome([f"(1 + 1e-6)*{radial}", "0"]).status == "fail"
    assert outcome([radial, radial]).status == "fail"
