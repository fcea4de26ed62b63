"""`--prove` for `stability`: a verdict proved from the signs of the linearization's
determinants and minors (mechbook.verify.stability_proof), never a wrong verdict, never one
that a coefficient 1e-6 off has changed.

The linearizations are written out here from their Lagrangians:
- two masses in a chain of springs (wall–k1–m1–k2–m2): T = ½m1ẋ1² + ½m2ẋ2²,
  V = ½k1x1² + ½k2(x2 − x1)², so M = diag(m1, m2), K = [[k1 + k2, −k2], [−k2, k2]];
- the inverted pendulum: T = ½mL²θ̇², V = mgL cos θ, about θ = 0: M = mL², K = −mgL;
- a free body turning at ω about its body axis 3, tilted by small angles a, b (Euler's
  equations linearized, Symon 11-2): I1·ä + ω(I1 + I2 − I3)·(−ḃ) + ω²(I3 − I2)·a = 0 and
  I2·b̈ + ω(I1 + I2 − I3)·ȧ + ω²(I3 − I1)·b = 0, so M = diag(I1, I2),
  C = ω(I1 + I2 − I3)·[[0, −1], [1, 0]] (gyroscopic), K = diag(ω²(I3 − I2), ω²(I3 − I1));
  its characteristic polynomial is I1I2λ⁴ + ω²[(I1 − I3)(I2 − I3) + I1I2]λ² +
  ω⁴(I3 − I1)(I3 − I2): stable about the greatest and the least axis, unstable about the
  intermediate one.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.records import ProofPolicy, Status
from mechbook.verify import proof
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem
from mechbook.verify.compare import Sampler
from mechbook.verify.stability_proof import prove_stability

ROOT = Path(__file__).resolve().parents[1]
PROVE = ProofPolicy(True, 5.0)
EPS = sp.Rational(1, 10**6)

m1, m2, k1, k2, m, g, L, w = sp.symbols("m1 m2 k1 k2 m g L omega", positive=True)
I1, I2, I3 = sp.symbols("I1 I2 I3", positive=True)


def _sampler(conditions=()):
    base = {m1: 1.0, m2: 2.0, k1: 3.0, k2: 1.5, m: 1.0, g: 9.8, L: 0.5, w: 1.3,
            I1: 1.0, I2: 1.7, I3: 2.3}
    return Sampler(base, list(conditions), policy=PROVE)


def _lin(M, C, K):
    return SimpleNamespace(M=sp.Matrix(M), C=sp.Matrix(C), K=sp.Matrix(K))


def _chain(k11):
    return _lin([[m1, 0], [0, m2]], [[0, 0], [0, 0]], [[k11, -k2], [-k2, k2]])


def _body(conditions):
    gyro = w * (I1 + I2 - I3)
    lin = _lin([[I1, 0], [0, I2]], [[0, -gyro], [gyro, 0]],
               [[w**2 * (I3 - I2), 0], [0, w**2 * (I3 - I1)]])
    return lin, _sampler(conditions)


def test_a_chain_of_springs_is_proved_stable_and_never_unstable():
    s = _sampler()
    assert prove_stability(_chain(k1 + k2), "stable", s).ok
    assert not prove_stability(_chain(k1 + k2), "unstable", s).ok


def test_a_stiffness_1e_6_off_flips_the_proof():
    """K11 = k2 − 1e-6·k1 (the wall's spring replaced by a negative one, 1e-6 of it):
    det K = −1e-6·k1·k2 < 0 at every point, so `unstable` is proved and `stable` is not."""
    s = _sampler()
    k11 = k2 - EPS * k1
    assert sp.expand(sp.Matrix([[k11, -k2], [-k2, k2]]).det()) == -EPS * k1 * k2
    assert not prove_stability(_chain(k11), "stable", s).ok
    assert prove_stability(_chain(k11), "unstable", s).ok


def test_the_inverted_pendulum_is_unstable_and_a_sign_not_fixed_is_not_proved():
    s = _sampler()
    up = _lin([[m * L**2]], [[0]], [[-m * g * L]])
    assert prove_stability(up, "unstable", s).ok
    assert not prove_stability(up, "stable", s).ok
    # a spring k1 against gravity: stable only where k1 > m·g/L, which nothing states
    spring = _lin([[m * L**2]], [[0]], [[k1 * L**2 - m * g * L]])
    for claim in ("stable", "unstable"):
        p = prove_stability(spring, claim, s)
        assert not p.ok and p.why == proof.NO_SIGN, claim


def test_a_free_body_about_each_axis():
    """Greatest and least axis stable (the least by gyroscopic stabilization: K is
    negative definite there), intermediate unstable; each opposite verdict never proved."""
    for conditions, right in (([I3 > I2, I2 > I1], "stable"),
                              ([I3 < I1, I1 < I2], "stable"),
                              ([I1 < I3, I3 < I2], "unstable")):
        lin, s = _body(conditions)
        wrong = "unstable" if right == "stable" else "stable"
        assert prove_stability(lin, right, s).ok, conditions
        assert not prove_stability(lin, wrong, s).ok, conditions


def test_a_gyroscopic_term_1e_6_too_small_is_not_proved_stable():
    """About the least axis with the gyroscopic coefficient scaled by 1e-6 (the rotation's
    coupling all but gone): the characteristic polynomial's middle coefficient
    ω²[I1(I3 − I1) + I2(I3 − I2)] + 1e-12·… is negative for I3 < I1 < I2, so no proof."""
    gyro = EPS * w * (I1 + I2 - I3)
    lin = _lin([[I1, 0], [0, I2]], [[0, -gyro], [gyro, 0]],
               [[w**2 * (I3 - I2), 0], [0, w**2 * (I3 - I1)]])
    assert not prove_stability(lin, "stable", _sampler([I3 < I1, I1 < I2])).ok


def test_without_the_conditions_nothing_is_proved():
    """The free body with no order of its moments: neither verdict holds everywhere."""
    lin, s = _body([])
    assert not prove_stability(lin, "stable", s).ok
    assert not prove_stability(lin, "unstable", s).ok


def test_symon_11_11_proved_and_its_wrong_verdict_fails(tmp_path):
    """The book's three axes: symbolic with --prove; the intermediate axis keyed `stable`
    fails (numerically, before any proof)."""
    import yaml

    problem = load_problem(ROOT / "problems" / "symon" / "11-11.yaml")
    data = yaml.safe_load((ROOT / "answers" / "symon" / "11-11.yaml").read_text())
    data["parts"] = [p for p in data["parts"] if p.get("quantity") == "stability"]
    f = tmp_path / "11-11.yaml"
    f.write_text(yaml.safe_dump(data))
    out = check_problem(Analysis(problem), load_answers(f), PROVE)
    assert [(o.part, o.status, o.method) for o in out] == [
        (p, Status.PASS, "symbolic") for p in ("greatest", "least", "intermediate")]
    for p in data["parts"]:
        if p["part"] == "intermediate":
            p["book"] = "stable"
    f.write_text(yaml.safe_dump(data))
    out = check_problem(Analysis(problem), load_answers(f), PROVE)
    assert {o.part: o.status for o in out}["intermediate"] == Status.FAIL


def test_a_first_order_linearization_is_unproved_not_unsupported():
    """The Chaplygin sleigh (a velocity constraint: a first-order linearization, no M, C,
    K): its two verdicts pass under --prove as in a plain check and say why unproved (the
    proof asked for M and made them unsupported)."""
    an = Analysis(load_problem(ROOT / "problems" / "classic" / "chaplygin-sleigh.yaml"))
    key = load_answers(ROOT / "answers" / "classic" / "chaplygin-sleigh.yaml")
    proved = check_problem(an, key, PROVE)
    plain = check_problem(Analysis(load_problem(
        ROOT / "problems" / "classic" / "chaplygin-sleigh.yaml")), key)
    assert [o.status for o in proved] == [o.status for o in plain]
    verdicts = [o for o in proved if o.quantity == "stability"]
    assert len(verdicts) == 2 and all(o.status == Status.PASS for o in verdicts)
    assert all("first-order linearization" in o.method for o in verdicts)
