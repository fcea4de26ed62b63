"""`accessible` against a closed form outside the books: a particle in the plane bound by
an isotropic spring, V = k r²/2, with energy E and angular momentum L reaches the radius a
exactly when E ≥ L²/(2 m a²) + k a²/2. A boundary moved by a percent, or by far less, fails;
a name that is an abbreviation must be the engine's integral."""

from __future__ import annotations

import copy

import pytest
from ruamel.yaml import YAML

from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

PLANE = """\
id: symon-text-test-plane
source: test
title: particle on an isotropic spring in the plane
parameters:
  m: {value: 0.7}
  k: {value: 2.0}
  a: {doc: the radius asked about, value: 0.5}
coordinates:
  r: {}
  phi: {}
particles:
  p: {mass: m, position: [r*cos(phi), r*sin(phi)]}
potential: k*r**2/2
"""


@pytest.fixture(scope="module")
def plane(tmp_path_factory) -> Analysis:
    path = tmp_path_factory.mktemp("access") / "text-test-plane.yaml"
    path.write_text(PLANE)
    return Analysis(load_problem(path))


def check(analysis, tmp_path, book, integrals=None, abbreviations=None, at=None):
    part = {"part": "x", "cite": "test", "quantity": "accessible", "at": at or {"r": "a"},
            "integrals": integrals or {"E": {"of": "energy", "value": 1.0},
                                       "L": {"of": "p_phi", "value": 0.3}},
            "book": book}
    doc = {"problem": analysis.problem.id, "source": "test", "parts": [part]}
    if abbreviations:
        doc["abbreviations"] = abbreviations
    YAML().dump(copy.deepcopy(doc), (tmp_path / "key.yaml").open("w"))
    out = check_problem(analysis, load_answers(tmp_path / "key.yaml"))[0]
    return out.status, out.detail


@pytest.mark.parametrize("book, status", [
    ("L**2/(2*m*a**2) + k*a**2/2 <= E", "pass"),
    ("L**2 <= 2*m*a**2*(E - k*a**2/2)", "pass"),
    ("L**2/(2*m*a**2) + k*a**2/2 >= E", "fail"),
    ("L**2/(2*m*a**2) + (101/100)*k*a**2/2 <= E", "fail"),
    ("L**2/(2*m*a**2) + (100000001/100000000)*k*a**2/2 <= E", "fail"),   # 1e-8
    ("L**2/(m*a**2) + k*a**2/2 <= E", "fail"),
])
def test_radius_reached_on_the_level_set(plane, tmp_path, book, status):
    got, detail = check(plane, tmp_path, book)
    assert got == status, detail


def test_an_abbreviation_must_be_the_engines_integral(plane, tmp_path):
    energy = "m*(rdot**2 + r**2*phidot**2)/2 + k*r**2/2"
    got, detail = check(plane, tmp_path, "L**2/(2*m*a**2) + k*a**2/2 <= E",
                        abbreviations={"E": energy})
    assert got == "pass", detail
    got, detail = check(plane, tmp_path, "L**2/(2*m*a**2) + k*a**2/2 <= E",
                        abbreviations={"E": energy + " + k"})
    assert got == "error" and "not the engine's energy" in detail


def test_a_name_clash_is_refused(plane, tmp_path):
    got, detail = check(plane, tmp_path, "L**2/(2*m*a**2) + k*a**2/2 <= k",
                        integrals={"k": {"of": "energy", "value": 1.0},
                                   "L": {"of": "p_phi", "value": 0.3}})
    assert got == "error" and "already a name" in detail


def test_a_momentum_that_is_not_conserved_is_refused(plane, tmp_path):
    got, detail = check(plane, tmp_path, "L**2 <= E",
                        integrals={"E": {"of": "energy", "value": 1.0},
                                   "L": {"of": "p_r", "value": 0.3}})
    assert got in ("unsupported", "error") and "not cyclic" in detail
