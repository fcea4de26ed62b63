"""The double-precision deflection (mechbook.engine.scattering_float) and the decisions it
serves, against closed forms derived here:

- Coulomb V = k/r: tan(Θ/2) = k/(2Eb) (tests/test_scattering.py's derivation).
- The hard sphere of radius a, V = 0 outside: Θ = 2 acos(b/a) for b < a, 0 beyond.
- V = −k/r + α/r²: with u = 1/r and l = b√(2mE), u'' + g²u = −c, g² = 1 + α/(Eb²),
  c = −k/(2Eb²); u = A cos(gψ) − c/g² vanishes on the asymptotes ψ = ±ψ∞, and u' = 1/b
  there gives A² = 1/(g²b²) + c²/g⁴, so cos(gψ∞) = κ/√(g² + κ²) with κ = cb = −k/(2Eb),
  and Θ = π − 2ψ∞ = π − (2/g) acos(κ/√(g² + κ²)). Near the centre the 1/r² wall throws the
  orbit back (Θ → π as b → 0), far out the attraction pulls it in (Θ → 0⁻): Θ(b) falls
  through 0 to a least value (a rainbow) and rises again, so it is not monotone.
- V = −α/r⁴: B(r)² = r² + α/(E r²), least at r² = √(α/E): b_c = √(2√(α/E)).
- V = k/√r: far out the integrand of Θ after r = r_s/(1 − w²) has a √(1 − w²) branch point
  at w = 1, where Gauss–Legendre converges slowly: double precision cannot say.
"""

from __future__ import annotations

import math

import mpmath
import pytest
import sympy as sp
from systems import PLANE

import mechbook.engine.scattering as engine
import mechbook.engine.scattering_float as fl
import mechbook.verify.quantities.scattering as quantity
from mechbook.engine.analysis import Analysis
from mechbook.errors import UnsupportedError
from mechbook.model.problem import load_problem

K, M, E = 0.7, 1.3, 0.9


def _system(tmp_path, name: str, potential: str, core: str | None = None):
    path = tmp_path / f"{name}.yaml"
    path.write_text(PLANE.format(name=name, potential=potential))
    analysis = Analysis(load_problem(path))
    dyn = analysis.dynamics(None)
    pt = dict(analysis.problem.values())
    k = next(s for s in pt if str(s) == "k")
    sc = engine.Scattering(dyn, dyn.sys.q[0], None if core is None else sp.sympify(core,
                                                                               {"k": k}))
    return sc, pt


def _orbit(sc, pt, b: float, dps: int = 20):
    return sc.orbit(pt, sp.Float(repr(b), 30), sp.Float(repr(E), 30), dps)


def _well(b: float) -> float:  # V = −k/r + k/r² (α = k), the closed form above
    g = math.sqrt(1 + K / (E * b * b))
    kappa = -K / (2 * E * b)
    return math.pi - 2 / g * math.acos(kappa / math.sqrt(g * g + kappa * kappa))


SCAN = [0.8 * 10 ** (-2 + 4 * j / 15) for j in range(16)]


@pytest.mark.parametrize("name, potential, core, exact", [
    ("coulomb", "k/r", None, lambda b: 2 * math.atan(K / (2 * E * b))),
    ("sphere", "0", "k", lambda b: 2 * math.acos(b / K) if b < K else 0.0),
    ("well", "-k/r + k/r**2", None, _well),
])
def test_the_double_precision_deflection_is_the_closed_form_within_its_bound(
        tmp_path, name, potential, core, exact):
    sc, pt = _system(tmp_path, name, potential, core)
    decided = 0
    for b in SCAN:
        got = fl.float_deflection(_orbit(sc, pt, b))
        if got is None:
            continue
        theta, bound = got
        decided += 1
        assert bound <= fl.MAX_ERROR, (b, bound)
        assert abs(theta - exact(b)) <= bound, (b, theta, exact(b), bound)
    assert decided >= 12, decided  # most of the scan is decided in double precision


def test_the_closed_form_well_is_not_monotone_on_the_scan():
    steps = [_well(y) - _well(x) for x, y in zip(SCAN, SCAN[1:], strict=False)]
    assert any(s > 1e-12 for s in steps) and any(s < -1e-12 for s in steps)


class _Beam:
    def __init__(self, sc):
        self.engine = sc


def _decision(sc, pt, b: float) -> str:
    try:
        quantity._one_branch(_Beam(sc), pt, sp.Float(repr(b), 30), sp.Float(repr(E), 30))
    except UnsupportedError as exc:
        return str(exc)
    return "one branch"


def _mp_calls(monkeypatch) -> list:
    """The 20-digit deflections the scan asks for, counted."""
    calls = []
    real = engine.Orbit.deflection.func

    def counted(self):
        calls.append(float(self.b))
        return real(self)

    prop = property(counted)
    monkeypatch.setattr(engine.Orbit, "deflection", prop)
    return calls


@pytest.mark.parametrize("name, potential, core, b, verdict", [
    ("well", "-k/r + k/r**2", None, 0.8, "Θ(b) is not monotone"),
    ("coulomb", "k/r", None, 0.8, "one branch"),
    ("sphere", "0", "k", 0.5, "one branch"),          # Θ = 0 on the scan's far half
])
def test_the_double_precision_scan_decides_as_the_twenty_digit_one(
        tmp_path, monkeypatch, name, potential, core, b, verdict):
    sc, pt = _system(tmp_path, name, potential, core)
    calls = _mp_calls(monkeypatch)
    quick = _decision(sc, pt, b)
    assert verdict in quick, quick
    assert len(calls) <= 4, calls  # decided in double precision, all but a few
    monkeypatch.setattr(quantity, "float_deflection", lambda orbit: None)
    sc2, pt2 = _system(tmp_path, name + "-exact", potential, core)
    exact = _decision(sc2, pt2, b)
    assert exact == quick
    assert len(calls) >= 16  # every orbit at 20 digits this time


