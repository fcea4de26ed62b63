"""`action` and `action_hamiltonian` (mechbook/verify/quantities/action.py) against closed
forms derived here, in the 1/2π convention J = (1/2π)∮p dq: the oscillator, a quartic
well, the planar Kepler problem's actions and H(J), and a particle in a box as the limit of
steep walls. Each key passes, and a 1 % and a 1e-6 wrong one (and 2J) fail."""

from __future__ import annotations

import json

import mpmath
import pytest
from systems import load_analysis

from mechbook.errors import SpecError
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem


def _outcome(tmp_path, num: str, problem: str, part: dict, symbols: dict):
    header = f"id: lim-{num}\nsource: test\ntitle: an action test\n"
    an = load_analysis(tmp_path, header + problem, num)
    d = tmp_path / "answers" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    f = d / f"{num}.yaml"
    f.write_text(json.dumps({"problem": f"lim-{num}", "source": "test", "symbols": symbols,
                             "parts": [{"part": "a", "cite": "t", **part}]}))
    return check_problem(an, load_answers(f))[0]


def _status(*args) -> str:
    return _outcome(*args).status.value


def well(power: int) -> str:
    return f"""\
parameters:
  m: {{value: 1.3}}
  lam: {{value: 0.7}}
coordinates:
  x: {{}}
particles:
  p: {{mass: m, position: [x]}}
potential: lam*x**{power}
"""


# The oscillator V = λx² (ω = sqrt(2λ/m)): the orbit is an ellipse in (x, p) with
# semi-axes sqrt(E/λ) and sqrt(2mE), area π·sqrt(2m/λ)·E, so J = area/2π = E/ω.
OSC_J = "E/sqrt(2*lam/m)"


@pytest.mark.parametrize("book, want", [
    (OSC_J, "pass"),
    (f"({OSC_J})*(1 + 1e-6)", "fail"),
    (f"({OSC_J})*1.01", "fail"),
    (f"2*({OSC_J})", "fail"),           # J and 2J told apart
    (f"2*pi*({OSC_J})", "fail"),        # the ∮p dq convention is not this quantity's
])
def test_the_oscillators_action_at_a_given_energy(tmp_path, book, want):
    part = {"quantity": "action", "coordinate": "x", "energy": "E", "inside": 0,
            "book": book}
    assert _status(tmp_path, "9801", well(2), part, {"E": {"value": 0.4}}) == want


@pytest.mark.parametrize("book, want", [
    ("A**2*sqrt(2*lam*m)/2", "pass"),   # E = λA², J = λA²/ω
    ("A**2*sqrt(2*lam*m)/2*(1 + 1e-6)", "fail"),
])
def test_the_oscillators_action_from_a_start(tmp_path, book, want):
    part = {"quantity": "action", "coordinate": "x", "initial": {"x": "A"}, "book": book}
    assert _status(tmp_path, "9802", well(2), part, {"A": {"value": 0.6}}) == want


@pytest.mark.parametrize("book, want", [
    ("J*sqrt(2*lam/m)", "pass"),                   # H = ωJ, ∂H/∂J = ω
    ("J*sqrt(2*lam/m)*(1 + 1e-6)", "fail"),
    ("J*sqrt(2*lam/m) + 1e-6*lam", "fail"),        # the energy right to 1e-6: H(J) fails
    ("J**2*sqrt(2*lam/m)/J", "pass"),
])
def test_the_oscillators_hamiltonian_in_its_action(tmp_path, book, want):
    part = {"quantity": "action_hamiltonian", "actions": {"J": "x"},
            "initial": {"x": "A"}, "book": book}
    out = _outcome(tmp_path, "9803", well(2), part, {"A": {"value": 0.6}, "J": {}})
    assert out.status.value == want, out.detail
    if want == "pass":  # the frequency also measured from the integrated motion
        assert "integrated motion's frequency" in out.detail


def _well_constant(n: int):
    """V = λx^(2n): J = (1/π)∫_{−a}^{a} sqrt(2m(E − λx^(2n))) dx, a = (E/λ)^(1/(2n)); with
    x = a·u, J = (2/π)·a·sqrt(2mE)·I_n, I_n = ∫₀¹ sqrt(1 − u^(2n)) du = B(1/(2n), 3/2)/(2n)
    (u^(2n) = s). Returns I_n as text for a key, checked here against the quadrature."""
    text = f"gamma(1/{2 * n})*gamma(3/2)/(gamma(1/{2 * n} + 3/2)*{2 * n})"
    with mpmath.workdps(30):
        closed = mpmath.beta(mpmath.mpf(1) / (2 * n), 1.5) / (2 * n)
        assert abs(closed - mpmath.quad(lambda u: mpmath.sqrt(1 - u ** (2 * n)), [0, 1])) \
            < 1e-25
    return text


def quartic_j(n: int = 2) -> str:
    return f"2/pi*(E/lam)**(1/{2 * n})*sqrt(2*m*E)*{_well_constant(n)}"


