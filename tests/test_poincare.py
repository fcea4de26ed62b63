"""`poincare` and `bifurcation`: return maps, their fixed points, multipliers and stability,
and the onset of a period doubling, against closed forms derived here.

- The damped driven linear oscillator m·ẍ + b·ẋ + k·x = F cos ωt: its stroboscopic fixed
  point is the steady response at t = 0, x = Re X, ẋ = −ω Im X with X = F/(k − mω² + ibω),
  and its multipliers are exp(λT), λ the roots of mλ² + bλ + k.
- A kicked rotor with kicks of width ε, V = K cos θ · P(t), P = 1/ε for |t mod 1| < ε/2 (a
  rectangular pulse: sign() of a cosine), sampled at t = 1/2: the fixed points θ = 0, π
  with θ̇ = 0, and the monodromy F(τ)·exp(Aε)·F(τ), F(τ) = [[1, τ], [0, 1]], τ = (1 − ε)/2,
  A = [[0, 1], [K cos θ/ε, 0]]; as ε → 0 the standard map's, μ² − (2 + K cos θ)μ + 1 = 0.
  The period doubling at θ = π where that trace is −2 (K = 4 for the standard map).
- Two uncoupled oscillators ω1, ω2, the surface x = 0 crossed upwards at energy E: the fixed
  point (0, 0, √(2E), 0), multipliers exp(±2πiω2/ω1).
- The driven damped pendulum θ̈ + bθ̇ + ω0² sin θ = F cos ωt at small F: its period-1
  orbit tends to the linear response (harmonic balance to first order), whose error falls
  like F³ (relative to the amplitude, like F²).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import scipy.linalg as sl
from ruamel.yaml import YAML
from scipy.optimize import brentq
from systems import load_analysis

from mechbook.numerics.poincare import ReturnMap, Section
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

OSC = """id: x
source: a test
title: a damped driven oscillator
parameters:
  m: {value: 1.3}
  k: {value: 2.0}
  b: {value: 0.3}
  F: {value: 0.5}
  w: {value: 1.3}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: k*x**2/2
forces: {x: -b*xdot + F*cos(w*t)}
"""
M, K, B, F, W = 1.3, 2.0, 0.3, 0.5, 1.3

ROTOR = """id: x
source: a test
title: a kicked rotor
parameters:
  K: {value: KVAL}
  eps: {value: 0.02}
coordinates:
  theta: {}
kinetic: thetadot**2/2
potential: K*cos(theta)*(1 + sign(cos(2*pi*t) - cos(pi*eps)))/(2*eps)
"""
EPS = 0.02

TWO = """id: x
source: a test
title: two oscillators
parameters:
  w1: {value: 1.0}
  w2: {value: 1.7}
coordinates:
  x: {}
  y: {}
kinetic: (xdot**2 + ydot**2)/2
potential: (w1**2*x**2 + w2**2*y**2)/2
"""

PENDULUM = """id: x
source: a test
title: a driven damped pendulum
parameters:
  b: {value: 0.5}
  w0: {value: 1.0}
  F: {value: FVAL}
  w: {value: 0.6}
coordinates:
  theta: {}