def test_where_double_precision_cannot_say_the_scan_takes_twenty_digits(tmp_path,
                                                                        monkeypatch):
    """V = k/√r: no double-precision value (the branch point at w = 1); the scan's
    decision is the 20-digit one, every orbit asked at 20 digits."""
    sc, pt = _system(tmp_path, "halfpow", "k/sqrt(r)")
    assert all(fl.float_deflection(_orbit(sc, pt, b)) is None for b in SCAN[::5])
    calls = _mp_calls(monkeypatch)
    assert _decision(sc, pt, 0.8) == "one branch"
    assert len(calls) == 16


def test_a_step_within_its_bound_of_the_threshold_is_taken_at_twenty_digits(tmp_path,
                                                                           monkeypatch):
    """A double-precision bound as wide as a step: the two orbits are asked at 20 digits
    and the decision is theirs."""
    sc, pt = _system(tmp_path, "coulomb-wide", "k/r")
    real = fl.float_deflection

    def wide(orbit):
        got = real(orbit)
        return None if got is None else (got[0], 1.0)  # a bound wider than every step

    monkeypatch.setattr(quantity, "float_deflection", wide)
    calls = _mp_calls(monkeypatch)
    assert _decision(sc, pt, 0.8) == "one branch"
    assert len(calls) == 16


def test_no_numpy_form_means_no_double_precision_value(tmp_path, monkeypatch):
    sc, pt = _system(tmp_path, "coulomb-none", "k/r")
    monkeypatch.setattr(engine.Scattering, "float_functions", None)
    assert fl.float_deflection(_orbit(sc, pt, 0.8)) is None


def test_a_captured_orbit_is_left_to_the_twenty_digit_search(tmp_path):
    """V = −k/r²: b < √(k/E) falls in; double precision does not say so itself."""
    sc, pt = _system(tmp_path, "isq", "-k/r**2")
    assert fl.float_deflection(_orbit(sc, pt, 0.3)) is None
    assert _orbit(sc, pt, 0.3).turning.captured


def test_the_critical_impact_parameter_with_and_without_the_double_precision_grid(
        tmp_path, monkeypatch):
    sc, pt = _system(tmp_path, "quartic", "-k/r**4")
    E30 = sp.Float(repr(E), 30)
    orbit = sc.orbit(pt, 1, E30, engine.DPS)
    grid = [mpmath.mpf(10) ** (mpmath.mpf(j) / 10) for j in range(-120, 121)]
    picked = engine._candidates(orbit, grid)
    best = min(range(len(grid)), key=lambda j: abs(float(grid[j]) ** 2 - math.sqrt(K / E)))
    assert picked is not None and best in picked and len(picked) < 20, picked
    with mpmath.workdps(50):  # k the float 0.7, E the 30-digit 0.9, as the engine has them
        exact = mpmath.sqrt(2 * mpmath.sqrt(mpmath.mpf(K) / engine._mp(E30, 50)))
        quick = engine.critical_impact_parameter(sc, pt, E30)
        assert abs(quick - exact) < mpmath.mpf(10) ** -35
    monkeypatch.setattr(engine.Scattering, "float_parts", None)
    sc2, pt2 = _system(tmp_path, "quartic-exact", "-k/r**4")
    with mpmath.workdps(50):
        slow = engine.critical_impact_parameter(sc2, pt2, E30)
        assert abs(slow - exact) < mpmath.mpf(10) ** -35


def test_the_turning_point_from_the_double_precision_bracket_holds_its_digits(tmp_path):
    """Coulomb: r_min = k/(2E) + √(k²/(4E²) + b²), at 40 digits to 1e-38."""
    sc, pt = _system(tmp_path, "coulomb-root", "k/r")
    orbit = _orbit(sc, pt, 0.8, engine.DPS)
    with mpmath.workdps(60):  # k the float 0.7, b and E the 30-digit 0.8 and 0.9
        k = mpmath.mpf(K)
        e, b = (engine._mp(sp.Float(repr(x), 30), 60) for x in (E, 0.8))
        exact = k / (2 * e) + mpmath.sqrt(k * k / (4 * e * e) + b * b)
        assert abs(orbit.r_min - exact) < mpmath.mpf(10) ** -38 * exact


def test_the_two_central_differences_must_agree(tmp_path, monkeypatch):
    """Steps of 1e-2·b and 1e-1·b leave the two central differences of dΘ/db apart by far
    more than 1e-15: the cross section is unsupported, not judged."""
    from ruamel.yaml import YAML

    from mechbook.verify.answers import load_answers
    from mechbook.verify.checker import check_problem

    path = tmp_path / "coulomb-steps.yaml"
    path.write_text(PLANE.format(name="coulomb-steps", potential="k/r"))
    analysis = Analysis(load_problem(path))
    doc = {"problem": analysis.problem.id, "source": "test",
           "symbols": {"b": {"value": 0.8, "positive": True},
                       "E": {"value": 0.9, "positive": True}},
           "parts": [{"part": "x", "cite": "test", "quantity": "cross_section",
                      "impact_parameter": "b", "energy": "E", "scattering_angle": "Chi",
                      "book": "(k/(4*E))**2/sin(Chi/2)**4"}]}
    key = tmp_path / "key.yaml"
    YAML().dump(doc, key.open("w"))
    monkeypatch.setattr(quantity, "STEPS", (2, 1))
    out = check_problem(analysis, load_answers(key))[0]
    assert out.status.value == "unsupported" and "not resolved" in out.detail, out.detail
