"""Lagrange multipliers against Newton's law: a pendulum whose string length is a constraint.

Newton, radially: m (r̈ − r θ̇²) = −T + m g cos θ with r = l fixed, so the string tension is
T = m g cos θ + m l θ̇², pulling inward. With the residual convention
E_i = d/dt ∂L/∂q̇_i − ∂L/∂q_i − λ ∂f/∂q_i and f = r − l, the generalized constraint force on
r is λ = −T.
"""

from __future__ import annotations

from pathlib import Path

from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.model.system import system_of
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

DATA = Path(__file__).parent / "data"


def _run(tmp_path, book: str | None = None):
    problem = load_problem(DATA / "problems/lim/2097.yaml")
    text = (DATA / "answers/lim/2097.yaml").read_text()
    if book is not None:
        text = text.replace('"-(m*g*cos(theta) + m*l*thetadot**2)"', book)
    path = tmp_path / "2097.yaml"
    path.write_text(text)
    return check_problem(Analysis(problem), load_answers(path))[0]


def test_tension_matches_newton(tmp_path):
    assert _run(tmp_path).status == "pass"


def test_wrong_sign_or_term_fails(tmp_path):
    assert _run(tmp_path, '"m*g*cos(theta) + m*l*thetadot**2"').status == "fail"
    assert _run(tmp_path, '"-(m*g*cos(theta) + 2*m*l*thetadot**2)"').status == "fail"
    assert _run(tmp_path, '"-(m*g*sin(theta) + m*l*thetadot**2)"').status == "fail"


def test_multiplier_at_rest_at_the_bottom_is_minus_weight():
    problem = load_problem(DATA / "problems/lim/2097.yaml")
    dyn = Analysis(problem).dynamics()
    sys = system_of(problem)
    r, theta = sys.q
    lam = dyn.solved[dyn.multipliers[0]]
    values = {**problem.values(), r: 2.0, theta: 0.0, sys.qd[0]: 0.0, sys.qd[1]: 0.0}
    assert abs(float(lam.subs(values)) + 9.81) < 1e-12


def _released(tmp_path, book: str, at: str = "{r: l, rdot: 0, theta: 0}"):
    """The same pendulum released from rest at theta0: at the bottom the energy integral
    gives l*thetadot**2 = 2*g*(1 - cos(theta0)), so T = m*g*(3 - 2*cos(theta0))."""
    problem = load_problem(DATA / "problems/lim/2097.yaml")
    text = (DATA / "answers/lim/2097.yaml").read_text()
    text = text.replace("    at: {r: l, rdot: 0}\n",
                        f"    at: {at}\n    released: {{theta: theta0, r: l}}\n")
    text = text.replace('"-(m*g*cos(theta) + m*l*thetadot**2)"', book)
    text = text.replace("parts:\n", "symbols:\n  theta0: {value: 0.9}\nparts:\n", 1)
    path = tmp_path / "2097.yaml"
    path.write_text(text)
    return check_problem(Analysis(problem), load_answers(path))[0]


def test_released_from_rest_uses_the_energy_integral(tmp_path):
    assert _released(tmp_path, '"-m*g*(3 - 2*cos(theta0))"').status == "pass"
    assert _released(tmp_path, '"-m*g*(3 - cos(theta0))"').status == "fail"
    assert _released(tmp_path, '"-m*g*(1 - 2*cos(theta0))"').status == "fail"
    # at an angle theta1 on the way down: T = m*g*(3*cos(theta1) - 2*cos(theta0))
    out = _released(tmp_path, '"-m*g*(3*cos(theta0/2) - 2*cos(theta0))"',
                    "{r: l, rdot: 0, theta: theta0/2}")
    assert out.status == "pass", out.detail


def test_released_needs_one_open_velocity(tmp_path):
    out = _released(tmp_path, '"-m*g*(3 - 2*cos(theta0))"', "{r: l, theta: 0}")
    assert out.status == "error" and "all velocities but one" in out.detail
