"""`extremum` and `part_energy` against closed forms on systems outside the books: the
resonance peak of a damped driven oscillator (over the drive frequency), the least period
of a physical pendulum (over the pivot's distance from the centre), the greatest range of
a projectile (over the launch angle, measured by integration), and the greatest kinetic
energy of one of two coupled masses over the whole later motion. Wrong locations and values
(a percent, and far below it) fail, and so does a maximum claimed as a minimum."""

from __future__ import annotations

import copy

import mpmath
import numpy as np
import pytest
from ruamel.yaml import YAML

from mechbook.engine.analysis import Analysis
from mechbook.engine.extremum import NoValue, locate, torus_maximum
from mechbook.model.problem import load_problem
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

DRIVEN = """\
id: symon-text-test-driven
source: test
title: damped driven oscillator
parameters:
  m: {value: 0.7}
  k: {value: 3.0}
  c: {value: 0.4}
  F0: {value: 0.2, small: true}
  Omega: {value: 2.0}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: k*x**2/2
forces: {x: -c*xdot + F0*cos(Omega*t)}
"""

PHYSICAL = """\
id: symon-text-test-physical
source: test
title: physical pendulum, pivot at distance d from the centre
parameters:
  m: {value: 0.5}
  rho: {doc: radius of gyration about the centre, value: 0.3}
  d: {doc: distance of the pivot from the centre, value: 0.4}
  g: {}
coordinates:
  theta: {}
kinetic: m*(rho**2 + d**2)*thetadot**2/2
potential: -m*g*d*cos(theta)
"""

PROJECTILE = """\
id: symon-text-test-projectile
source: test
title: projectile
parameters:
  m: {value: 0.2}
  g: {}
coordinates:
  x: {}
  y: {}
particles:
  ball: {mass: m, position: [x, y]}
gravity: {}
"""

COUPLED = """\
id: symon-text-test-coupled
source: test
title: two masses between walls, coupled by a spring
parameters:
  m: {value: 0.5}
  k: {value: 2.0}
  kappa: {value: 0.3}
coordinates:
  x1: {}
  x2: {}
particles:
  one: {mass: m, position: [x1]}
  two: {mass: m, position: [x2]}
potential: k*x1**2/2 + k*x2**2/2 + kappa*(x1 - x2)**2/2
"""


def _analysis(tmp_path_factory, text: str) -> Analysis:
    name = text.split("\n", 1)[0].removeprefix("id: symon-")
    path = tmp_path_factory.mktemp("extremum") / f"{name}.yaml"
    path.write_text(text)
    return Analysis(load_problem(path))


@pytest.fixture(scope="module")
def driven(tmp_path_factory):
    return _analysis(tmp_path_factory, DRIVEN)


@pytest.fixture(scope="module")
def physical(tmp_path_factory):
    return _analysis(tmp_path_factory, PHYSICAL)


@pytest.fixture(scope="module")
def projectile(tmp_path_factory):
    return _analysis(tmp_path_factory, PROJECTILE)


@pytest.fixture(scope="module")
def coupled(tmp_path_factory):
    return _analysis(tmp_path_factory, COUPLED)


def check(analysis: Analysis, tmp_path, symbols: dict | None = None, **part):
    doc = {"problem": analysis.problem.id, "source": "test", "symbols": symbols or {},
           "parts": [{"part": "x", "cite": "test", **part}]}
    if not doc["symbols"]:
        del doc["symbols"]
    YAML().dump(copy.deepcopy(doc), (tmp_path / "key.yaml").open("w"))
    out = check_problem(analysis, load_answers(tmp_path / "key.yaml"))[0]
    return out.status, out.detail


# ---- the optimizer itself ---------------------------------------------------------------------
def test_locate_finds_a_resonance_peak_to_30_digits():
    with mpmath.workdps(60):
        z = mpmath.mpf("0.3")

        def f(x):
            return 1 / mpmath.sqrt((1 - x**2) ** 2 + (z * x) ** 2)

        e = locate(f, mpmath.mpf("0.1"), 3, "maximum")
        exact = mpmath.sqrt(1 - z**2 / 2)
        assert e.interior and e.curvature < 0
        assert abs(e.x - exact) < mpmath.mpf(10) ** -30
        assert abs(e.value - f(exact)) < mpmath.mpf(10) ** -50


