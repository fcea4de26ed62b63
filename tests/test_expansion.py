"""The `approximation:` key: a problem's small-angle Lagrangian, expanded by the engine."""

from __future__ import annotations

import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.model.system import system_of

PENDULUM = """\
id: lim-2098
source: test
title: Small-angle pendulum
parameters:
  m: {value: 0.7}
  l: {value: 1.3}
  g: {}
coordinates:
  theta: {doc: angle from the downward vertical}
particles:
  bob: {mass: m, position: [l*sin(theta), -l*cos(theta)]}
gravity: {}
approximation: {about: {theta: 0}, order: 2}
"""


def test_small_angle_lagrangian_is_quadratic(tmp_path):
    path = tmp_path / "2098.yaml"
    path.write_text(PENDULUM)
    problem = load_problem(path)
    sys = system_of(problem)
    m, ln, g = (problem.parameters[n].symbol for n in ("m", "l", "g"))
    theta, thetadot = sys.q[0], sys.qd[0]
    expected = m * ln**2 * thetadot**2 / 2 - m * g * ln * theta**2 / 2
    assert sp.simplify(sys.lagrangian - expected) == 0
    dyn = Analysis(problem).dynamics()
    assert sp.simplify(dyn.accelerations[0] + g * theta / ln) == 0


def test_expansion_about_a_shifted_point(tmp_path):
    path = tmp_path / "2098.yaml"
    path.write_text(PENDULUM.replace("about: {theta: 0}", "about: {theta: pi}"))
    problem = load_problem(path)
    sys = system_of(problem)
    m, ln, g = (problem.parameters[n].symbol for n in ("m", "l", "g"))
    theta = sys.q[0]
    # about the top, V = -m g l cos(theta) expands to - m g l (theta - pi)**2 / 2 (+ const)
    dv = sp.diff(-sys.lagrangian.subs(sys.qd[0], 0), theta)
    assert sp.simplify(dv + m * g * ln * (theta - sp.pi)) == 0
