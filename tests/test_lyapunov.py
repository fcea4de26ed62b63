"""`lyapunov`: the largest exponent by Benettin's method, against closed forms and
well-known verdicts.

- An overdamped oscillator ẍ + bẋ + kx = 0 (b² > 4k): every tangent vector ends along the
  slower mode, so the exponent is the larger root of λ² + bλ + k, −b/2 + √(b²/4 − k), exactly
  (the other mode's share dies like e^{−2√(b²/4 − k)·t}).
- Two uncoupled oscillators (a linear centre): tangent vectors rotate, all exponents zero.
- Hénon–Heiles, V = (x² + y²)/2 + x²y − y³/3: at E = 1/12 the orbits are regular (KAM tori
  fill the section), at E = 1/6 the start (0, −0.1) on the y-axis lies in the chaotic sea
  (Hénon & Heiles 1964; its exponent is positive, of order 0.1 or below).
- The driven damped pendulum θ̈ + θ̇/q + sin θ = g cos(ω t), ω = 2/3, q = 2 (Baker &
  Gollub's values): chaotic at g = 1.5, a periodic attractor (a negative exponent) at 0.9.
- A kicked rotor (rectangular kicks of width ε, the standard map as ε → 0): chaotic at
  K = 6, regular next to the elliptic fixed point at K = 1.5.
- An unbounded motion (an inverted oscillator) has no exponent: an error with its line.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from ruamel.yaml import YAML
from systems import load_analysis

from mechbook.errors import UnsupportedError
from mechbook.numerics.lyapunov import RESOLUTION, largest_exponent
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

OVERDAMPED = """id: x
source: a test
title: an overdamped oscillator
parameters:
  b: {value: 3.0}
  k: {value: 1.0}
coordinates:
  x: {}
kinetic: xdot**2/2
potential: k*x**2/2
forces: {x: -b*xdot}
"""

CENTRE = """id: x
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

HENON_HEILES = """id: x
source: a test
title: the Henon-Heiles system
parameters: {}
coordinates:
  x: {}
  y: {}
kinetic: (xdot**2 + ydot**2)/2
potential: (x**2 + y**2)/2 + x**2*y - y**3/3
"""

PENDULUM = """id: x
source: a test
title: a driven damped pendulum
parameters:
  q: {value: 2.0}
  g: {value: 1.5}
  w: {value: 0.6666666666666666}
coordinates:
  theta: {}
kinetic: thetadot**2/2
potential: -cos(theta)
forces: {theta: -thetadot/q + g*cos(w*t)}
"""

ROTOR = """id: x
source: a test
title: a kicked rotor
parameters:
  K: {value: 6.0}
  eps: {value: 0.02}
coordinates:
  theta: {}
kinetic: thetadot**2/2
potential: K*cos(theta)*(1 + sign(cos(2*pi*t) - cos(pi*eps)))/(2*eps)
"""

INVERTED = """id: x
source: a test
title: an inverted oscillator
parameters:
  k: {value: 1.0}
coordinates:
  x: {}
kinetic: xdot**2/2
potential: -k*x**2/2
"""


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    return tmp_path_factory.mktemp("lyapunov")


def check(analysis, tmp_path, symbols=None, **part):
    doc = {"problem": analysis.problem.id, "source": "test",
           "parts": [{"part": "x", "cite": "test", "quantity": "lyapunov", **part}]}
    if symbols:
        doc["symbols"] = symbols
    YAML().dump(copy.deepcopy(doc), (tmp_path / "key.yaml").open("w"))
    out = check_problem(analysis, load_answers(tmp_path / "key.yaml"))[0]
    return out.status, out.detail


EXPONENT = "-b/2 + sqrt(b**2/4 - k)"


