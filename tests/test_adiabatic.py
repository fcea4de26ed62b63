"""`adiabatic_invariant` against closed forms outside the books: a pendulum whose string is
drawn in (θ0⁴r³ kept: J = π m √g r^{3/2} θ0²) and a mass on a spring whose stiffness k(t)
changes slowly (A⁴k kept: J = π√(mk)A²). The simulated slow change alone reproduces the
closed-form amplitude; wrong exponents fail, a constant factor or term is the same law."""

from __future__ import annotations

import copy

import pytest
from ruamel.yaml import YAML

from mechbook.engine.adiabatic import simulate
from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

PENDULUM = """\
id: symon-text-test-drawn
source: test
title: pendulum on a string drawn through a hole
parameters:
  m: {value: 0.2}
  g: {}
coordinates:
  theta: {}
driven:
  r: {free: true}
particles:
  bob: {mass: m, position: [r*sin(theta), -r*cos(theta)]}
gravity: {}
"""

SPRING = """\
id: symon-text-test-stiffening
source: test
title: mass on a spring of slowly changing stiffness
parameters:
  m: {value: 0.5}
coordinates:
  x: {}
driven:
  k: {free: true}
kinetic: m*xdot**2/2
potential: k*x**2/2
"""


def _analysis(tmp_path_factory, text: str) -> Analysis:
    name = text.split("\n", 1)[0].removeprefix("id: symon-")
    path = tmp_path_factory.mktemp("adiabatic") / f"{name}.yaml"
    path.write_text(text)
    return Analysis(load_problem(path))


@pytest.fixture(scope="module")
def pendulum(tmp_path_factory):
    return _analysis(tmp_path_factory, PENDULUM)


@pytest.fixture(scope="module")
def spring(tmp_path_factory):
    return _analysis(tmp_path_factory, SPRING)


def check(analysis, tmp_path, book, coordinate, slow, about, **extra):
    doc = {"problem": analysis.problem.id, "source": "test",
           "symbols": {"A": {"value": 0.01}, "s0": {"value": 1.0}},
           "parts": [{"part": "x", "cite": "test", "quantity": "adiabatic_invariant",
                      "about": about, "coordinate": coordinate, "amplitude": "A",
                      "slow": slow, "book": book, **extra}]}
    YAML().dump(copy.deepcopy(doc), (tmp_path / "key.yaml").open("w"))
    out = check_problem(analysis, load_answers(tmp_path / "key.yaml"))[0]
    return out.status, out.detail


@pytest.mark.parametrize("book, status", [
    ("A**4*r**3", "pass"),
    ("A**2*r**(3/2)", "pass"),           # the same law
    ("3*A**4*r**3 + 1", "pass"),         # a constant factor and term: the same law
    ("A**4*r**2", "fail"),
    ("A**2*r**3", "fail"),
    ("A**4*r**(303/100)", "fail"),       # an exponent 1 % off
    ("A*r", "fail"),
    ("A**4*r**3*theta", "fail"),         # not a law in the amplitude and r
])
@pytest.mark.slow
def test_pendulum_drawn_in(pendulum, tmp_path, book, status):
    got, detail = check(pendulum, tmp_path, book, "theta", {"r": ["s0", "s0/2"]},
                        {"theta": 0})
    assert got == status, detail


@pytest.mark.slow
@pytest.mark.parametrize("book, status", [
    ("A**4*k", "pass"),
    ("A**2*k", "fail"),                  # energy over stiffness is not kept
    ("A**4*k**2", "fail"),
])
def test_spring_stiffening(spring, tmp_path, book, status):
    got, detail = check(spring, tmp_path, book, "x", {"k": ["s0", "4*s0"]}, {"x": 0})
    assert got == status, detail


@pytest.mark.slow
def test_simulated_slow_change_gives_the_closed_form_amplitude(pendulum, spring):
    """Independently of any answer key: the amplitude after the change against the
    closed forms A0·(r0/r1)^(3/4) and A0·(k0/k1)^(1/4), to the small-amplitude correction."""
    values = pendulum.problem.values()
    r = pendulum.system().free_driven[0][0]
    run = simulate(pendulum.dynamics(), r, values, 1.0, 0.5, 0.005)
    assert abs(run.a1 / (0.005 * 2 ** 0.75) - 1) < 2e-5
    k = spring.system().free_driven[0][0]
    run = simulate(spring.dynamics(), k, spring.problem.values(), 1.0, 4.0, 0.3)
    assert abs(run.a1 / (0.3 / 4 ** 0.25) - 1) < 1e-6   # linear: no amplitude correction


# `invariant: action`: the law is the action itself, J = (1/2π)∮p dx. For the spring the
# orbit is an ellipse of semi-axes A and sqrt(mk)·A (p = m·ẋ, |ẋ| ≤ ωA, ω = sqrt(k/m)), of
# area π·sqrt(mk)·A², so J = sqrt(mk)·A²/2 (= E/ω); for the drawn pendulum M = m r²,
# K = m g r, so J = m·sqrt(g)·r^(3/2)·A²/2.
@pytest.mark.slow
@pytest.mark.parametrize("book, status", [
    ("A**2*sqrt(m*k)/2", "pass"),
    ("A**2*sqrt(m*k)", "fail"),               # 2J
    ("pi*A**2*sqrt(m*k)", "fail"),            # the area ∮p dx = 2πJ
    ("A**2*sqrt(m*k)/2*(1 + 1e-6)", "fail"),
    ("A**2*sqrt(m*k)/2*1.01", "fail"),
    ("A**4*k", "fail"),                       # a function of J, not J
])
def test_spring_the_action_itself(spring, tmp_path, book, status):
    got, detail = check(spring, tmp_path, book, "x", {"k": ["s0", "4*s0"]}, {"x": 0},
                        invariant="action")
    assert got == status, detail


@pytest.mark.slow
@pytest.mark.parametrize("book, status", [
    ("m*sqrt(g)*r**(3/2)*A**2/2", "pass"),
    ("m*sqrt(g)*r**(3/2)*A**2", "fail"),
    ("m*sqrt(g)*r**(3/2)*A**2/2*(1 + 1e-6)", "fail"),
])
def test_pendulum_the_action_itself(pendulum, tmp_path, book, status):
    got, detail = check(pendulum, tmp_path, book, "theta", {"r": ["s0", "s0/2"]},
                        {"theta": 0}, invariant="action")
    assert got == status, detail