def test_locate_reports_an_extremum_at_the_end_of_the_interval():
    e = locate(lambda x: x**2, 1, 2, "maximum")
    assert not e.interior and e.x == 2


def test_torus_maximum_of_a_beat():
    def F(t):
        return (mpmath.sin(t[0]) - mpmath.mpf("1.1") * mpmath.sin(t[1])) ** 2 + \
            (mpmath.cos(t[0]) - mpmath.cos(t[1])) ** 2

    with mpmath.workdps(40):
        _, v = torus_maximum(F, 2)
        assert abs(v - mpmath.mpf("2.1") ** 2) < mpmath.mpf(10) ** -30


def test_torus_maximum_scanned_in_double_precision_finds_the_same_maximum():
    """The vectorized double-precision scan only picks the starting node: Newton's method on
    the 40-digit function gives the same maximum as the 40-digit scan."""
    def F(t):
        return (mpmath.sin(t[0]) - mpmath.mpf("1.1") * mpmath.sin(t[1])) ** 2 + \
            (mpmath.cos(t[0]) - mpmath.cos(t[1])) ** 2

    def scan(th):
        return (np.sin(th[:, 0]) - 1.1 * np.sin(th[:, 1])) ** 2 + \
            (np.cos(th[:, 0]) - np.cos(th[:, 1])) ** 2

    with mpmath.workdps(40):
        slow_at, slow = torus_maximum(F, 2)
        fast_at, fast = torus_maximum(F, 2, scan=scan)
        assert abs(fast - slow) < mpmath.mpf(10) ** -30
        assert abs(fast - mpmath.mpf("2.1") ** 2) < mpmath.mpf(10) ** -30
        with pytest.raises(NoValue):
            torus_maximum(F, 2, scan=lambda th: np.full(len(th), np.nan))


# ---- a response peak over the drive frequency --------------------------------------------------
PEAK_AT = "sqrt(k/m - c**2/(2*m**2))"
PEAK = "F0/(c*sqrt(k/m - c**2/(4*m**2)))"


@pytest.mark.parametrize("book, status", [
    ({"at": PEAK_AT, "value": PEAK}, "pass"),
    ({"at": PEAK_AT}, "pass"),
    ({"value": PEAK}, "pass"),
    ({"at": "sqrt(k/m)"}, "fail"),                                  # the undamped frequency
    ({"at": f"(101/100)*{PEAK_AT}"}, "fail"),                       # 1 % off
    ({"at": f"(1000000001/1000000000)*{PEAK_AT}"}, "fail"),         # 1e-9 off
    ({"value": f"(101/100)*{PEAK}"}, "fail"),
    ({"value": f"(1000000001/1000000000)*{PEAK}"}, "fail"),
    ({"value": "F0/(c*sqrt(k/m))"}, "fail"),                        # the value at sqrt(k/m)
])
def test_resonance_peak_over_the_drive_frequency(driven, tmp_path, book, status):
    got, detail = check(driven, tmp_path, quantity="extremum", about={"x": 0},
                        maximize={"amplitude": "x"}, over={"Omega": ["sqrt(k/m)/5",
                                                                     "5*sqrt(k/m)"]},
                        book=book)
    assert got == status, detail


def test_a_maximum_claimed_as_a_minimum_fails(driven, tmp_path):
    got, detail = check(driven, tmp_path, quantity="extremum", about={"x": 0},
                        minimize={"amplitude": "x"}, over={"Omega": ["sqrt(k/m)/5",
                                                                     "5*sqrt(k/m)"]},
                        book={"at": PEAK_AT})
    assert got == "fail" and "end of the interval" in detail


def test_a_peak_outside_the_interval_fails(driven, tmp_path):
    got, detail = check(driven, tmp_path, quantity="extremum", about={"x": 0},
                        maximize={"amplitude": "x"}, over={"Omega": ["2*sqrt(k/m)",
                                                                     "5*sqrt(k/m)"]},
                        book={"at": PEAK_AT})
    assert got == "fail" and "end of the interval" in detail