@pytest.mark.parametrize("book, status", [
    (EXPONENT, "pass"),
    (f"({EXPONENT})*1.01", "fail"),
    (f"({EXPONENT})*1.000001", "fail"),
    ("-b/2 - sqrt(b**2/4 - k)", "fail"),      # the other (faster) exponent
    ("negative", "pass"),
    ("zero", "fail"),
    ("positive", "fail"),                     # resolved negative: λ + s < −b
])
def test_overdamped_oscillator_exponent_in_closed_form(tree, tmp_path, book, status):
    an = load_analysis(tree, OVERDAMPED, "9301")
    got = check(an, tmp_path, initial={"x": 1, "xdot": 0}, time=40, book=book)
    assert got[0] == status, got


@pytest.mark.parametrize("book, status", [("zero", "pass"), ("positive", "unsupported"),
                                          ("negative", "unsupported")])
def test_a_linear_centre_has_zero_exponents(tree, tmp_path, book, status):
    an = load_analysis(tree, CENTRE, "9302")
    got = check(an, tmp_path, initial={"x": 0.3, "ydot": 0.2}, time=400, book=book)
    assert got[0] == status, got


def hh_start(energy: str, y: str) -> dict:
    """(x, y, ẋ, ẏ) = (0, y, √(2E − y² + 2y³/3), 0): on the energy surface E."""
    return {"y": y, "xdot": f"sqrt(2*{energy} - ({y})**2 + 2*({y})**3/3)"}


def test_a_zero_pass_states_the_bound_it_proves(tree, tmp_path):
    """`zero` passes on |λ| + s ≤ b = 8/T: the power line must say that an exponent below b
    is not excluded, never that zero is resolved "beyond" the resolution."""
    an = load_analysis(tree, CENTRE, "9302")
    doc = {"problem": an.problem.id, "source": "test",
           "parts": [{"part": "x", "cite": "test", "quantity": "lyapunov", "time": 400,
                      "initial": {"x": 0.3, "ydot": 0.2}, "book": "zero"}]}
    YAML().dump(doc, (tmp_path / "key.yaml").open("w"))
    out = check_problem(an, load_answers(tmp_path / "key.yaml"))[0]
    assert out.status == "pass", out.detail
    assert f"≤ {RESOLUTION / 400:.2g}" in out.power and "not excluded" in out.power, out.power
    assert "beyond" not in out.power, out.power


def test_a_regular_orbit_claimed_positive_is_unsupported_with_the_reason(tree, tmp_path):
    """A run of length T cannot tell zero from a positive exponent below b = 8/T (a weakly
    chaotic or sticky orbit): nothing contradicts `positive`, so the claim is `unsupported`,
    never `fail`, and the reason gives b, λ, the spread, T and the run that would resolve
    it (b = 8/T: T = 4000 resolves 8/4000 = 0.002)."""
    an = load_analysis(tree, CENTRE, "9302")
    got = check(an, tmp_path, initial={"x": 0.3, "ydot": 0.2}, time=400, book="positive")
    assert got[0] == "unsupported", got
    b = RESOLUTION / 400
    assert f"resolution b = {b:.2g}" in got[1] and "not excluded" in got[1], got
    assert "λ = " in got[1] and "spread" in got[1] and "T = 400" in got[1], got
    assert "`time: 4000` resolves 0.002" in got[1], got


@pytest.mark.parametrize("lam, s, status", [
    (0.01, 0.002, "unsupported"),   # 0.008 > 0: T > 8/0.008 = 1000 would resolve it
    (0.03, 0.002, "pass"),          # λ − s = 0.028 > b = 0.02
    (-0.03, 0.002, "fail"),         # λ + s = −0.028 < −b
    (-0.01, 0.002, "unsupported"),  # a negative λ within b: a positive one not excluded
])
def test_a_sign_claim_against_the_resolution(lam, s, status):
    """`positive` at T = 400 (b = 0.02), in closed form: passes where λ − s > b, fails only
    where λ + s < −b; in between the reason names the `time:` beyond 8/(λ − s) that would
    resolve a λ − s > 0."""
    from mechbook.verify.quantities.chaos import judge_exponent_sign
    b = RESOLUTION / 400
    try:
        verdict = judge_exponent_sign("positive", lam, s, b, 400.0, "m")
    except UnsupportedError as exc:
        assert status == "unsupported", exc
        if lam - s > 0:
            assert "`time:` beyond 1000 would resolve it" in str(exc), exc
        return
    assert ("pass" if verdict.ok else "fail") == status
    mirrored = judge_exponent_sign("negative", -lam, s, b, 400.0, "m")
    assert mirrored.ok == verdict.ok


