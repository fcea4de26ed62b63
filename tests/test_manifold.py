"""States on the constraint manifold, and degrees of freedom counted by rank.

A constrained system's solved accelerations hold on its constraint manifold only; a claim
about its motion (a first integral, a degree-of-freedom count) is judged there. The
systems and their derivations: tests/constrained_systems.py.
"""

from __future__ import annotations

import mpmath
import pytest
import sympy as sp
from constrained_systems import CIRCLE, SPHERICAL, check, key

from mechbook.core.numeval import evaluate
from mechbook.model.manifold import StateManifold
from mechbook.model.problem import load_problem
from mechbook.model.system import system_of
from mechbook.verify.compare import Sampler

ENERGY = "m*(xdot**2 + ydot**2)/2 + m*g*y"


def _conserved(book: str) -> str:
    return key(f"  - part: a\n    cite: energy\n    quantity: conserved\n    book: \"{book}\"\n")


@pytest.mark.parametrize("book, status", [
    (ENERGY, "pass"),
    ("1.01*m*(xdot**2 + ydot**2)/2 + m*g*y", "fail"),  # a factor on T
    ("m*(xdot**2 + ydot**2)/2 + 1.01*m*g*y", "fail"),  # a factor on V
    ("m*xdot**2/2 + m*g*y", "fail"),  # a term dropped
    ("m*(xdot**2 + ydot**2)/2 + m*g*y + 1e-6*m*g*x", "fail"),  # a small wrong term
])
def test_first_integral_on_the_circle(tmp_path, book, status):
    out = check(tmp_path, "9401", CIRCLE, _conserved(book))["a"]
    assert out.status == status, out.detail


def test_named_energy_on_the_circle(tmp_path):
    out = check(tmp_path, "9402", CIRCLE, _conserved(f"E = {ENERGY}"))["a"]
    assert out.status == "pass", out.detail


def _count(book) -> str:
    return key(f"  - part: a\n    cite: freedoms\n    quantity: mode_count\n    book: {book}\n")


@pytest.mark.parametrize("system, book, status", [
    (SPHERICAL, "2", "pass"), (SPHERICAL, "3", "fail"), (SPHERICAL, "1", "fail"),
    (CIRCLE, "1", "pass"), (CIRCLE, "2", "fail"),
    (SPHERICAL, "{configuration: 2, velocity: 2}", "pass"),
    (SPHERICAL, "{configuration: 3}", "fail"),
])
def test_degrees_of_freedom_by_rank(tmp_path, system, book, status):
    out = check(tmp_path, "9403", system, _count(book))["a"]
    assert out.status == status, out.detail


def test_degrees_of_freedom_at_a_point(tmp_path):
    answers = key("  - part: a\n    cite: freedoms\n    quantity: mode_count\n"
                  "    about: {x: 0, y: 0, z: -l}\n    book: 2\n")
    assert check(tmp_path, "9404", SPHERICAL, answers)["a"].status == "pass"


def _circle(tmp_path):
    path = tmp_path / "problems" / "lim" / "9405.yaml"
    path.parent.mkdir(parents=True)
    path.write_text(CIRCLE.replace("NUM", "9405"))
    return system_of(load_problem(path))


def test_projection_reaches_the_working_precision(tmp_path):
    sys = _circle(tmp_path)
    manifold = StateManifold(sys)
    x, y = sys.q
    xd, yd = sys.qd
    values = {k: sp.Float(v, 30) for k, v in sys.problem.values().items()}
    point = manifold.project({**values, x: sp.Float(0.3), y: sp.Float(-0.9),
                              xd: sp.Float(0.7), yd: sp.Float(0.2)})
    assert point is not None
    g = sys.constraints[0][1]
    v, scale = evaluate(g, point, 40)
    assert abs(v) < 1e-28 * scale
    gdot = sys.dt(g)
    v, scale = evaluate(gdot, point, 40)
    assert abs(v) < 1e-28 * max(scale, 1)
    # the least change: a point already on the circle stays where it is
    l = sys.problem.values()[sp.Symbol("l", positive=True)]  # noqa: E741
    on = {**values, x: sp.Float(0, 30), y: -sp.Float(l, 30), xd: sp.Float(0.5, 30),
          yd: sp.Float(0, 30)}
    again = manifold.project(on)
    assert abs(float(again[y] + l)) < 1e-25 and abs(float(again[xd] - 0.5)) < 1e-25


def test_sampler_draws_states_on_the_manifold(tmp_path):
    sys = _circle(tmp_path)
    manifold = StateManifold(sys)
    sampler = Sampler(sys.problem.values(), manifold=manifold)
    g = sys.constraints[0][1]
    for _ in range(5):
        pt = sampler.draw(list(sys.q) + list(sys.qd))
        with mpmath.workdps(40):
            assert abs(evaluate(g, pt, 40)[0]) < 1e-25
            assert abs(evaluate(sys.dt(g), pt, 40)[0]) < 1e-25
    # parameters alone are not projected (no state drawn)
    assert set(sampler.draw()) == set(sys.problem.values())


def test_freedoms_of_redundant_rows_count_once(tmp_path):
    sys = _circle(tmp_path)
    manifold = StateManifold(sys)
    x, y = sys.q
    values = {k: sp.Float(v, 30) for k, v in sys.problem.values().items()}
    point = manifold.project({**values, x: sp.Float(0.3), y: sp.Float(0.9)})
    f = manifold.freedoms(point)
    assert (f.configuration, f.velocity) == (1, 1)


def _event(initial: str, book: str) -> str:
    return key("  - part: a\n    cite: quarter swing\n    quantity: event_time\n"
               f"    initial: {initial}\n    event: x\n    estimate: {{rtol: 1e-6}}\n"
               f"    book: {book}\n")


QUARTER = "0.580881729115339815263"  # sqrt(l/g)·K(sin²(θ0/2)), l = 1.3, g = 9.81, θ0 = 0.5


@pytest.mark.parametrize("initial, book, status", [
    # released from rest at 0.5 rad on the circle: a quarter of the finite-amplitude
    # period, T/4 = sqrt(l/g)·K(k²), k = sin(θ0/2) (mpmath's ellipk, computed here)
    ("{x: l*sin(1/2), y: -l*cos(1/2)}", QUARTER, "pass"),
    ("{x: l*sin(1/2), y: -l*cos(1/2)}", "0.5814", "fail"),
    # the velocities left unstated are solved from ẋx + ẏy = 0: here zero
    ("{x: l*sin(1/2), y: -l*cos(1/2), xdot: 0}", QUARTER, "pass"),
])
def test_a_trajectory_starts_on_the_manifold(tmp_path, initial, book, status):
    out = check(tmp_path, "9406", CIRCLE, _event(initial, book))["a"]
    assert out.status == status, out.detail


def test_a_start_off_the_manifold_is_refused(tmp_path):
    out = check(tmp_path, "9407", CIRCLE, _event("{x: l, y: l}", QUARTER))["a"]
    assert out.status == "error" and "breaks the constraints" in out.detail, out.detail
