"""Steady motions as answers, on the spherical pendulum (solved by hand): the conical
motion at theta0 (from the upward vertical) turns at phidot**2 = -g/(R*cos(theta0)), which
exists only below the horizontal; Routh's effective potential; stability without a
boundary; and each check failing a wrong answer."""

from __future__ import annotations

import copy

import pytest
from ruamel.yaml import YAML
from systems import pendulum

from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

PENDULUM = """\
id: symon-text-test-spherical
source: test
title: spherical pendulum
parameters:
  m: {value: 0.4}
  R: {value: 1.2}
  g: {}
coordinates:
  theta: {}
  phi: {}
particles:
  bob: {mass: m, position: [R*sin(theta)*cos(phi), R*sin(theta)*sin(phi), R*cos(theta)]}
gravity: {}
"""

KEY = {"problem": "symon-text-test-spherical", "source": "test",
       "symbols": {"theta0": {"value": 2.3}}, "parts": []}


@pytest.fixture(scope="module")
def analysis(tmp_path_factory) -> Analysis:
    path = tmp_path_factory.mktemp("steady") / "text-test-spherical.yaml"
    path.write_text(PENDULUM)
    return Analysis(load_problem(path))


def check(analysis, tmp_path, **part) -> str:
    doc = copy.deepcopy(KEY)
    doc["parts"] = [{"part": "x", "cite": "test", **part}]
    path = tmp_path / "key.yaml"
    YAML().dump(doc, path.open("w"))
    out = check_problem(analysis, load_answers(path))[0]
    return out.status, out.detail


STEADY = {"quantity": "steady_rates", "about": {"theta": "theta0"}, "unknown": "phi"}


@pytest.mark.parametrize("book, status", [
    ("phidot**2*R*cos(theta0) + g = 0", "pass"),
    ("phidot**2*R*cos(theta0) - g = 0", "fail"),       # roots only where there are none
    ("phidot**2*R*cos(theta0) + 2*g = 0", "fail"),
    ("phidot*R*cos(theta0) + g = 0", "fail"),           # one root, not two
    (["sqrt(-g/(R*cos(theta0)))", "-sqrt(-g/(R*cos(theta0)))"], "pass"),
    (["sqrt(-g/(R*cos(theta0)))"], "fail"),             # the other root is missing
    (["sqrt(-2*g/(R*cos(theta0)))", "-sqrt(-2*g/(R*cos(theta0)))"], "fail"),
])
def test_steady_rates(analysis, tmp_path, book, status):
    got, detail = check(analysis, tmp_path, **STEADY, assume=["theta0 > pi/2", "theta0 < pi"],
                        book=book)
    assert got == status, detail


def test_steady_rate_subset_with_partial(analysis, tmp_path):
    got, detail = check(analysis, tmp_path, **STEADY, assume=["theta0 > pi/2", "theta0 < pi"],
                        partial=True, book=["sqrt(-g/(R*cos(theta0)))"])
    assert got == "pass", detail


@pytest.mark.parametrize("book, status", [
    ("theta0 > pi/2", "pass"), ("theta0 < pi/2", "fail"), ("theta0 > pi/3", "fail")])
def test_steady_exists(analysis, tmp_path, book, status):
    got, detail = check(analysis, tmp_path, quantity="steady_exists", about={"theta": "theta0"},
                        unknown="phi", assume=["theta0 < pi"], book=book)
    assert got == status, detail


@pytest.mark.parametrize("book, status", [
    ("p_phi**2/(2*m*R**2*sin(theta)**2) + m*g*R*cos(theta)", "pass"),
    ("p_phi**2/(2*m*R**2*sin(theta)**2) + m*g*R*cos(theta) + p_phi**2", "pass"),  # + f(p)
    ("p_phi**2/(m*R**2*sin(theta)**2) + m*g*R*cos(theta)", "fail"),
    ("p_phi**2/(2*m*R**2*sin(theta)**2) - m*g*R*cos(theta)", "fail"),
])
def test_effective_potential(analysis, tmp_path, book, status):
    got, detail = check(analysis, tmp_path, quantity="effective_potential", cyclic=["phi"],
                        book=book)
    assert got == status, detail


@pytest.mark.parametrize("verdict, status", [("stable", "pass"), ("unstable", "fail")])
def test_stability_without_a_boundary(analysis, tmp_path, verdict, status):
    """The conical motion of a spherical pendulum is stable wherever it exists."""
    got, detail = check(analysis, tmp_path, quantity="stability",
                        steady={"phi": "sqrt(-g/(R*cos(theta0)))"}, about={"theta": "theta0"},
                        assume=["theta0 > pi/2", "theta0 < pi"], book=verdict)
    assert got == status, detail


@pytest.mark.parametrize("about, verdict, status", [
    ("0", "stable", "pass"), ("0", "unstable", "fail"),
    ("pi", "unstable", "pass"), ("pi", "stable", "fail"),
    ("pi/2", "unstable", "fail")])  # not an equilibrium: a fail, never a pass
def test_stability_of_equilibria(tmp_path, about, verdict, status):
    """A plane pendulum hangs stably and balances upright unstably whatever its parameters:
    a stability condition would have no boundary to sample across."""
    path = tmp_path / "text-test-pendulum.yaml"
    path.write_text(pendulum(0.3, 0.8, header="id: symon-text-test-pendulum\nsource: test\n"
                             "title: pendulum\n"))
    key = {"problem": "symon-text-test-pendulum", "source": "test",
           "parts": [{"part": "x", "cite": "test", "quantity": "stability",
                      "about": {"theta": about}, "book": verdict}]}
    YAML().dump(key, (tmp_path / "key.yaml").open("w"))
    out = check_problem(Analysis(load_problem(path)), load_answers(tmp_path / "key.yaml"))[0]
    assert out.status == status, out.detail


@pytest.mark.parametrize("book, rtol, status", [
    (["3.503"], 0.001, "pass"), (["3.6"], 0.001, "fail"), (["3.6"], 0.05, "pass"),
    (["-3.503"], 0.001, "pass"), (["3.50"], 0.0001, "fail")])
def test_numeric_estimate(analysis, tmp_path, book, rtol, status):
    """At the book's numbers (R = 1.2, g = 9.81, theta0 = 2.3): phidot = 3.5033 rad/s."""
    got, detail = check(analysis, tmp_path, **STEADY, partial=True,
                        estimate={"values": {"theta0": 2.3}, "rtol": rtol}, book=book)
    assert got == status, detail


def test_no_steady_motion_anywhere_cannot_pass(analysis, tmp_path):
    """Above the horizontal there is no conical motion; an equation without real roots
    there agrees with the engine vacuously, so the check refuses to call it a pass."""
    got, detail = check(analysis, tmp_path, **STEADY, assume=["theta0 < pi/2"],
                        book="phidot**2 + g/R = 0")
    assert got == "error" and "cannot discriminate" in detail  # undecided, not a fail