@pytest.mark.parametrize("energy, y, book, status", [
    ("1/12", "0.1", "zero", "pass"),
    ("1/12", "0.1", "positive", "unsupported"),  # below b: not excluded, not contradicted
    ("1/12", "-0.2", "zero", "pass"),
    ("1/6", "-0.1", "positive", "pass"),
    ("1/6", "-0.1", "zero", "fail"),           # regular for a chaotic orbit
    ("1/6", "-0.1", "negative", "fail"),       # resolved positive: λ − s > b
])
def test_henon_heiles_regular_and_chaotic(tree, tmp_path, energy, y, book, status):
    an = load_analysis(tree, HENON_HEILES, "9303")
    got = check(an, tmp_path, initial=hh_start(energy, y), time=1000, book=book)
    assert got[0] == status, got


@pytest.mark.parametrize("claim, status", [
    ((0.5, 0.25), "unsupported"),  # v = λ + s/2 ± s/4 overlaps [λ − s, λ + s], not around it
    ((3.0, 1.0), "fail"),          # v = λ + 3s ± s: [λ − s, λ + s] wholly outside
    ((0.0, 2.0), "pass"),          # v = λ ± 2s: [λ − s, λ + s] wholly inside
])
def test_a_value_is_judged_by_the_runs_interval(tree, tmp_path, claim, status):
    """A value claim against the run's interval [λ − s, λ + s]: pass only inside v ± tol,
    fail only outside it, else unsupported. The claims are placed from the run's own λ and
    s (computed here, with the checker's start on E = 1/6), so each lands where it is said to."""
    an = load_analysis(tree, HENON_HEILES, "9303")
    y0 = np.array([0.0, -0.1, math.sqrt(2 / 6 - 0.01 - 2e-3 / 3), 0.0])
    run = largest_exponent(an.system(), an.dynamics(), {}, y0, 1000.0)
    lam, s = run.estimate, run.spread
    assert s > 0
    shift, width = claim  # in units of the spread
    got = check(an, tmp_path, initial=hh_start("1/6", "-0.1"), time=1000,
                book=repr(lam + shift * s), tolerance=repr(width * s))
    assert got[0] == status, got
    if status == "unsupported":
        assert "neither lies within nor outside" in got[1] and "spread" in got[1], got


def test_a_wrong_value_fails(tree, tmp_path):
    """The chaotic exponent at E = 1/6 is of order 0.1 (Hénon & Heiles' orbits separate
    over tens of time units), so 1 ± 0.1 is contradicted."""
    an = load_analysis(tree, HENON_HEILES, "9303")
    got = check(an, tmp_path, initial=hh_start("1/6", "-0.1"), time=1000, book="1",
                tolerance="0.1")
    assert got[0] == "fail" and "lies outside" in got[1], got


def test_a_long_run_reports_its_progress(tree, tmp_path):
    """The checker's stage is told how far the run has got (a run stopped by check's time
    limit then says where it was), four times over the 64 windows."""
    an = load_analysis(tree, HENON_HEILES, "9303")
    doc = {"problem": an.problem.id, "source": "test",
           "parts": [{"part": "x", "cite": "test", "quantity": "lyapunov", "time": 1000,
                      "initial": hh_start("1/12", "0.1"), "book": "zero"}]}
    YAML().dump(doc, (tmp_path / "key.yaml").open("w"))
    told = []
    out = check_problem(an, load_answers(tmp_path / "key.yaml"), stage=told.append)[0]
    assert out.status == "pass"
    assert told == ["part x (lyapunov)"] + [f"part x (lyapunov): t = {t} of 1000"
                                           for t in (250, 500, 750, 1000)]
    assert f"resolution {RESOLUTION / 1000:.2g}" in out.power


