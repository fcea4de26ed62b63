"""`hamilton_jacobi` (mechbook/verify/quantities/hamilton_jacobi.py) against complete
integrals derived here: an oscillator, a body thrown upward, and a two-dimensional
anisotropic oscillator separated in x and y (two separation constants). The book's S
passes, with the motion it generates (∂S/∂α = β) agreeing with the engine's integration;
a 1 % or a 1e-6 wrong S and a wrong separation fail."""

from __future__ import annotations

import json

import pytest
from systems import load_analysis

from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem


def _outcome(tmp_path, num: str, problem: str, part: dict, symbols: dict):
    header = f"id: lim-{num}\nsource: test\ntitle: a Hamilton-Jacobi test\n"
    an = load_analysis(tmp_path, header + problem, num)
    d = tmp_path / "answers" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    f = d / f"{num}.yaml"
    f.write_text(json.dumps({"problem": f"lim-{num}", "source": "test", "symbols": symbols,
                             "parts": [{"part": "a", "cite": "t", **part}]}))
    return check_problem(an, load_answers(f))[0]


OSCILLATOR = """\
parameters:
  m: {value: 1.3}
  lam: {value: 0.7}
coordinates:
  x: {}
particles:
  p: {mass: m, position: [x]}
potential: lam*x**2
"""
# H = p²/2m + λx²; S = −E·t + W(x, E) with W' = p = sqrt(2m(E − λx²)) = sqrt(a² − b²x²),
# a² = 2mE, b² = 2mλ: W = (x/2)·sqrt(a² − b²x²) + (a²/(2b))·asin(bx/a), a²/(2b) =
# E·sqrt(m/(2λ)), bx/a = x·sqrt(λ/E).
OSC_S = "-E*t + x/2*sqrt(2*m*(E - lam*x**2)) + E*sqrt(m/(2*lam))*asin(x*sqrt(lam/E))"


@pytest.mark.parametrize("book, want", [
    (OSC_S, "pass"),
    (f"({OSC_S})*1.01", "fail"),
    (OSC_S.replace("-E*t", "-E*t*(1 + 1e-6)"), "fail"),
    (OSC_S.replace("asin(x*sqrt(lam/E))", "asin(x*sqrt(lam/E)*(1 + 1e-6))"), "fail"),
    (OSC_S.replace("-E*t", "-2*E*t"), "fail"),        # the separation constant's time part
    (OSC_S + " + 3*E", "pass"),                       # S + f(α): the same complete integral
])
def test_the_oscillators_complete_integral(tmp_path, book, want):
    part = {"quantity": "hamilton_jacobi", "constants": ["E"], "start": {"x": 0},
            "book": book}
    out = _outcome(tmp_path, "9901", OSCILLATOR, part, {"E": {"value": 0.5}})
    assert out.status.value == want, out.detail
    if want == "pass":
        assert "generated motion agrees" in out.detail


FALLING = """\
parameters:
  m: {value: 0.8}
  g: {value: 9.81}
coordinates:
  z: {}
particles:
  p: {mass: m, position: [0, z]}
gravity: {}
"""
# H = p²/2m + m·g·z; W' = p = sqrt(2m(E − mgz)) (moving up): W = −(2m(E − mgz))^(3/2)/
# (3m²g) (d/dz: −(3/2)·sqrt(·)·(−2m²g)/(3m²g) = sqrt(·)). S = −E·t + W; β = ∂S/∂E = −t −
# sqrt(2m(E − mgz))/(mg), i.e. p = −mg(t + β): a body thrown up, decelerated by g.
FALL_S = "-E*t - (2*m*(E - m*g*z))**(3/2)/(3*m**2*g)"


@pytest.mark.parametrize("book, want", [
    (FALL_S, "pass"),
    (FALL_S.replace("3*m**2*g", "3*m**2*g*(1 + 1e-6)"), "fail"),
    (FALL_S.replace("(3/2)", "(3/2 + 1e-6)"), "fail"),
])
def test_a_body_thrown_upward(tmp_path, book, want):
    part = {"quantity": "hamilton_jacobi", "constants": ["E"], "start": {"z": 0},
            "book": book}
    out = _outcome(tmp_path, "9902", FALLING, part, {"E": {"value": 2.0}})
    assert out.status.value == want, out.detail


PLANE = """\
parameters:
  m: {value: 1.0}
  a: {value: 0.6}
  b: {value: 1.7}
coordinates:
  x: {}
  y: {}
particles:
  p: {mass: m, position: [x, y]}
potential: a*x**2 + b*y**2
"""


def _w(c: str, k: str, e: str) -> str:
    """W for one coordinate of potential k·c² and energy e (as OSC_S's)."""
    return (f"{c}/2*sqrt(2*m*({e} - {k}*{c}**2)) + "
            f"{e}*sqrt(m/(2*{k}))*asin({c}*sqrt({k}/{e}))")


PLANE_S = f"-(E1 + E2)*t + {_w('x', 'a', 'E1')} + {_w('y', 'b', 'E2')}"


@pytest.mark.parametrize("book, want", [
    (PLANE_S, "pass"),
    (PLANE_S.replace("-(E1 + E2)*t", "-(E1 + E2*(1 + 1e-6))*t"), "fail"),
    (f"-(E1 + E2)*t + {_w('x', 'a', 'E1')} + {_w('y', 'a', 'E2')}", "fail"),   # y's stiffness
])
def test_two_separation_constants(tmp_path, book, want):
    part = {"quantity": "hamilton_jacobi", "constants": ["E1", "E2"],
            "start": {"x": 0, "y": 0}, "book": book}
    out = _outcome(tmp_path, "9903", PLANE, part, {"E1": {"value": 0.5}, "E2": {"value": 0.3}})
    assert out.status.value == want, out.detail


def test_a_complete_integral_needs_a_constant_per_coordinate(tmp_path):
    part = {"quantity": "hamilton_jacobi", "constants": ["E1"], "start": {"x": 0, "y": 0},
            "book": PLANE_S}
    out = _outcome(tmp_path, "9904", PLANE, part, {"E1": {"value": 0.5}, "E2": {"value": 0.3}})
    assert out.status.value == "error" and "one constant per coordinate" in out.detail