kinetic: thetadot**2/2
potential: -w0**2*cos(theta)
forces: {theta: -b*thetadot + F*cos(w*t)}
"""


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    return tmp_path_factory.mktemp("poincare")


@pytest.fixture(scope="module")
def osc(tree):
    return load_analysis(tree, OSC, "9101")


def rotor(tree, k: float, num: str):
    return load_analysis(tree, ROTOR.replace("KVAL", repr(k)), num)


def check(analysis, tmp_path, **part):
    doc = {"problem": analysis.problem.id, "source": "test",
           "parts": [{"part": "x", "cite": "test", **part}]}
    YAML().dump(copy.deepcopy(doc), (tmp_path / "key.yaml").open("w"))
    out = check_problem(analysis, load_answers(tmp_path / "key.yaml"))[0]
    return out.status, out.detail


def osc_closed_form():
    X = F / complex(K - M * W**2, B * W)
    T = 2 * math.pi / W
    lam = np.roots([M, B, K])
    return (X.real, -W * X.imag), np.exp(lam * T)


STROBE = {"period": "2*pi/w"}


def _osc_book(scale_x=1.0, scale_mu=1.0, stable=True):
    # the closed form written out, so that a mutant is a change of a number in it
    d = "((k - m*w**2)**2 + (b*w)**2)"
    x = f"{scale_x}*F*(k - m*w**2)/{d}"
    xdot = f"w*F*b*w/{d}"
    lam = "(-b/(2*m) + sqrt(-1)*sqrt(k/m - b**2/(4*m**2)))"
    lam_bar = "(-b/(2*m) - sqrt(-1)*sqrt(k/m - b**2/(4*m**2)))"
    mus = [f"{scale_mu}*exp({lam}*2*pi/w)", f"exp({lam_bar}*2*pi/w)"]
    return {"at": {"x": x, "xdot": xdot}, "multipliers": mus, "stable": stable}


def test_the_oscillators_book_is_its_closed_form():
    """The key below is the closed form above (a check of the test's own algebra)."""
    (x, xd), mu = osc_closed_form()
    d = (K - M * W**2) ** 2 + (B * W) ** 2
    assert abs(F * (K - M * W**2) / d - x) < 1e-15 and abs(W * F * B * W / d - xd) < 1e-15
    lam = -B / (2 * M) + 1j * math.sqrt(K / M - B**2 / (4 * M**2))
    assert min(abs(mu - np.exp(lam * 2 * math.pi / W))) < 1e-14


@pytest.mark.parametrize("book, status", [
    (_osc_book(), "pass"),
    (_osc_book(scale_x=1.01), "fail"),
    (_osc_book(scale_x=1.000001), "fail"),
    (_osc_book(scale_mu=1.01), "fail"),
    (_osc_book(scale_mu=1.000001), "fail"),
    (_osc_book(stable=False), "fail"),        # a stable point called unstable
    ({"stable": True}, "pass"),
])
def test_driven_oscillator_fixed_point(osc, tmp_path, book, status):
    got = check(osc, tmp_path, quantity="poincare", section=STROBE,
                initial={"x": 0, "xdot": 0}, book=book)
    assert got[0] == status, got


def test_monodromy_is_the_matrix_exponential(osc):
    rm = ReturnMap(osc.system(), osc.dynamics(), osc.problem.values(),
                   Section(period=2 * math.pi / W))
    orbit = rm.orbit(np.zeros(2))
    A = np.array([[0, 1], [-K / M, -B / M]])
    assert np.max(np.abs(orbit.jacobian - sl.expm(A * 2 * math.pi / W))) < 1e-9
    assert np.max(np.abs(rm.finite_difference(orbit.points[0]) - orbit.jacobian)) < 1e-6


def rotor_monodromy(k: float, theta: float) -> np.ndarray:
    tau = (1 - EPS) / 2
    Fm = np.array([[1, tau], [0, 1]])
    A = np.array([[0, 1], [k * math.cos(theta) / EPS, 0]])
    return Fm @ sl.expm(A * EPS) @ Fm


ROTOR_SECTION = {"period": 1, "phase": "1/2"}


@pytest.mark.parametrize("theta, stable", [(math.pi, True), (0.0, False)])
def test_kicked_rotor_fixed_points_and_multipliers(tree, tmp_path, theta, stable):
    k = 1.5
    an = rotor(tree, k, "9102")
    mu = np.linalg.eigvals(rotor_monodromy(k, theta))
    at = {"theta": repr(theta), "thetadot": 0}
    mus = [repr(complex(m)).strip("()").replace("j", "*sqrt(-1)") for m in mu]
    base = dict(quantity="poincare", section=ROTOR_SECTION,
                initial={"theta": repr(theta + 0.1), "thetadot": 0.05})
    assert check(an, tmp_path, **base, book={"at": at, "multipliers": mus,
                                             "stable": stable})[0] == "pass"
    assert check(an, tmp_path, **base, book={"stable": not stable})[0] == "fail"
    wrong = [f"({m})*1.000001" for m in mus]
    assert check(an, tmp_path, **base, book={"multipliers": wrong})[0] == "fail"
    wrong = [f"({m})*1.01" for m in mus]
    assert check(an, tmp_path, **base, book={"multipliers": wrong})[0] == "fail"


@pytest.mark.parametrize("at, stable, status", [
    ({"theta": "pi", "thetadot": 0}, True, "pass"),     # a fixed point, not the guess's
    ({"theta": "pi", "thetadot": 0}, False, "fail"),    # judged on the book's orbit
    ({"theta": "1", "thetadot": 0}, None, "fail"),      # no orbit: Newton from it goes on
    ({"theta": "pi*1.000001", "thetadot": 0}, None, "fail"),
])
def test_a_book_point_away_from_newtons_guess(tree, tmp_path, at, stable, status):
    """`initial:` is Newton's guess only: the rotor has fixed points at 0 and π, and the
    book's π is an orbit although Newton from near 0 finds 0. Only Newton from the book's
    point can refute it (the kicks leave θ = π at rest: the torque K sin θ vanishes)."""
    an = rotor(tree, 1.5, "9102")
    book = {"at": at} if stable is None else {"at": at, "stable": stable}
    got = check(an, tmp_path, quantity="poincare", section=ROTOR_SECTION,
                initial={"theta": 0.1, "thetadot": 0.05}, book=book)
    assert got[0] == status, got


def test_kicked_rotor_tends_to_the_standard_map(tree):
    """Narrow kicks: the multipliers approach the standard map's, to O(Kε)."""
    k = 1.5
    an = rotor(tree, k, "9102")
    rm = ReturnMap(an.system(), an.dynamics(), an.problem.values(), Section(period=1.0,
                                                                            phase=0.5))
    for theta in (math.pi, 0.0):
        orbit = rm.orbit(np.array([theta + 0.1, 0.0]))
        standard = np.roots([1, -(2 + k * math.cos(theta)), 1])
        for m in standard:
            assert min(abs(orbit.multipliers - m)) < 2 * k * EPS


def rotor_doubling() -> float:
    """K where the trace of the pulsed rotor's monodromy at θ = π is −2."""
    return brentq(lambda k: np.trace(rotor_monodromy(k, math.pi)) + 2, 3.0, 5.0, xtol=1e-14)


@pytest.mark.parametrize("scale, status", [(1, "pass"), (1.01, "fail"), (1.000001, "fail")])
def test_period_doubling_of_the_kicked_rotor(tree, tmp_path, scale, status):
    kstar = rotor_doubling()
    assert abs(kstar - 4) < 0.1  # the standard map's K = 4, to O(ε)
    an = rotor(tree, 3.5, "9103")
    got = check(an, tmp_path, quantity="bifurcation", section=ROTOR_SECTION,
                initial={"theta": "pi", "thetadot": 0}, over={"K": [3.5, 4.5]},
                kind="period_doubling", book=repr(kstar * scale))
    assert got[0] == status, got


def test_no_onset_in_the_bracket_is_unsupported(tree, tmp_path):
    an = rotor(tree, 3.5, "9103")
    got = check(an, tmp_path, quantity="bifurcation", section=ROTOR_SECTION,
                initial={"theta": "pi", "thetadot": 0}, over={"K": [1, 2]},
                kind="period_doubling", book="4")
    assert got[0] == "unsupported" and "no onset" in got[1]


@pytest.mark.parametrize("book, status", [
    ({"at": {"x": 0, "y": 0, "ydot": 0, "xdot": "sqrt(2*E0)"},
      "multipliers": ["exp(2*pi*sqrt(-1)*w2/w1)", "exp(-2*pi*sqrt(-1)*w2/w1)"],
      "stable": True}, "pass"),
    ({"at": {"xdot": "1.01*sqrt(2*E0)"}}, "fail"),
    ({"multipliers": ["exp(2*pi*sqrt(-1)*1.000001*w2/w1)",
                      "exp(-2*pi*sqrt(-1)*1.000001*w2/w1)"]}, "fail"),
])
def test_surface_section_of_two_oscillators(tree, tmp_path, book, status):
    an = load_analysis(tree, TWO, "9104")
    doc = {"problem": an.problem.id, "source": "test", "symbols": {"E0": {"value": 0.5}},
           "parts": [{"part": "x", "cite": "test", "quantity": "poincare",
                      "section": {"coordinate": "x", "value": 0, "direction": "up"},
                      "energy": "E0", "initial": {"y": 0.01, "xdot": 0.9}, "book": book}]}
    YAML().dump(doc, (tmp_path / "key.yaml").open("w"))
    out = check_problem(an, load_answers(tmp_path / "key.yaml"))[0]
    assert out.status == status, out.detail


def test_a_section_never_crossed_is_an_error_with_its_line(tree, tmp_path):
    an = load_analysis(tree, TWO, "9104")
    got = check(an, tmp_path, quantity="poincare",
                section={"coordinate": "x", "value": 5, "direction": "up", "within": 50},
                initial={"x": 0, "xdot": 0.5}, book={"stable": True})
    assert got[0] == "error" and "key.yaml:" in got[1] and "does not cross" in got[1], got


def test_driven_pendulum_period_one_orbit_is_harmonic_balance_at_small_forcing(tree):
    """θ ≈ A cos(ωt − φ), A e^{−iφ} = F/(ω0² − ω² + ibω): the error at t = 0 falls like F³
    (the first neglected harmonic-balance term is of order A³), so relative to A like F²."""
    errors = []
    for n, f in enumerate((0.04, 0.02)):
        an = load_analysis(tree, PENDULUM.replace("FVAL", repr(f)), f"92{n}0")
        rm = ReturnMap(an.system(), an.dynamics(), an.problem.values(),
                       Section(period=2 * math.pi / 0.6))
        orbit = rm.orbit(np.zeros(2))
        X = f / complex(1.0 - 0.36, 0.5 * 0.6)
        hb = np.array([X.real, -0.6 * X.imag])
        errors.append(float(np.max(np.abs(orbit.points[0] - hb))) / abs(X))
        assert orbit.spectral_radius < 1  # a stable orbit (damped, small forcing)
    assert errors[0] < 1e-3
    ratio = errors[0] / errors[1]
    assert 3.0 < ratio < 5.0  # relative error ~ A²: halving F quarters it


def test_a_surface_section_of_a_driven_system_is_an_error(osc, tmp_path):
    got = check(osc, tmp_path, quantity="poincare",
                section={"coordinate": "x", "value": 0, "direction": "up"},
                initial={"x": 0, "xdot": 0.5}, book={"stable": True})
    assert got[0] == "error" and "key.yaml:" in got[1] and "autonomous" in got[1], got


def test_a_constrained_system_is_unsupported(tmp_path):
    text = """id: x
source: a test
title: a bead held on a circle
parameters:
  R: {value: 1.0}
  F: {value: 0.1}
coordinates:
  x: {}
  y: {}
kinetic: (xdot**2 + ydot**2)/2
constraints:
  - {name: hoop, expr: x**2 + y**2 - R**2}
forces: {x: F*cos(t)}
"""
    an = load_analysis(tmp_path, text, "9105")
    got = check(an, tmp_path, quantity="poincare", section={"period": "2*pi"},
                initial={"x": 1}, book={"stable": True})
    assert got[0] == "unsupported" and "constraints" in got[1], got


def test_period_two_orbit_born_in_the_doubling(tree):
    """Past the onset K*, the period-2 orbit around θ = π: two distinct points that P swaps,
    det DP² = 1 (a Hamiltonian map), on the unit circle (stable), and its size growing like
    √(K − K*) (the normal form of a period doubling): quartering K − K* halves it."""
    kstar = rotor_doubling()
    sizes = []
    for n, dk in enumerate((0.04, 0.01)):
        an = rotor(tree, kstar + dk, f"911{n}")
        rm = ReturnMap(an.system(), an.dynamics(), an.problem.values(),
                       Section(period=1.0, phase=0.5))
        orbit = rm.orbit(np.array([math.pi + 0.3, 0.0]), 2)
        a, b = orbit.points
        assert np.max(np.abs(rm.difference(rm(a, tangent=False)[0], b))) < 1e-9
        assert np.max(np.abs(rm.difference(a, b))) > 0.1
        assert abs(np.linalg.det(orbit.jacobian) - 1) < 1e-9
        assert abs(orbit.spectral_radius - 1) < 1e-8
        sizes.append(float(np.max(np.abs(rm.difference(a, np.array([math.pi, 0.0]))))))
    assert sizes[0] / sizes[1] == pytest.approx(2.0, rel=0.02)


@pytest.mark.parametrize("initial, book, status", [
    ({"theta": "pi + 0.3", "thetadot": 0}, {"stable": True}, "pass"),
    ({"theta": "pi + 0.3", "thetadot": 0}, {"stable": False}, "fail"),
    ({"theta": "pi", "thetadot": 0}, {"stable": False}, "fail"),  # the fixed point itself
])
def test_a_period_two_claim(tree, tmp_path, initial, book, status):
    an = rotor(tree, rotor_doubling() + 0.04, "9112")
    got = check(an, tmp_path, quantity="poincare", section=ROTOR_SECTION, order=2,
                initial=initial, book=book)
    assert got[0] == status, got
    if initial["theta"] == "pi":
        assert "period shorter than 2" in got[1]


SPRING_ROTOR = """id: x
source: a test
title: a kicked rotor on a spring
parameters:
  K: {value: 0.5}
  eps: {value: 0.02}
  s: {value: 1.0}
coordinates:
  theta: {}
kinetic: thetadot**2/2
potential: s*theta**2/2 + K*cos(theta)*(1 + sign(cos(2*pi*t) - cos(pi*eps)))/(2*eps)
"""


def spring_rotor_fold() -> float:
    """K where θ = 0 turns hyperbolic through μ = +1: between kicks the spring turns the
    state by F(τ) = [[cos wτ, sin wτ/w], [−w sin wτ, cos wτ]] (w = √s = 1), in a kick
    δθ̈ = (K/ε − s)δθ; the trace of F·E·F reaches +2."""
    tau = (1 - EPS) / 2
    Fm = np.array([[math.cos(tau), math.sin(tau)], [-math.sin(tau), math.cos(tau)]])

    def trace(k):
        E = sl.expm(np.array([[0, 1], [k / EPS - 1.0, 0]]) * EPS)
        return np.trace(Fm @ E @ Fm) - 2

    return brentq(trace, 0.1, 3.0, xtol=1e-14)


@pytest.mark.parametrize("scale, status", [(1, "pass"), (1.01, "fail"), (1.000001, "fail")])
def test_fold_of_a_kicked_rotor_on_a_spring(tree, tmp_path, scale, status):
    kstar = spring_rotor_fold()
    an = load_analysis(tree, SPRING_ROTOR, "9120")
    got = check(an, tmp_path, quantity="bifurcation", section=ROTOR_SECTION,
                initial={"theta": 0, "thetadot": 0}, over={"K": [0.1, 3]}, kind="fold",
                book=repr(kstar * scale))
    assert got[0] == status, got
