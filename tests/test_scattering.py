"""Scattering on unbound orbits (issue 39, item 1) against closed forms derived here:

- Coulomb V = ±k/r (Rutherford): the orbit u = 1/r solves u'' + u = ∓k/(2Eb²), so
  tan(Θ/2) = ±k/(2Eb); the larger root of E = Eb²/r² ± k/r is r_min = ±k/(2E) +
  √(k²/(4E²) + b²); b = (k/2E)cot(Θ/2) gives dσ/dΩ = (k/4E)²/sin⁴(χ/2).
- The hard sphere of radius a (V = 0 outside): a specular reflection at angle of incidence
  asin(b/a), Θ = π − 2 asin(b/a) = 2 acos(b/a), r_min = a; b = a cos(Θ/2) gives
  dσ/dΩ = a²/4 (isotropic) and σ = πa².
- V = ±α/r²: the centrifugal coefficient l²/2m ± α rescales the orbit, Θ = π(1 − l/√(l² ±
  2mα)) = π(1 − b/√(b² ± α/E)), r_min = √(b² ± α/E). Attractive: captured exactly when
  b² < α/E, b_c = √(α/E), σ_capture = πα/E. Repulsive: with x = 1 − Θ/π, b = √(α/E)
  x/√(1 − x²), so dσ/dΩ = (α/E) x/(π sin Θ (1 − x²)²).
- V = −α/r⁴: B(r)² = r² + α/(E r²) is least at r² = √(α/E): b_c² = 2√(α/E).
- Time delay against the free line of the same b and E (v = √(2E/m)): the radial motion in
  E·c²/r² is the free one of impact parameter c, which spends √(X² − c²)/v between r = c
  and X. A hard sphere of radius a: τ = 2[(√(X² − b²) − √(a² − b²)) − √(X² − b²)]/v =
  −2√(a² − b²)/v; with V = α/r² outside it (c² = b² + α/E < a²): τ = −2√(a² − c²)/v; for
  V = ±α/r² alone the delay vanishes as X → ∞ (τ = 0).

Each key wrong by 1 % and by 1e-6 fails; a wrong verdict fails; a bound orbit or a
potential that does not vanish far out is an error with the file and line; a quadrature
that does not reach its digits is unsupported, never a fail.
"""

from __future__ import annotations

import math

import mpmath
import pytest
import sympy as sp
from ruamel.yaml import YAML
from systems import PLANE

import mechbook.engine.scattering as engine
from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem
from mechbook.verify.part import AnswerKey
from mechbook.verify.wellformed import validate_key

SYMBOLS = {"b": {"value": 0.8, "positive": True}, "E": {"value": 0.9, "positive": True}}


@pytest.fixture(scope="module")
def systems(tmp_path_factory):
    root = tmp_path_factory.mktemp("scattering")
    made = {}
    for name, potential in [("coulomb", "k/r"), ("coulomb-attractive", "-k/r"),
                            ("free", "0"), ("inverse-square", "k/r**2"),
                            ("inverse-square-attractive", "-k/r**2"),
                            ("inverse-fourth-attractive", "-k/r**4"),
                            ("logarithmic", "k*log(r)")]:
        path = root / f"{name}.yaml"
        path.write_text(PLANE.format(name=name, potential=potential))
        made[name] = Analysis(load_problem(path))
    return made


def check(analysis, tmp_path, part: dict, symbols: dict | None = None):
    """(status, detail) of one part, checked through the real key loader and checker."""
    doc = {"problem": analysis.problem.id, "source": "test",
           "symbols": symbols or SYMBOLS,
           "parts": [{"part": "x", "cite": "test", "impact_parameter": "b", "energy": "E",
                      **part}]}
    path = tmp_path / "key.yaml"
    YAML().dump(doc, path.open("w"))
    out = check_problem(analysis, load_answers(path))[0]
    return out.status.value, out.detail


def mutants(book: str) -> list[str]:
    return [f"({book})*1.01", f"({book})*(1 + 1e-6)"]


