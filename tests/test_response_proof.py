"""`--prove` for the linear-response answers (mechbook.verify.response_proof): exponents,
complex modes, a characteristic polynomial and simultaneous diagonalization proved by
identities in the coefficients of det(Mp² + Cp + K), never a key 1e-6 or 1 % off.

The linearizations are written out here from their Lagrangians and Rayleigh functions:
- the damped oscillator, T = ½mẋ², V = ½kx², F = ½bẋ²: M = [[m]], C = [[b]], K = [[k]];
  mp² + bp + k = 0 gives p = (−b ± √(b² − 4mk))/(2m), and with b = 0 the mode p = i√(k/m),
  u = [1]; in ω (p = iω) the secular polynomial is k − mω² + ibω;
- two masses in a chain of springs (wall–k1–m1–k2–m2), M = diag(m1, m2),
  K = [[k1 + k2, −k2], [−k2, k2]]: with friction C = b·M (proportional damping) one
  congruence diagonalizes all three (K M⁻¹ C = bK = C M⁻¹ K); with C = diag(b, 0) not
  (K M⁻¹ C − C M⁻¹ K has the off-diagonal entry −k2·b/m1 ≠ 0);
- the driven damped oscillator, F = F0 cos ωt (or F0 sin ωt, a quarter period later):
  x = Re(X e^{iωt}) with (k − mω² + ibω)X = F0, so the amplitude in phase with the force
  is A = F0/(k − mω² + ibω) for either;
- equal masses m on springs k–k–k (wall to wall): M = m·1, K = [[2k, −k], [−k, 2k]],
  normal coordinates x1 = (η1 + η2)/√(2m), x2 = (η1 − η2)/√(2m) with ω1² = k/m (in step)
  and ω2² = 3k/m (opposed): AᵀMA = 1, AᵀKA = diag(k/m, 3k/m);
- the heavy symmetric top's uniform precession (Symon Eq. 11-171): at the tilt θ0 with
  spin ω3 the torque balance is sin θ0·(I1 φ̇² cos θ0 − I3 ω3 φ̇ + mgl) = 0, so the book's
  quadratic I1 φ̇² cos θ0 − I3 ω3 φ̇ + mgl = 0 has the same roots wherever sin θ0 ≠ 0.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import sympy as sp
import yaml

from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.records import ProofPolicy, Status
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem
from mechbook.verify.compare import Sampler
from mechbook.verify.response_proof import (
    prove_characteristic_polynomial,
    prove_complex_modes,
    prove_exponents,
    prove_normal_transformation,
    prove_proportional,
    prove_simultaneous_diagonalization,
    prove_steady_amplitude,
)

ROOT = Path(__file__).resolve().parents[1]
PROVE = ProofPolicy(True, 5.0)
WRONG = (1 + sp.Rational(1, 10**6), sp.Rational(101, 100))  # 1e-6 and 1 % off

m, b, k, x, F0, w = sp.symbols("m b k x F0 omega", positive=True)
t = sp.Symbol("t", real=True)
m1, m2, k1, k2 = sp.symbols("m1 m2 k1 k2", positive=True)
IM = sp.I


def _sampler():
    base = {m: 1.0, b: 0.3, k: 2.0, m1: 1.0, m2: 2.0, k1: 3.0, k2: 1.5, F0: 0.7, w: 1.1}
    return Sampler(base, [], policy=PROVE)


def _lin(M, C, K):
    return SimpleNamespace(M=sp.Matrix(M), C=sp.Matrix(C), K=sp.Matrix(K), first_order=False)


DAMPED = _lin([[m]], [[b]], [[k]])
ROOTS = [(-b + s * sp.sqrt(b**2 - 4 * m * k)) / (2 * m) for s in (1, -1)]


def test_the_damped_oscillators_exponents_are_proved_and_wrong_ones_are_not():
    assert prove_exponents(DAMPED, ROOTS, False, _sampler()).ok
    assert prove_exponents(DAMPED, ROOTS[:1], True, _sampler()).ok
    for f in WRONG:
        wrong = [ROOTS[0], ROOTS[1] * f]
        assert not prove_exponents(DAMPED, wrong, False, _sampler()).ok
        assert not prove_exponents(DAMPED, [ROOTS[0] * f], True, _sampler()).ok
    # one root written twice (a double root it is not): refused as partial, failed as all
    written_twice = [ROOTS[0], sp.expand(ROOTS[0])]
    assert written_twice[0] != written_twice[1]  # two expressions, one value
    assert not prove_exponents(DAMPED, written_twice, True, _sampler()).ok
    # both roots the same one: the sum and product do not match the coefficients
    assert not prove_exponents(DAMPED, [ROOTS[0], ROOTS[0]], False, _sampler()).ok
    # too few for the full multiset: refused, with the reason
    short = prove_exponents(DAMPED, ROOTS[:1], False, _sampler())
    assert not short.ok and "not all 2n" in short.why


def test_an_undamped_mode_is_proved_and_a_frequency_off_is_not():
    lin = _lin([[m]], [[0]], [[k]])
    w = sp.sqrt(k / m)
    assert prove_complex_modes(lin, [(IM * w, [1]), (-IM * w, [1])], _sampler()).ok
    for f in WRONG:
        assert not prove_complex_modes(lin, [(IM * w * f, [1])], _sampler()).ok


def test_a_chain_mode_with_a_wrong_shape_is_not_proved():
    """m1 = m2 = m, k1 = k2 = k: ω² = k(3 ∓ √5)/(2m), u = [1, (1 + √5)/2] for the lower."""
    lin = _lin([[m, 0], [0, m]], [[0, 0], [0, 0]], [[2 * k, -k], [-k, k]])
    w = sp.sqrt(k * (3 - sp.sqrt(5)) / (2 * m))
    shape = [1, (1 + sp.sqrt(5)) / 2]
    assert prove_complex_modes(lin, [(IM * w, shape)], _sampler()).ok
    for f in WRONG:
        assert not prove_complex_modes(lin, [(IM * w, [1, shape[1] * f])], _sampler()).ok


def test_the_secular_polynomial_in_omega_is_proved_up_to_a_factor():
    book = 2 * (m * x**2 - IM * b * x - k)  # −2·(k − mω² + ibω): the same roots
    assert prove_characteristic_polynomial(DAMPED, book, x, IM * x, _sampler()).ok
    for f in WRONG:
        wrong = 2 * (m * x**2 - IM * b * x - k * f)
        assert not prove_characteristic_polynomial(DAMPED, wrong, x, IM * x, _sampler()).ok
    # a polynomial of the wrong degree (a spurious root 0) is refused
    assert not prove_characteristic_polynomial(DAMPED, x * book, x, IM * x, _sampler()).ok
    # an exponent map not linear in the variable: refused with the reason
    refused = prove_characteristic_polynomial(DAMPED, book, x, IM * x**2, _sampler())
    assert not refused.ok and "not a linear function" in refused.why


def _chain(C):
    return _lin([[m1, 0], [0, m2]], C, [[k1 + k2, -k2], [-k2, k2]])


def test_proportional_friction_is_proved_separable_and_generic_friction_is_not():
    assert prove_simultaneous_diagonalization(_chain([[b * m1, 0], [0, b * m2]]), True,
                                              _sampler()).ok
    assert not prove_simultaneous_diagonalization(_chain([[b, 0], [0, 0]]), True,
                                                  _sampler()).ok
    for f in WRONG:
        near = _chain([[b * m1, 0], [0, b * m2 * f]])
        assert not prove_simultaneous_diagonalization(near, True, _sampler()).ok
    false = prove_simultaneous_diagonalization(_chain([[b, 0], [0, 0]]), False, _sampler())
    assert not false.ok and "points only" in false.why


def _driven(force):
    lin = _lin([[m]], [[b]], [[k]])
    lin.F, lin.dyn = [force], SimpleNamespace(sys=SimpleNamespace(t=t))
    return lin


def test_a_driven_oscillators_amplitude_is_proved_and_one_off_is_not():
    amplitude = F0 / (k - m * w**2 + IM * b * w)
    for force in (F0 * sp.cos(w * t), F0 * sp.sin(w * t)):
        lin = _driven(force)
        assert prove_steady_amplitude(lin, {"x": amplitude}, {"x": [1]}, w, _sampler()).ok
        for f in WRONG:
            wrong = {"x": F0 / (k - m * w**2 * f + IM * b * w)}
            assert not prove_steady_amplitude(lin, wrong, {"x": [1]}, w, _sampler()).ok
    # a force at another frequency is not harmonic at ω: refused with the reason
    other = prove_steady_amplitude(_driven(F0 * sp.cos(2 * w * t)), {"x": amplitude},
                                   {"x": [1]}, w, _sampler())
    assert not other.ok and "not proved harmonic" in other.why


def test_a_normal_transformation_is_proved_and_one_off_is_not():
    lin = _lin([[m, 0], [0, m]], [[0, 0], [0, 0]], [[2 * k, -k], [-k, 2 * k]])
    A = sp.Matrix([[1, 1], [1, -1]]) / sp.sqrt(2 * m)
    freqs = {0: sp.sqrt(k / m), 1: sp.sqrt(3 * k / m)}
    assert prove_normal_transformation(lin, A, freqs, _sampler()).ok
    for f in WRONG:
        assert not prove_normal_transformation(lin, A * sp.diag(1, f), freqs, _sampler()).ok
        assert not prove_normal_transformation(lin, A, {0: freqs[0] * f}, _sampler()).ok


def test_proportional_polynomials_are_proved_and_a_coefficient_off_is_not():
    th = sp.Symbol("theta0", real=True)
    engine = sp.sin(th) * (m * x**2 * sp.cos(th) - k * b * x + F0)
    book = m * x**2 * sp.cos(th) - k * b * x + F0
    assert prove_proportional(book, engine, x, _sampler()).ok
    assert prove_proportional(-2 * book, engine, x, _sampler()).ok
    for f in WRONG:
        wrong = m * x**2 * sp.cos(th) - k * b * x * f + F0
        assert not prove_proportional(wrong, engine, x, _sampler()).ok
    assert not prove_proportional(x * book, engine, x, _sampler()).ok  # a root 0 more


def test_the_heavy_tops_precession_equation_is_proved_and_a_wrong_one_fails(tmp_path):
    problem = load_problem(ROOT / "problems" / "symon" / "text-11-5-heavy-top.yaml")
    part = "d-uniform-precession"

    def keep(data):
        data["parts"] = [p for p in data["parts"] if p["part"] == part]

    out = check_problem(Analysis(problem), _key(tmp_path, "text-11-5-heavy-top", keep), PROVE)
    assert [(o.status, o.method) for o in out] == [(Status.PASS, "symbolic")]
    for factor in ("(1 + 1/10**6)", "(101/100)"):
        def wrong(data, factor=factor):
            keep(data)
            data["parts"][0]["book"] = data["parts"][0]["book"].replace(
                "m*g*l", f"m*g*l*{factor}")

        out = check_problem(Analysis(problem), _key(tmp_path, "text-11-5-heavy-top", wrong),
                            PROVE)
        assert [o.status for o in out] == [Status.FAIL]


def _key(tmp_path, name: str, edit):
    data = yaml.safe_load((ROOT / "answers" / "symon" / f"{name}.yaml").read_text())
    edit(data)
    f = tmp_path / f"{name}.yaml"
    f.write_text(yaml.safe_dump(data, allow_unicode=True, sort_keys=False))
    return load_answers(f)


def test_symon_12_10_proved_and_a_wrong_exponent_fails(tmp_path):
    """Symon 12-10's exponents −b/2 ± iν (friction b·M): symbolic with --prove, and the
    separation proved; the decay −b/2 changed by 1e-6 fails (numerically)."""
    problem = load_problem(ROOT / "problems" / "symon" / "12-10.yaml")

    def keep(data):
        data["parts"] = [p for p in data["parts"] if p["quantity"] != "motion"]  # the costly

    out = {o.quantity: o for o in check_problem(Analysis(problem),
                                                _key(tmp_path, "12-10", keep), PROVE)}
    for q in ("exponents", "simultaneous_diagonalization"):
        assert (out[q].status, out[q].method) == (Status.PASS, "symbolic"), out[q].detail

    def wrong(data):
        keep(data)
        for p in data["parts"]:
            if p["quantity"] == "exponents":
                p["book"][0] = p["book"][0].replace("-b/2", "-b/2*(1 + 1/10**6)")

    out = check_problem(Analysis(problem), _key(tmp_path, "12-10", wrong), PROVE)
    assert {o.quantity: o.status for o in out}["exponents"] == Status.FAIL
