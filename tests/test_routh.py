"""Small oscillations about steady motion (Routh's reduction) against closed forms."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.errors import NotEquilibriumError, UnsupportedError
from mechbook.model.problem import load_problem

CONE = """\
id: lim-2099
source: test
title: Particle inside a cone
parameters:
  m: {value: 1.3}
  g: {}
  alpha: {doc: half-angle of the cone, value: 0.5}
coordinates:
  r: {doc: distance from the axis}
  phi: {doc: azimuth}
particles:
  p: {mass: m, position: [r*cos(phi), r*sin(phi), r/tan(alpha)]}
gravity: {}
"""


@pytest.fixture()
def cone(tmp_path):
    path = tmp_path / "2099.yaml"
    path.write_text(CONE)
    problem = load_problem(path)
    return problem, Analysis(problem)


def test_cone_steady_frequency_is_sqrt3_omega_sin_alpha(cone):
    problem, analysis = cone
    sys = analysis.system()
    r, phi = sys.q
    g, alpha = problem.parameters["g"].symbol, problem.parameters["alpha"].symbol
    omega = sp.Symbol("Omega", positive=True)
    lin = analysis.steady_linear(None, {phi: omega}, {r: g / (omega**2 * sp.tan(alpha))})
    values = {**problem.values(), omega: 2.7}
    got = lin.numeric_frequencies(values)
    expected = np.sqrt(3) * 2.7 * np.sin(0.5)
    assert got.shape == (1,)
    assert abs(got[0] - expected) < 1e-10 * expected
    # the frequency about steady motion differs from the bare potential's (which has none)
    assert abs(got[0] - 2.7) > 0.1


def test_wrong_radius_is_not_a_steady_motion(cone):
    problem, analysis = cone
    sys = analysis.system()
    r, phi = sys.q
    omega = sp.Symbol("Omega", positive=True)
    with pytest.raises(NotEquilibriumError, match="not an equilibrium"):
        analysis.steady_linear(None, {phi: omega}, {r: 2 * problem.parameters["g"].symbol})


def test_non_cyclic_coordinate_is_refused(cone):
    problem, analysis = cone
    sys = analysis.system()
    r, phi = sys.q
    with pytest.raises(UnsupportedError, match="not a cyclic coordinate"):
        analysis.steady_linear(None, {r: sp.Integer(1)}, {phi: sp.Integer(0)})