CASES = [  # (system, quantity, book, extra keys)
    ("coulomb", "deflection_angle", "2*atan(k/(2*E*b))", {}),
    ("coulomb-attractive", "deflection_angle", "-2*atan(k/(2*E*b))", {}),
    ("coulomb", "closest_approach", "k/(2*E) + sqrt(k**2/(4*E**2) + b**2)", {}),
    ("coulomb-attractive", "closest_approach", "-k/(2*E) + sqrt(k**2/(4*E**2) + b**2)", {}),
    ("coulomb", "cross_section", "(k/(4*E))**2/sin(Chi/2)**4", {"scattering_angle": "Chi"}),
    ("coulomb-attractive", "cross_section", "(k/(4*E))**2/sin(Chi/2)**4",
     {"scattering_angle": "Chi"}),
    ("inverse-square", "deflection_angle", "pi*(1 - b/sqrt(b**2 + k/E))", {}),
    ("inverse-square-attractive", "deflection_angle", "pi*(1 - b/sqrt(b**2 - k/E))",
     {"assume": ["b**2 > 2*k/E"]}),
    ("inverse-square", "closest_approach", "sqrt(b**2 + k/E)", {}),
    ("inverse-square", "cross_section",
     "k/E*(1 - Chi/pi)/(pi*sin(Chi)*(1 - (1 - Chi/pi)**2)**2)", {"scattering_angle": "Chi"}),
    ("free", "deflection_angle", "2*acos(b/k)", {"hard_core": "k", "assume": ["b < k"]}),
    ("free", "closest_approach", "k", {"hard_core": "k", "assume": ["b < k"]}),
    ("free", "cross_section", "k**2/4", {"hard_core": "k", "assume": ["b < k"]}),
    ("free", "total_cross_section", "pi*k**2", {"hard_core": "k"}),
    ("inverse-square-attractive", "critical_impact_parameter", "sqrt(k/E)", {}),
    ("inverse-square-attractive", "total_cross_section", "pi*k/E", {"process": "capture"}),
    ("inverse-fourth-attractive", "critical_impact_parameter", "sqrt(2*sqrt(k/E))", {}),
    ("coulomb-attractive", "critical_impact_parameter", "0", {}),
    ("free", "time_delay", "-2*sqrt(k**2 - b**2)/sqrt(2*E/m)",
     {"hard_core": "k", "assume": ["b < k"]}),
    ("inverse-square", "time_delay", "-2*sqrt(4*k - b**2 - k/E)/sqrt(2*E/m)",
     {"hard_core": "2*sqrt(k)", "assume": ["b**2 + k/E < 4*k"]}),
]


@pytest.mark.parametrize("system, quantity, book, extra", CASES,
                         ids=[f"{c[0]}-{c[1]}" for c in CASES])
def test_closed_forms_pass_and_mutants_fail(systems, tmp_path, system, quantity, book, extra):
    status, detail = check(systems[system], tmp_path, {"quantity": quantity, "book": book,
                                                       **extra})
    assert status == "pass", detail
    if book == "0":  # no capture: a positive b_c fails
        status, detail = check(systems[system], tmp_path, {"quantity": quantity,
                                                           "book": "1e-6", **extra})
        assert status == "fail", detail
        return
    for wrong in mutants(book):
        status, detail = check(systems[system], tmp_path, {"quantity": quantity,
                                                           "book": wrong, **extra})
        assert status == "fail", (wrong, detail)


def test_the_deflection_is_the_closed_form_to_thirty_digits(systems):
    """The engine's Θ itself (no checker): Rutherford's at 40 and 55 digits."""
    a = systems["coulomb"]
    dyn = a.dynamics(None)
    s = engine.Scattering(dyn, dyn.sys.q[0])
    pt = {k: sp.Float(str(v), 30) for k, v in a.problem.values().items()}
    b, E = sp.Float("0.8", 30), sp.Float("0.9", 30)
    theta, diff = engine.checked(s, pt, b, E, lambda o: o.deflection)
    with mpmath.workdps(50):
        k = mpmath.mpf(str(pt[sp.Symbol("k", positive=True)]))
        exact = 2 * mpmath.atan(k / (2 * mpmath.mpf("0.9") * mpmath.mpf("0.8")))
        assert abs(theta - exact) < mpmath.mpf(10) ** -29
        assert diff < mpmath.mpf(10) ** -29


