"""A string's named field (`string: {field: u}`): integrals of u and udot over the string
in answer keys, against an independent quadrature (scipy) for a string of variable density,
whose momenta couple the modes: p_k = ∫σ(x)·u_t·sin(kπx/l) dx. Wrong integrands fail; a
field name that clashes with a parameter is refused."""

from __future__ import annotations

import copy
import math

import pytest
from ruamel.yaml import YAML
from scipy.integrate import quad

from mechbook.engine.analysis import Analysis
from mechbook.errors import SpecError
from mechbook.model.problem import load_problem
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

STRING = """\
id: symon-text-test-field
source: test
title: string of variable density
parameters:
  l: {value: 0.9}
  tau: {value: 40.0}
  sigma0: {value: 0.05}
  alpha: {value: 0.02}
coordinates:
  q1: {}
  q2: {}
  q3: {}
string:
  length: l
  tension: tau
  density: sigma0 + alpha*sin(pi*x/l)
  amplitudes: [q1, q2, q3]
  field: u
"""


@pytest.fixture(scope="module")
def string(tmp_path_factory) -> Analysis:
    path = tmp_path_factory.mktemp("field") / "text-test-field.yaml"
    path.write_text(STRING)
    return Analysis(load_problem(path))


def check(analysis, tmp_path, **part):
    doc = {"problem": analysis.problem.id, "source": "test",
           "parts": [{"part": "x", "cite": "test", **part}]}
    YAML().dump(copy.deepcopy(doc), (tmp_path / "key.yaml").open("w"))
    out = check_problem(analysis, load_answers(tmp_path / "key.yaml"))[0]
    return out.status, out.detail


SIGMA = "(sigma0 + alpha*sin(pi*x/l))"


def test_momenta_as_field_integrals(string, tmp_path):
    book = {f"q{k}": f"integral({SIGMA}*udot*sin({k}*pi*x/l), x, 0, l)" for k in (1, 2, 3)}
    got, detail = check(string, tmp_path, quantity="expression", of="momenta", book=book)
    assert got == "pass", detail


@pytest.mark.parametrize("book", [
    {"q1": "integral(sigma0*udot*sin(pi*x/l), x, 0, l)"},                # uniform density
    {"q1": f"integral({SIGMA}*udot*sin(2*pi*x/l), x, 0, l)"},            # another mode
    {"q1": f"integral({SIGMA}*udot*sin(pi*x/l), x, 0, l/2)"},            # half the string
])
def test_wrong_field_integrals_fail(string, tmp_path, book):
    got, _ = check(string, tmp_path, quantity="expression", of="momenta", book=book)
    assert got == "fail"


def test_engine_momenta_match_an_independent_quadrature(string):
    """The engine's p_k = Σ_j M_kj q̇_j against M_kj = ∫σ sin_k sin_j dx by scipy."""
    sys = string.system()
    dyn = string.dynamics()
    vals = {str(k): float(v) for k, v in string.problem.values().items()}
    length, s0, a = vals["l"], vals["sigma0"], vals["alpha"]
    for k in range(3):
        for j in range(3):
            want, _ = quad(lambda x, k=k, j=j: (s0 + a * math.sin(math.pi * x / length))
                           * math.sin((k + 1) * math.pi * x / length)
                           * math.sin((j + 1) * math.pi * x / length), 0, length, epsabs=1e-14)
            got = float(dyn.momenta[k].diff(sys.qd[j]).subs(string.problem.values()))
            assert abs(got - want) < 1e-12


def test_kinetic_energy_as_a_field_integral(string, tmp_path):
    """T = ½∫σ u_t² dx, the text's definition, against the engine's kinetic energy."""
    got, detail = check(string, tmp_path, quantity="expression", of="kinetic",
                        book="integral(" + SIGMA + "*udot**2, x, 0, l)/2")
    assert got == "pass", detail


def test_a_field_name_that_is_taken_is_refused(tmp_path):
    text = STRING.replace("  alpha: {value: 0.02}", "  alpha: {value: 0.02}\n  u: {value: 1}")
    path = tmp_path / "text-test-field.yaml"
    path.write_text(text)
    with pytest.raises(SpecError, match="already taken"):
        Analysis(load_problem(path)).system()
