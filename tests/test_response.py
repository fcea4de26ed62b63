"""Linear response on small hand-solved systems: exponents, decay rates, forced motion from
rest, steady amplitudes, resonances, simultaneous diagonalization, matrices, the
characteristic polynomial; and the cross-checks that measure decay rates and steady
amplitudes from simulations. Every check must also fail a wrong value."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from systems import load_analysis as load

from mechbook.crosscheck.frequencies import frequency_crosscheck
from mechbook.crosscheck.response import response_crosscheck
from mechbook.engine import response
from mechbook.engine.analysis import Analysis
from mechbook.errors import UnsupportedError
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

DAMPED = """\
id: lim-9301
source: test
title: damped driven oscillator
parameters:
  m: {value: 1.5}
  k: {value: 6.0}
  b: {value: 0.3}
  F0: {value: 0.01, small: true}
  w: {value: 1.1}
coordinates:
  x: {}
particles:
  mass: {mass: m, position: [x]}
potential: k*x**2/2
dissipation: b*xdot**2/2
forces: {x: F0*cos(w*t)}
"""

TWO = """\
id: lim-9302
source: test
title: two masses, three springs, friction on one
parameters:
  m: {value: 1.0}
  k: {value: 2.0}
  c: {value: 0.5}
  b: {value: 0.2}
  F0: {value: 0.01, small: true}
  w: {value: 0.7}
coordinates:
  x1: {}
  x2: {}
particles:
  p1: {mass: m, position: [x1]}
  p2: {mass: m, position: [x2]}
potential: (k*x1**2 + c*(x2 - x1)**2 + k*x2**2)/2
dissipation: BDISS
forces: {x2: F0*cos(w*t)}
"""


def check(tmp_path: Path, an: Analysis, parts: list[dict]) -> list:
    d = tmp_path / "answers" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    f = d / f"{an.problem.id.split('-')[1]}.yaml"
    f.write_text(json.dumps({"problem": an.problem.id, "source": "test",
                                 "parts": [{"cite": "test", **p} for p in parts]}))
    return check_problem(an, load_answers(f))


def status(tmp_path, an, part) -> str:
    out = check(tmp_path, an, [part])[0]
    return out.status


# damped oscillator m x'' + b x' + k x = F0 cos(wt): by hand
GAMMA = "b/(2*m)"
NU = "sqrt(k/m - b**2/(4*m**2))"


def test_exponents_and_decay_rates(tmp_path):
    an = load(tmp_path, DAMPED, "9301")
    good = {"part": "e", "quantity": "exponents", "about": {"x": 0},
            "book": [f"-{GAMMA} + sqrt(-1)*{NU}", f"-{GAMMA} - sqrt(-1)*{NU}"]}
    assert status(tmp_path, an, good) == "pass"
    bad = dict(good, book=[f"-{GAMMA} + sqrt(-1)*{NU}", f"-2*{GAMMA} - sqrt(-1)*{NU}"])
    assert status(tmp_path, an, bad) == "fail"
    assert status(tmp_path, an, {"part": "d", "quantity": "decay_rates", "about": {"x": 0},
                                 "book": [GAMMA]}) == "pass"
    assert status(tmp_path, an, {"part": "d", "quantity": "decay_rates", "about": {"x": 0},
                                 "book": [f"2*{GAMMA}"]}) == "fail"


def test_steady_amplitude_with_phase_lag(tmp_path):
    """X = F0/(k - m w**2 + i b w): complex, relative to the force's phase."""
    an = load(tmp_path, DAMPED, "9301")
    right = {"part": "s", "quantity": "steady_amplitude", "about": {"x": 0}, "frequency": "w",
             "book": {"x": "F0/(k - m*w**2 + sqrt(-1)*b*w)"}}
    assert status(tmp_path, an, right) == "pass"
    wrong = dict(right, book={"x": "F0/(k - m*w**2 - sqrt(-1)*b*w)"})  # lead, not lag
    assert status(tmp_path, an, wrong) == "fail"
    modulus = dict(right, book={"x": "F0/sqrt((k - m*w**2)**2 + b**2*w**2)"})  # no phase
    assert status(tmp_path, an, modulus) == "fail"