@pytest.mark.parametrize("system, book, status", [
    ("inverse-square-attractive", "b**2 < k/E", "pass"),
    ("inverse-square-attractive", "b**2 < 1.000001*k/E", "fail"),    # moved by 1e-6
    ("inverse-square-attractive", "b**2 < 1.01*k/E", "fail"),
    ("inverse-square-attractive", "b**2 > k/E", "fail"),              # the verdict flipped
    ("inverse-fourth-attractive", "b**4 < 4*k/E", "pass"),
    ("inverse-fourth-attractive", "b**4 < 4.000004*k/E", "fail"),
])
def test_capture_relation(systems, tmp_path, system, book, status):
    symbols = {"b": {"value": 0.8, "positive": True}, "E": {"value": 1.1, "positive": True}}
    got, detail = check(systems[system], tmp_path, {"quantity": "capture", "book": book},
                        symbols)
    assert got == status, detail


@pytest.mark.parametrize("system, b, word, status", [
    ("coulomb", 0.8, "scattered", "pass"),
    ("coulomb", 0.8, "captured", "fail"),
    ("inverse-square-attractive", 0.3, "captured", "pass"),    # b_c = sqrt(0.7/0.9) = 0.88
    ("inverse-square-attractive", 0.3, "scattered", "fail"),
])
def test_capture_verdict(systems, tmp_path, system, b, word, status):
    symbols = {"b": {"value": b, "positive": True}, "E": {"value": 0.9, "positive": True}}
    got, detail = check(systems[system], tmp_path, {"quantity": "capture", "book": word,
                                                    "assume": ["b < 0.45"]}, symbols)
    assert got == status, detail


def test_a_captured_orbit_fails_a_finite_deflection(systems, tmp_path):
    symbols = {"b": {"value": 0.3, "positive": True}, "E": {"value": 0.9, "positive": True}}
    status, detail = check(systems["inverse-square-attractive"], tmp_path,
                           {"quantity": "deflection_angle", "book": "pi",
                            "assume": ["b < 0.45"]}, symbols)
    assert status == "fail" and "captured" in detail


@pytest.mark.parametrize("system, book, status", [
    ("inverse-square", "0", "pass"),
    ("inverse-square", "1e-6*b/sqrt(2*E/m)", "fail"),
    ("coulomb", "0", "unsupported"),          # the delay grows like log R: no limit
])
def test_time_delay_without_a_core(systems, tmp_path, system, book, status):
    got, detail = check(systems[system], tmp_path, {"quantity": "time_delay", "book": book})
    assert got == status, detail


def test_a_long_range_potential_fails_a_finite_total_cross_section(systems, tmp_path):
    status, detail = check(systems["coulomb"], tmp_path,
                           {"quantity": "total_cross_section", "book": "pi*k**2"})
    assert status == "fail" and "infinite" in detail


def test_a_glory_is_unsupported(systems, tmp_path):
    """Head-on at b → 0 the hard sphere back-scatters: at b = a·cos(π/2 − tiny)... the
    glory is sin Θ = 0 with b ≠ 0: the attractive 1/r² at b² = 4α/(3E) has Θ = −π."""
    symbols = {"b": {"value": math.sqrt(4 * 0.7 / (3 * 0.9)), "positive": True},
               "E": {"value": 0.9, "positive": True}}
    doc = {"quantity": "cross_section", "book": "1", "restrict": {"b": "sqrt(4*k/(3*E))"}}
    status, detail = check(systems["inverse-square-attractive"], tmp_path, doc, symbols)
    assert status == "unsupported" and "glory" in detail, detail


def test_several_branches_are_unsupported(systems, tmp_path):
    """The attractive 1/r² winds without bound as b → b_c: χ(b) is not monotone."""
    symbols = {"b": {"value": 1.0, "positive": True}, "E": {"value": 0.9, "positive": True}}
    status, detail = check(systems["inverse-square-attractive"], tmp_path,
                           {"quantity": "cross_section", "book": "1"}, symbols)
    assert status == "unsupported" and "several impact parameters" in detail, detail