# ---- a least period over a parameter ------------------------------------------------------------
@pytest.mark.parametrize("book, status", [
    ({"at": "rho", "value": "2*pi*sqrt(2*rho/g)"}, "pass"),
    ({"at": "(101/100)*rho"}, "fail"),
    ({"at": "(1000000001/1000000000)*rho"}, "fail"),
    ({"value": "(101/100)*2*pi*sqrt(2*rho/g)"}, "fail"),
    ({"value": "2*pi*sqrt(rho/g)"}, "fail"),
])
def test_least_period_of_a_physical_pendulum(physical, tmp_path, book, status):
    got, detail = check(physical, tmp_path, quantity="extremum", about={"theta": 0},
                        minimize={"period": 1}, over={"d": ["rho/5", "5*rho"]}, book=book)
    assert got == status, detail


def test_least_frequency_is_not_a_least_period(physical, tmp_path):
    """The frequency is greatest where the period is least: a minimum claimed fails."""
    got, _ = check(physical, tmp_path, quantity="extremum", about={"theta": 0},
                   minimize={"frequency": 1}, over={"d": ["rho/5", "5*rho"]},
                   book={"at": "rho"})
    assert got == "fail"
    got, detail = check(physical, tmp_path, quantity="extremum", about={"theta": 0},
                        maximize={"frequency": 1}, over={"d": ["rho/5", "5*rho"]},
                        book={"at": "rho", "value": "sqrt(g/(2*rho))"})
    assert got == "pass", detail


# ---- a measured trajectory quantity over an initial condition ------------------------------------
SYMBOLS = {"alpha": {"value": 0.6}, "v0": {"value": 3.0}}
LAUNCH = {"xdot": "v0*cos(alpha)", "ydot": "v0*sin(alpha)"}


@pytest.mark.parametrize("book, status", [
    ({"at": "pi/4", "value": "v0**2/g"}, "pass"),
    ({"at": "(101/100)*pi/4"}, "fail"),
    ({"value": "(101/100)*v0**2/g"}, "fail"),
    ({"value": "(100001/100000)*v0**2/g"}, "fail"),   # 1e-5: beyond the stated 1e-6
])
def test_greatest_range_of_a_projectile(projectile, tmp_path, book, status):
    got, detail = check(projectile, tmp_path, symbols=SYMBOLS, quantity="extremum",
                        maximize={"event": "y", "advance": "x"}, initial=LAUNCH,
                        over={"alpha": ["1/10", "3/2"]}, book=book)
    assert got == status, detail


# ---- a part's energy along the motion, and its greatest value over all later times --------------
W1, W2 = "sqrt(k/m)", "sqrt((k + 2*kappa)/m)"
KINETIC_ONE = f"m*(a/2)**2*({W1}*sin({W1}*t) + {W2}*sin({W2}*t))**2/2"


@pytest.mark.parametrize("book, status", [
    (KINETIC_ONE, "pass"),
    (f"(101/100)*{KINETIC_ONE}", "fail"),
    (f"m*(a/2)**2*({W1}*sin({W1}*t) - {W2}*sin({W2}*t))**2/2", "fail"),
])
def test_energy_of_one_mass_along_the_motion(coupled, tmp_path, book, status):
    """x1 = (a/2)(cos w1 t + cos w2 t) from x1 = a at rest: mass one's energy is its
    kinetic energy (the springs belong to no one part)."""
    got, detail = check(coupled, tmp_path, symbols={"a": {"value": 0.1}},
                        quantity="part_energy", about={"x1": 0, "x2": 0}, body="one",
                        initial={"x1": "a"}, book=book)
    assert got == status, detail


@pytest.mark.parametrize("book, status", [
    ({"value": f"m*(a/2)**2*({W1} + {W2})**2/2"}, "pass"),
    ({"value": f"(1000001/1000000)*m*(a/2)**2*({W1} + {W2})**2/2"}, "fail"),
    ({"value": f"m*(a/2)**2*({W2})**2/2"}, "fail"),
])
def test_greatest_energy_of_one_mass_over_the_motion(coupled, tmp_path, book, status):
    got, detail = check(coupled, tmp_path, symbols={"a": {"value": 0.1}},
                        quantity="extremum", about={"x1": 0, "x2": 0},
                        maximize={"energy_of": "one"}, over="motion", initial={"x1": "a"},
                        book=book)
    assert got == status, detail


def test_an_unknown_part_is_a_clear_error(coupled, tmp_path):
    got, detail = check(coupled, tmp_path, symbols={"a": {"value": 0.1}},
                        quantity="part_energy", about={"x1": 0, "x2": 0}, body="three",
                        initial={"x1": "a"}, book="0")
    assert got == "error" and "one, two" in detail