def test_forced_motion_from_rest_undamped(tmp_path):
    """x'' + w0**2 x = (F0/m) cos(wt) from rest: x = F0 (cos wt - cos w0 t)/(m (w0**2 - w**2))."""
    an = load(tmp_path, DAMPED.replace("dissipation: b*xdot**2/2\n", ""), "9301")
    w0 = "sqrt(k/m)"
    right = {"part": "m", "quantity": "motion", "about": {"x": 0},
             "initial": {"x": 0, "xdot": 0},
             "book": {"x": f"F0*(cos(w*t) - cos({w0}*t))/(m*({w0}**2 - w**2))"}}
    assert status(tmp_path, an, right) == "pass"
    particular = dict(right, book={"x": f"F0*cos(w*t)/(m*({w0}**2 - w**2))"})
    assert status(tmp_path, an, particular) == "fail"  # not from rest


def test_resonances_only_excited_modes(tmp_path):
    """Equal masses, symmetric springs: a force on x2 excites both modes; the same force on
    both masses (in phase) excites only the in-phase mode sqrt(k/m)."""
    an = load(tmp_path, TWO.replace("dissipation: BDISS\n", ""), "9302")
    both = ["sqrt(k/m)", "sqrt((k + 2*c)/m)"]
    part = {"part": "r", "quantity": "resonances", "about": {"x1": 0, "x2": 0},
            "driving": "w", "book": both}
    assert status(tmp_path, an, part) == "pass"
    assert status(tmp_path, an, dict(part, book=both[:1])) == "fail"
    sym = TWO.replace("dissipation: BDISS\n", "").replace(
        "forces: {x2: F0*cos(w*t)}", "forces: {x1: F0*cos(w*t), x2: F0*cos(w*t)}")
    an2 = load(tmp_path, sym, "9303")
    assert status(tmp_path, an2, dict(part, book=both[:1])) == "pass"
    assert status(tmp_path, an2, part) == "fail"


def test_simultaneous_diagonalization(tmp_path):
    prop = TWO.replace("BDISS", "b*(x1dot**2 + x2dot**2)/2")  # B = b*1, M = m*1
    one = TWO.replace("BDISS", "b*x1dot**2/2")  # friction on one mass only
    part = {"part": "d", "quantity": "simultaneous_diagonalization",
            "about": {"x1": 0, "x2": 0}, "book": True}
    assert status(tmp_path, load(tmp_path, prop, "9304"), part) == "pass"
    assert status(tmp_path, load(tmp_path, one, "9305"), part) == "fail"
    assert status(tmp_path, load(tmp_path, one, "9305"), dict(part, book=False)) == "pass"


def test_matrices_and_characteristic_polynomial(tmp_path):
    an = load(tmp_path, DAMPED, "9301")
    mats = {"part": "m", "quantity": "matrices", "about": {"x": 0},
            "book": {"M": [["m"]], "B": [["b"]], "K": [["k"]]}}
    assert status(tmp_path, an, mats) == "pass"
    assert status(tmp_path, an, dict(mats, book={"K": [["2*k"]]})) == "fail"
    poly = {"part": "p", "quantity": "characteristic_polynomial", "about": {"x": 0},
            "book": "m*p**2 + b*p + k"}
    assert status(tmp_path, an, poly) == "pass"
    assert status(tmp_path, an, dict(poly, book="m*p**2 - b*p + k")) == "fail"
    scaled = dict(poly, variable="P", exponent="sqrt(k/m)*P", book="P**2 + b*P/sqrt(k*m) + 1")
    assert status(tmp_path, an, scaled) == "pass"