@pytest.mark.parametrize("mutate, want", [
    (lambda s: s, "pass"),
    (lambda s: f"({s})*(1 + 1e-6)", "fail"),
    (lambda s: f"({s})*1.01", "fail"),
    (lambda s: s.replace("(E/lam)**(1/4)", "(E/lam)**(1/4 + 1e-6)"), "fail"),
])
def test_a_quartic_wells_action(tmp_path, mutate, want):
    """J ∝ E^(3/4) with the Beta constant derived in _well_constant."""
    part = {"quantity": "action", "coordinate": "x", "energy": "E", "inside": 0,
            "book": mutate(quartic_j(2))}
    assert _status(tmp_path, "9804", well(4), part, {"E": {"value": 0.5}}) == want


def test_a_quartic_wells_hamiltonian_and_frequency(tmp_path):
    """J = C·E^(3/4) inverted: H = (J/C)^(4/3); ω = ∂H/∂J then is the engine's 2π/T."""
    C = quartic_j(2).replace("(E/lam)**(1/4)*sqrt(2*m*E)", "lam**(-1/4)*sqrt(2*m)")
    good = f"(J/({C}))**(4/3)"
    for book, want in ((good, "pass"), (f"({good})*(1 + 1e-6)", "fail"),
                       (good.replace("4/3", "4/3 + 1e-6"), "fail")):
        part = {"quantity": "action_hamiltonian", "actions": {"J": "x"}, "energy": "E",
                "inside": 0, "book": book}
        out = _outcome(tmp_path, "9805", well(4), part, {"E": {"value": 0.5}, "J": {}})
        assert out.status.value == want, book
        if want == "pass":
            assert "integrated motion's frequency" in out.detail, out.detail


def test_a_box_is_the_limit_of_steep_walls(tmp_path):
    """A particle in a box of length 2a bounces with |p| = sqrt(2mE): J = 2·2a·sqrt(2mE)/
    (2π) = (2/π)·a·sqrt(2mE). The engine has no hard walls: the box is the limit n → ∞ of
    V = λ(x/a)^(2n), whose exact J (the Beta form above, λ = 1/a^(2n) folded in) the engine
    reproduces at n = 8 to 1e-15; there the box's formula is off by the factor
    (E/λ)^(1/(2n))·I_n (exactly), and both tend to it."""
    part = {"quantity": "action", "coordinate": "x", "energy": "E", "inside": 0,
            "book": quartic_j(8)}
    assert _status(tmp_path, "9806", well(16), part, {"E": {"value": 0.5}}) == "pass"
    box = "2/pi*(1/lam)**(1/16)*sqrt(2*m*E)"  # a = λ^(-1/(2n)): the wall's place
    part["book"] = box
    assert _status(tmp_path, "9806", well(16), part, {"E": {"value": 0.5}}) == "fail"
    with mpmath.workdps(30):  # I_n → 1 and E^(1/2n) → 1: the box's J is the limit
        assert abs(mpmath.beta(mpmath.mpf(1) / 2000, 1.5) / 2000 - 1) < 1e-3


KEPLER = """\
parameters:
  m: {value: 1.0}
  k: {value: 1.0}
coordinates:
  r: {positive: true}
  phi: {}
particles:
  p: {mass: m, position: [r*cos(phi), r*sin(phi)]}
potential: -k/r
"""
# A bound orbit of angular momentum L and eccentricity e: E = −mk²(1 − e²)/(2L²), semi-major
# axis a = k/(2|E|) (a point the radial motion passes through). The radial action
# J_r = (1/π)∫ sqrt(2m(E + k/r) − L²/r²) dr between the roots = −L + k·sqrt(m/(−2E))
# (the standard contour integral; checked against mpmath's quadrature in the test), the
# azimuth's J_φ = L over a full turn, so E = −mk²/(2(J_r + J_φ)²) and both frequencies are
# mk²/(J_r + J_φ)³ (the degenerate Kepler problem).
ENERGY = "-m*k**2*(1 - e**2)/(2*L**2)"
KEPLER_MOTION = {"energy": ENERGY, "inside": "k/(2*m*k**2*(1 - e**2)/(2*L**2))",
                 "momenta": {"phi": "L"}}
KEPLER_SYMBOLS = {"e": {"value": 0.5}, "L": {"value": 0.9}}


def test_the_radial_action_closed_form_is_the_quadrature():
    with mpmath.workdps(30):
        m, k, L, e = 1, 1, mpmath.mpf("0.9"), mpmath.mpf("0.5")
        E = -m * k**2 * (1 - e**2) / (2 * L**2)
        r1, r2 = (L**2 / (m * k * (1 + e)), L**2 / (m * k * (1 - e)))
        quad = mpmath.quad(lambda r: mpmath.sqrt(2 * m * (E + k / r) - L**2 / r**2),
                           [r1, r2]) / mpmath.pi
        assert abs(quad - (-L + k * mpmath.sqrt(m / (-2 * E)))) < 1e-20