@pytest.mark.parametrize("system, symbols, line_of", [
    ("coulomb-attractive", {"b": {"value": 0.8, "positive": True},
                            "E": {"value": -0.5}}, "energy"),            # a bound Kepler orbit
    ("logarithmic", SYMBOLS, "energy"),                                  # V → ∞ far out
])
def test_bound_orbits_are_errors_with_file_and_line(systems, tmp_path, system, symbols,
                                                    line_of):
    part = {"quantity": "deflection_angle", "book": "1"}
    status, detail = check(systems[system], tmp_path, part, symbols)
    assert status == "error", detail
    assert "key.yaml:" in detail and ("bound" in detail or "vanish" in detail), detail
    key: AnswerKey = load_answers(tmp_path / "key.yaml")
    faults = validate_key(systems[system], key)  # refused before anything is judged
    assert "x" in faults and "key.yaml:" in str(faults["x"])


def test_a_quadrature_short_of_its_digits_is_unsupported(systems, tmp_path, monkeypatch):
    """A tanh-sinh rule cut to degree 1 misses 30 digits at one of the two precisions: the
    part is unsupported with the reason, not a fail (its book value is wrong too)."""
    quad = mpmath.quad

    def short(f, points, **kw):
        return quad(f, points, maxdegree=2 if mpmath.mp.dps < 50 else 8)

    monkeypatch.setattr(engine.mpmath, "quad", short)
    fresh = Analysis(systems["coulomb"].problem)  # no orbit the other tests computed
    status, detail = check(fresh, tmp_path,
                           {"quantity": "deflection_angle", "book": "3*atan(k/(2*E*b))"})
    assert status == "unsupported" and "did not reach" in detail, detail


@pytest.mark.parametrize("book, partial, status", [
    (["k/(2*E0) + sqrt(k**2/(4*E0**2) + l**2/(2*m*E0))"], True, "pass"),
    (["1.01*(k/(2*E0) + sqrt(k**2/(4*E0**2) + l**2/(2*m*E0)))"], True, "fail"),
    (["(1 + 1e-6)*(k/(2*E0) + sqrt(k**2/(4*E0**2) + l**2/(2*m*E0)))"], True, "fail"),
])
def test_turning_points_of_an_unbound_orbit(systems, tmp_path, book, partial, status):
    """`turning_points` on a Coulomb orbit with E > 0 (it was refused: "no turning point (the
    coordinate runs away)"): the closest approach is the one finite turning point, from
    E0 = m(v² + w²)/2 + k and l = m·w at r = 1, rdot = -v, thetadot = w."""
    symbols = {"v": {"value": 0.9, "positive": True}, "w": {"value": 0.6, "positive": True}}
    doc = {"problem": "classic-coulomb", "source": "test", "symbols": symbols,
           "abbreviations": {"E0": "m*(v**2 + w**2)/2 + k", "l": "m*w"},
           "parts": [{"part": "x", "cite": "test", "quantity": "turning_points",
                      "coordinate": "r", "initial": {"r": 1, "rdot": "-v", "thetadot": "w"},
                      "partial": partial, "book": book}]}
    path = tmp_path / "key.yaml"
    YAML().dump(doc, path.open("w"))
    out = check_problem(systems["coulomb"], load_answers(path))[0]
    assert out.status.value == status, out.detail


def test_an_unbound_orbit_has_no_period(systems, tmp_path):
    symbols = {"v": {"value": 0.9, "positive": True}, "w": {"value": 0.6, "positive": True}}
    doc = {"problem": "classic-coulomb", "source": "test", "symbols": symbols,
           "parts": [{"part": "x", "cite": "test", "quantity": "motion_frequency",
                      "coordinate": "r", "initial": {"r": 1, "rdot": "-v", "thetadot": "w"},
                      "book": "1"}]}
    path = tmp_path / "key.yaml"
    YAML().dump(doc, path.open("w"))
    out = check_problem(systems["coulomb"], load_answers(path))[0]
    assert out.status.value == "unsupported" and "unbound" in out.detail, out.detail


def _crosscheck(analysis, tmp_path, book: str, extra: dict | None = None):
    from mechbook.crosscheck.problem import crosscheck_problem

    doc = {"problem": analysis.problem.id, "source": "test", "symbols": SYMBOLS,
           "parts": [{"part": "x", "cite": "test", "quantity": "deflection_angle",
                      "impact_parameter": "b", "energy": "E", "book": book, **(extra or {})}]}
    path = tmp_path / "key.yaml"
    YAML().dump(doc, path.open("w"))
    return [x for x in crosscheck_problem(analysis, load_answers(path))
            if x.kind == "scattering"]