def test_complex_modes_and_normal_transformation(tmp_path):
    an = load(tmp_path, TWO.replace("BDISS", "b*(x1dot**2 + x2dot**2)/2"), "9304")
    g = "(b/(2*m))"
    modes = {"part": "c", "quantity": "complex_modes", "about": {"x1": 0, "x2": 0},
             "book": [{"exponent": f"-{g} + sqrt(-1)*sqrt(k/m - {g}**2)",
                       "shape": {"x1": 1, "x2": 1}}]}
    assert status(tmp_path, an, modes) == "pass"
    wrong = {"part": "c", "quantity": "complex_modes", "about": {"x1": 0, "x2": 0},
             "book": [{"exponent": f"-{g} + sqrt(-1)*sqrt(k/m - {g}**2)",
                       "shape": {"x1": 1, "x2": -1}}]}
    assert status(tmp_path, an, wrong) == "fail"


def test_decay_cross_check_measures_the_damping(tmp_path):
    an = load(tmp_path, DAMPED, "9301")
    lin = an.linear(None, {an.system().q[0]: sp.S.Zero})
    x = frequency_crosscheck(an, lin, an.problem.values(), "damped")
    assert x.status == "pass", x.detail
    (mode,) = x.modes
    assert abs(mode["decay_measured"] - 0.1) / 0.1 < 1e-6  # b/(2m) = 0.3/3
    # a tampered engine (friction halved in the linear system) is caught
    lin.C = lin.C / 2
    bad = frequency_crosscheck(an, lin, an.problem.values(), "tampered")
    assert bad.status == "fail"


def test_response_cross_check_measures_the_amplitude(tmp_path):
    an = load(tmp_path, DAMPED, "9301")
    lin = an.linear(None, {an.system().q[0]: sp.S.Zero})
    values = {k: sp.Float(v, 30) for k, v in an.problem.values().items()}
    x = response_crosscheck(an, lin, values, 1.1, "response")
    assert x.status == "pass", x.detail
    assert x.error < 1e-6
    lin.K = lin.K * 1.01  # a wrong stiffness in the engine's linear system
    bad = response_crosscheck(an, lin, values, 1.1, "tampered")
    assert bad.status == "fail"


def test_jordan_size_at_a_double_root(tmp_path):
    """x'' + 2a x' + a**2 x = 0 (critical damping) has t*exp(-a t): a block of size 2."""
    text = DAMPED.replace("b: {value: 0.3}", "b: {value: 6.0}").replace(
        "forces: {x: F0*cos(w*t)}\n", "")  # b = 2*sqrt(k*m) = 6
    an = load(tmp_path, text, "9306")
    lin = an.linear(None, {an.system().q[0]: sp.S.Zero})
    values = {k: sp.Float(v, 30) for k, v in an.problem.values().items()}
    assert response.jordan_size(lin, values, complex(-2.0)) == 2
    part = {"part": "s", "quantity": "secular_growth", "about": {"x": 0},
            "restrict": {"b": "2*sqrt(k*m)"}, "book": 1}
    assert status(tmp_path, an, part) == "pass"
    assert status(tmp_path, an, dict(part, book=0)) == "fail"
    assert status(tmp_path, an, dict(part, book=2)) == "fail"
    off = {"part": "s", "quantity": "secular_growth", "about": {"x": 0}, "book": 0}
    assert status(tmp_path, an, off) == "pass"  # off the critical surface: no t terms


@pytest.mark.parametrize("omega", [0.5, 1.7])
def test_harmonic_response_solves_the_equations(tmp_path, omega):
    an = load(tmp_path, TWO.replace("BDISS", "b*x1dot**2/2"), "9305")
    lin = an.linear(None, {q: sp.S.Zero for q in an.system().q})
    values = dict(an.problem.values())
    values[sp.Symbol("w", positive=True)] = omega  # the driving frequency
    X = response.harmonic_response(lin, values, omega)
    M, C, K = lin.matrices(values)
    F = response.forcing_phasor(lin, values, omega)
    assert np.allclose((K - omega**2 * M + 1j * omega * C) @ X, F, rtol=1e-12,
                       atol=1e-14 * np.max(np.abs(F)))
    with pytest.raises(UnsupportedError):  # a force at another frequency is refused
        response.forcing_phasor(lin, values, omega * 1.3)