@pytest.mark.parametrize("g, book, status", [
    ("1.5", "positive", "pass"),
    ("1.5", "negative", "fail"),
    ("1.5", "zero", "fail"),
    ("0.9", "negative", "pass"),
    ("0.9", "positive", "fail"),               # a periodic attractor: resolved negative
])
def test_baker_gollub_pendulum(tree, tmp_path, g, book, status):
    """A turning pendulum is bounded (θ is an angle of the equations: only θ̇ counts)."""
    an = load_analysis(tree, PENDULUM, "9304")
    got = check(an, tmp_path, initial={"theta": 0.2}, time=1000, book=book,
                estimate={"values": {"g": g}, "rtol": 0.01})
    assert got[0] == status, got


@pytest.mark.parametrize("k, start, book, status", [
    ("6", {"theta": 1.0, "thetadot": 0.3}, "positive", "pass"),
    ("6", {"theta": 1.0, "thetadot": 0.3}, "zero", "fail"),
    ("6", {"theta": 1.0, "thetadot": 0.3}, "negative", "fail"),
    ("1.5", {"theta": "pi + 0.05", "thetadot": 0}, "zero", "pass"),
    ("1.5", {"theta": "pi + 0.05", "thetadot": 0}, "positive", "unsupported"),
])
def test_kicked_rotor(tree, tmp_path, k, start, book, status):
    an = load_analysis(tree, ROTOR, "9305")
    got = check(an, tmp_path, initial=start, time=200, max_step=0.005, book=book,
                estimate={"values": {"K": k}, "rtol": 0.01})
    assert got[0] == status, got


def test_an_unbounded_motion_is_an_error_with_its_line(tree, tmp_path):
    an = load_analysis(tree, INVERTED, "9306")
    got = check(an, tmp_path, initial={"x": 0.1}, time=100, book="1")
    assert got[0] == "error" and "key.yaml:" in got[1] and "unbounded" in got[1], got


def test_the_standard_map_exponent_grows_like_log_k_over_2(tree, tmp_path):
    """For large K the standard map's exponent approaches ln(K/2) (Chirikov): at K = 6,
    1.1 within ±0.3 (the pulses' width adds ~0.1, the run's spread ~0.2) — a value claim
    with its tolerance.

    Past a few dozen kicks a chaotic run is a sample of the sea that rounding picks: the
    start (1, 0.3) passed on one machine and was unresolved (spread 0.62, a sticky stretch)
    on another whose OpenBLAS kernel rounds solve_ivp's stage sums otherwise. So eight
    starts: none may fail (the claim is true), and most pass (35 of 40 nearby starts did;
    the rest are unresolved, `unsupported` with the run's figures, as the quantity
    promises)."""
    an = load_analysis(tree, ROTOR, "9305")
    outcomes = []
    for k in range(8):
        (tmp_path / str(k)).mkdir()
        got = check(an, tmp_path / str(k), initial={"theta": 1.0, "thetadot": 0.3 + 0.1 * k},
                    time=400, max_step=0.005, book="log(3)", tolerance="0.3")
        assert got[0] in ("pass", "unsupported"), got
        assert got[0] == "pass" or "neither lies within nor outside" in got[1] \
            or "integration failed" in got[1], got
        outcomes.append(got[0])
    assert outcomes.count("pass") >= 4, outcomes
    assert math.log(3) == pytest.approx(1.0986, abs=1e-4)


def test_a_run_past_its_budget_stops_and_says_so(tree):
    """After four windows the run projects its cost; past the budget it stops (check's time
    limit is then never reached by a part that would not finish)."""
    an = load_analysis(tree, HENON_HEILES, "9303")
    y0 = np.array([0.0, 0.1, math.sqrt(2 / 12 - 0.01 + 2e-3 / 3), 0.0])
    with pytest.raises(UnsupportedError, match="would take about"):
        largest_exponent(an.system(), an.dynamics(), {}, y0, 1000.0, budget=1e-9)
    run = largest_exponent(an.system(), an.dynamics(), {}, y0, 1000.0)
    assert len(run.logs) == 64 and run.seconds < 60