@pytest.mark.parametrize("system, extra", [("coulomb", {}), ("coulomb-attractive", {}),
                                           ("free", {"hard_core": "k"})])
def test_the_asymptote_of_the_integrated_orbit_agrees(systems, tmp_path, system, extra):
    (x,) = _crosscheck(systems[system], tmp_path, "1", extra)
    assert x.status.value == "pass" and x.error < 1e-10, x.detail
    if system == "free":  # a hard sphere has a time delay: measured from the run too
        assert "time delay" in x.detail, x.detail


def test_the_asymptote_crosscheck_can_fail(systems, tmp_path, monkeypatch):
    """An engine whose deflection is 7e-9 off is caught by the integrated orbit."""
    real = engine.Orbit.deflection.func

    def off(self):
        with mpmath.workdps(self.dps):
            return real(self) * (1 + mpmath.mpf(2) ** -27)  # 7e-9

    monkeypatch.setattr(engine.Orbit, "deflection", property(off))
    (x,) = _crosscheck(systems["coulomb"], tmp_path, "1")
    assert x.status.value == "fail", x.detail


def test_an_orbit_is_computed_once_per_precision(systems):
    """The same numbers at the same precision give the same orbit (its values computed
    once); another precision, b or E gives another, so the two-precision check still sees
    two independent quadratures."""
    fresh = Analysis(systems["coulomb"].problem)
    dyn = fresh.dynamics()
    sc = engine.Scattering(dyn, fresh.system().q[0])
    pt = dict(fresh.problem.values())
    b, E = sp.Float("0.8", 30), sp.Float("0.9", 30)
    one = sc.orbit(pt, b, E)
    assert sc.orbit(pt, b, E) is one and sc.orbit(pt, sp.Float("0.8", 30), E) is one
    assert sc.orbit(pt, b, E, engine.DPS + 15) is not one
    assert sc.orbit(pt, b * (1 + sp.Float("1e-20", 30)), E) is not one
    k = next(float(v) for s, v in pt.items() if str(s) == "k")
    assert abs(float(one.deflection) - 2 * math.atan(k / (2 * 0.9 * 0.8))) < 1e-14
    assert sc.orbit(pt, b, E).deflection is one.deflection  # not computed again


def test_a_root_far_inside_the_core_does_not_divide_by_zero(tmp_path):
    """V = −k/r outside a hard core a = k/2, b small: the orbit reaches the core and the
    root of E = V_eff inside it is 1e-6 of a, so the substitution's interval [w_lo, 1] is
    1e-12 wide and tanh-sinh nodes round to w = 1 (r = ∞; a ZeroDivisionError before).
    With s = 1/r the swept angle from infinity to the core is ∫_0^{1/a} ds/√(A + 2Bs − s²),
    A = 1/b², B = k/(2Eb²): asin((1/a − B)/R) + asin(B/R), R = √(A + B²); the orbit
    reflects there and Θ = π − 2·that."""
    a = load_problem_at(tmp_path, "coulomb-attractive-core", "-k/r")
    dyn = a.dynamics(None)
    pt = dict(a.problem.values())
    k_sym = next(s for s in pt if str(s) == "k")
    s = engine.Scattering(dyn, dyn.sys.q[0], k_sym / 2)
    b, E = sp.Float("0.0032918532", 30), sp.Float("0.068055582", 30)
    theta, _ = engine.checked(s, pt, b, E, lambda o: o.deflection)
    with mpmath.workdps(60):
        k = mpmath.mpf(pt[k_sym])
        bb, ee = engine._mp(b, 60), engine._mp(E, 60)
        A, B = 1 / bb ** 2, k / (2 * ee * bb ** 2)
        R = mpmath.sqrt(A + B * B)
        assert B + R > 2 / k  # the hyperbola's perihelion is inside the core: it hits it
        exact = mpmath.pi - 2 * (mpmath.asin((2 / k - B) / R) + mpmath.asin(B / R))
        assert abs(theta - exact) < mpmath.mpf(10) ** -29


def load_problem_at(tmp_path, name: str, potential: str) -> Analysis:
    path = tmp_path / f"{name}.yaml"
    path.write_text(PLANE.format(name=name, potential=potential))
    return Analysis(load_problem(path))
