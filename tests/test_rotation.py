"""Rotating-body quantities on a symmetric body with an axial torque N3 (solved by hand:
Euler's equations give omega3 = omega30 + N3*t/I3 and omega_perp turning about e3 at
(I3 - I1)*omega3/I1 relative to the body), and each failing a wrong answer."""

from __future__ import annotations

import copy

import pytest
from ruamel.yaml import YAML

from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

BODY = """\
id: symon-text-test-jet
source: test
title: symmetric body with an axial torque
parameters:
  I1: {value: 1.0}
  I3: {value: 1.6}
  N3: {value: 0.4}
coordinates:
  theta: {}
  phi: {}
  psi: {}
rigid_bodies:
  b:
    mass: 1
    position: [0, 0, 0]
    inertia: [[I1, 0, 0], [0, I1, 0], [0, 0, I3]]
    euler_angles: [phi, theta, psi]
    rates: [w1, w2, w3]
torques:
  - {body: b, axes: body, components: [0, 0, N3]}
"""


@pytest.fixture(scope="module")
def body(tmp_path_factory) -> Analysis:
    path = tmp_path_factory.mktemp("rot") / "text-test-jet.yaml"
    path.write_text(BODY)
    return Analysis(load_problem(path))


def check(analysis, tmp_path, **part):
    doc = {"problem": "symon-text-test-jet", "source": "test",
           "symbols": {"c1": {"positive": False, "value": 0.3},
                       "c2": {"positive": False, "value": -0.5},
                       "w30": {"positive": False, "value": 0.7}},
           "abbreviations": {"chi": "(I3 - I1)*(w30*t + N3*t**2/(2*I3))/I1"},
           "parts": [{"part": "x", "cite": "test", **part}]}
    YAML().dump(copy.deepcopy(doc), (tmp_path / "key.yaml").open("w"))
    out = check_problem(analysis, load_answers(tmp_path / "key.yaml"))[0]
    return out.status, out.detail


@pytest.mark.parametrize("book, status", [
    (["I1*w1dot + (I3 - I1)*w2*w3 = 0", "I1*w2dot - (I3 - I1)*w3*w1 = 0", "I3*w3dot = N3"],
     "pass"),
    (["I1*w1dot - (I3 - I1)*w2*w3 = 0"], "fail"),
    (["I3*w3dot = 2*N3"], "fail")])
def test_euler_equations_as_eom(body, tmp_path, book, status):
    assert check(body, tmp_path, quantity="eom", book=book)[0] == status


@pytest.mark.parametrize("spec, book, status", [
    ({"vector": "omega", "axis": "e3", "frame": "body"}, "(I3 - I1)*w3/I1", "pass"),
    ({"vector": "omega", "axis": "e3", "frame": "body"}, "(I3 - I1)*w3/I3", "fail"),
    ({"vector": "omega", "axis": "e3", "frame": "body"}, "-(I3 - I1)*w3/I1", "fail"),
    ({"vector": "e1", "axis": "e3", "frame": "body"}, "0", "pass"),  # fixed in the body
    ({"vector": "e1", "axis": "e3", "frame": "body"}, "w3", "fail"),
    ({"vector": "e1", "axis": "e3", "frame": "space"}, "w3", "pass"),  # the body spins
])
def test_precession_rate(body, tmp_path, spec, book, status):
    got, detail = check(body, tmp_path, quantity="precession_rate", body="b", book=book, **spec)
    assert got == status, detail


@pytest.mark.parametrize("book, status", [
    ({"w1": "c1*cos(chi) - c2*sin(chi)", "w2": "c1*sin(chi) + c2*cos(chi)",
      "w3": "w30 + N3*t/I3"}, "pass"),
    ({"w1": "c1*cos(chi) + c2*sin(chi)", "w2": "c1*sin(chi) + c2*cos(chi)",
      "w3": "w30 + N3*t/I3"}, "fail"),
    ({"w1": "c1*cos(chi) - c2*sin(chi)", "w2": "c1*sin(chi) + c2*cos(chi)",
      "w3": "w30 + 2*N3*t/I3"}, "fail")])
def test_solution_in_body_rates(body, tmp_path, book, status):
    got, detail = check(body, tmp_path, quantity="solution", book=book)
    assert got == status, detail


@pytest.mark.parametrize("book, status", [
    ("w1**2 + w2**2 + w3**2 = thetadot**2 + phidot**2 + psidot**2 + 2*phidot*psidot*cos(theta)",
     "pass"),
    ("w1**2 + w2**2 = thetadot**2 + phidot**2", "fail"),
    ("I1*w1*w1dot + I1*w2*w2dot + I3*w3*w3dot = N3*w3", "pass"),  # dT/dt = N.omega
    ("I1*w1*w1dot + I1*w2*w2dot + I3*w3*w3dot = N3*w1", "fail")])
def test_identity(body, tmp_path, book, status):
    got, detail = check(body, tmp_path, quantity="state_identity", book=book)
    assert got == status, detail


MATRIX = [["cos(psi)*cos(phi) - cos(theta)*sin(phi)*sin(psi)",
           "cos(psi)*sin(phi) + cos(theta)*cos(phi)*sin(psi)", "sin(psi)*sin(theta)"],
          ["-sin(psi)*cos(phi) - cos(theta)*sin(phi)*cos(psi)",
           "-sin(psi)*sin(phi) + cos(theta)*cos(phi)*cos(psi)", "cos(psi)*sin(theta)"],
          ["sin(theta)*sin(phi)", "-sin(theta)*cos(phi)", "cos(theta)"]]


def test_rotation_matrix(body, tmp_path):
    assert check(body, tmp_path, quantity="rotation_matrix", body="b", book=MATRIX)[0] == "pass"
    transposed = [list(r) for r in zip(*MATRIX, strict=True)]
    assert check(body, tmp_path, quantity="rotation_matrix", body="b",
                 book=transposed)[0] == "fail"
    assert check(body, tmp_path, quantity="rotation_matrix", body="b", transform="body_to_space",
                 book=transposed)[0] == "pass"