@pytest.mark.parametrize("coordinate, book, want", [
    ("r", f"-L + k*sqrt(m/(-2*({ENERGY})))", "pass"),
    ("r", f"(-L + k*sqrt(m/(-2*({ENERGY}))))*(1 + 1e-6)", "fail"),
    ("r", f"(-L + k*sqrt(m/(-2*({ENERGY}))))*1.01", "fail"),
    ("r", f"k*sqrt(m/(-2*({ENERGY})))", "fail"),   # J_r + J_φ is not J_r
    ("phi", "L", "pass"),
    ("phi", "L*(1 + 1e-6)", "fail"),
    ("phi", "2*pi*L", "fail"),
])
def test_keplers_actions(tmp_path, coordinate, book, want):
    part = {"quantity": "action", "coordinate": coordinate, **KEPLER_MOTION, "book": book}
    assert _status(tmp_path, "9807", KEPLER, part, KEPLER_SYMBOLS) == want


@pytest.mark.parametrize("book, want", [
    ("-m*k**2/(2*(Jr + Jphi)**2)", "pass"),
    ("-m*k**2/(2*(Jr + Jphi)**2)*(1 + 1e-6)", "fail"),
    ("-m*k**2/(2*(Jr + Jphi)**2)*1.01", "fail"),
    ("-m*k**2/(2*(Jr + 2*Jphi)**2)", "fail"),
])
def test_keplers_hamiltonian_in_the_actions(tmp_path, book, want):
    part = {"quantity": "action_hamiltonian", "actions": {"Jr": "r", "Jphi": "phi"},
            **KEPLER_MOTION, "book": book}
    out = _outcome(tmp_path, "9808", KEPLER, part, {**KEPLER_SYMBOLS, "Jr": {}, "Jphi": {}})
    assert out.status.value == want, out.detail
    if want == "pass":  # measured too, from the state at `inside:` with E and L
        assert "integrated motion's frequency" in out.detail


def test_an_unbound_motion_has_no_action(tmp_path):
    """E > 0 on the Kepler problem: r runs away; an error at the part, nothing checked."""
    part = {"quantity": "action", "coordinate": "r", "energy": "B", "inside": 1,
            "momenta": {"phi": "L"}, "book": "L"}
    out = _outcome(tmp_path, "9809", KEPLER, part, {"B": {"value": 0.5}, "L": {"value": 1}})
    assert out.status.value == "error" and "unbound motion has no action" in out.detail


def test_the_motion_must_be_given(tmp_path):
    part = {"quantity": "action", "coordinate": "x", "book": "E"}
    out = _outcome(tmp_path, "9810", well(2), part, {"E": {"value": 1}})
    assert out.status.value == "error" and "give the motion" in out.detail
    out = _outcome(tmp_path, "9812", well(2), {"quantity": "action", "energy": "E",
                                               "inside": 0, "book": "E"}, {"E": {"value": 1}})
    assert out.status.value == "error" and "name the `coordinate:`" in out.detail
    with pytest.raises(SpecError):
        _outcome(tmp_path, "9811", well(2), {**part, "energy": "E", "frobnicate": 1},
                 {"E": {"value": 1}})


def test_a_quadrature_short_of_its_digits_is_unsupported(tmp_path, monkeypatch):
    """Where the 50- and 60-digit quadratures do not agree to what is asked, the part is
    unsupported with the reason, never a fail (the demand raised beyond 60 digits here)."""
    import mpmath as mp

    from mechbook.verify.quantities import action

    monkeypatch.setattr(action, "RESOLVED", mp.mpf(10) ** -70)
    part = {"quantity": "action", "coordinate": "x", "energy": "E", "inside": 0,
            "book": f"2*({OSC_J})"}   # even a wrong key: not a fail
    out = _outcome(tmp_path, "9813", well(2), part, {"E": {"value": 0.4}})
    assert out.status.value == "unsupported" and "quadrature reached only" in out.detail


def test_each_orbit_is_built_once_per_point_and_precision(tmp_path, monkeypatch):
    # H(J) = −mk²/2(J_r + J_φ)² (the closed form above) passes, and its actions, radial
    # frequency, angular rate and energy at a point read one orbit at each precision:
    # no level-set orbit is built twice with the same energy, momenta, start and digits
    from mechbook.engine.levelset import LevelSet

    built = []
    orbit_at = LevelSet.orbit_at

    def counted(self, energy, momenta, inside, values, dps):
        built.append((str(self.c), mpmath.nstr(energy, 40), tuple(mpmath.nstr(p, 40)
                      for p in momenta), mpmath.nstr(inside, 40), dps))
        return orbit_at(self, energy, momenta, inside, values, dps)

    monkeypatch.setattr(LevelSet, "orbit_at", counted)
    part = {"quantity": "action_hamiltonian", "actions": {"Jr": "r", "Jphi": "phi"},
            **KEPLER_MOTION, "book": "-m*k**2/(2*(Jr + Jphi)**2)"}
    out = _outcome(tmp_path, "9808", KEPLER, part, {**KEPLER_SYMBOLS, "Jr": {}, "Jphi": {}})
    assert out.status.value == "pass", out.detail
    assert len(built) == len(set(built)) >= 12  # six points at two precisions at least
