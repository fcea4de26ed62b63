"""The complete elliptic integrals K(m), E(m) (parameter m = k², SymPy's and mpmath's
convention) and Euler's Γ in expressions: parsed (mechbook.model.expr), evaluated at 50
digits (core.numeval), compiled (core.compile), and checked in answer keys: a pendulum's
exact period and the quartic oscillator's frequency pass, and each 1e-6 wrong fails."""

from __future__ import annotations

import json

import mpmath
import numpy as np
import pytest
import sympy as sp
from systems import load_analysis, pendulum

from mechbook.core.compile import compile_batch, compile_exprs
from mechbook.core.numeval import evaluate_mp
from mechbook.errors import ExpressionError, SpecError
from mechbook.model.expr import parse
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

m, x = sp.Symbol("m", positive=True), sp.Symbol("x", real=True)


def test_parsed_with_the_parameter_m():
    assert parse("elliptic_k(m)", {"m": m}) == sp.elliptic_k(m)
    assert parse("elliptic_e(m)", {"m": m}) == sp.elliptic_e(m)
    assert parse("gamma(x)", {"x": x}) == sp.gamma(x)
    assert parse("gamma(5)") == 24


@pytest.mark.parametrize("text, why", [
    ("elliptic_k(2)", "no finite real value"),   # K(m) is complex for m > 1
    ("elliptic_k(1)", "not finite"),              # the logarithmic singularity at m = 1
    ("elliptic_e(3)", "no finite real value"),
    ("gamma(0)", "not finite"),                   # a pole
    ("gamma(-2)", "not finite"),
    ("elliptic_e(1/2, 1/3)", "takes 1 argument"),  # the incomplete E(φ, m) is not offered
    ("elliptic_k", "without a call"),
])
def test_refused(text, why):
    with pytest.raises(ExpressionError, match=why):
        parse(text)


def test_a_declared_gamma_is_the_declared_name(tmp_path):
    """gamma is a common name in the books (a coordinate, a parameter, an angle): declaring
    it stays allowed, the name then means what was declared, and gamma(...) is refused."""
    g = sp.Symbol("gamma")
    assert parse("2*gamma", {"gamma": g}) == 2 * g
    with pytest.raises(ExpressionError, match="declared name"):
        parse("gamma(1/4)", {"gamma": g})
    text = pendulum(1.0, 1.0, header="id: lim-9711\nsource: test\ntitle: gamma as a name\n")
    an = load_analysis(tmp_path, text.replace("  m: {value: 1.0}",
                                              "  m: {value: 1.0}\n  gamma: {value: 0.3}"),
                       "9711")
    assert "gamma" in {s.name for s in an.system().numeric_values()}
    with pytest.raises(SpecError, match="reserved"):  # the elliptic names stay reserved
        load_analysis(tmp_path, text.replace("  m: {value: 1.0}", "  elliptic_k: {value: 1}"),
                      "9712")


def test_fifty_digits_against_identities():
    """K(1/2) = Γ(1/4)²/(4√π), and Legendre's relation at k² = 1/2,
    2·E(1/2)·K(1/2) − K(1/2)² = π/2: both to 1e-48 at 50 digits."""
    with mpmath.workdps(50):
        K = evaluate_mp(sp.elliptic_k(m), {m: sp.Rational(1, 2)}, 50)
        E = evaluate_mp(sp.elliptic_e(m), {m: sp.Rational(1, 2)}, 50)
        G = evaluate_mp(sp.gamma(x), {x: sp.Rational(1, 4)}, 50)
        assert abs(K - G**2 / (4 * mpmath.sqrt(mpmath.pi))) < mpmath.mpf(10) ** -48
        assert abs(2 * E * K - K**2 - mpmath.pi / 2) < mpmath.mpf(10) ** -48
        assert abs(K - mpmath.mpf("1.8540746773013719184338503471952600462175988235")) \
            < mpmath.mpf(10) ** -45


def test_compiled_where_symengine_cannot():
    exprs = [sp.elliptic_k(sp.sin(x) ** 2), sp.elliptic_e(x), sp.gamma(x)]
    f, _ = compile_exprs([x], exprs)
    F = compile_batch([x], exprs)
    for v in (0.3, 0.7):
        want = [float(mpmath.ellipk(mpmath.sin(v) ** 2)), float(mpmath.ellipe(v)),
                float(mpmath.gamma(v))]
        assert f(np.array([v])) == pytest.approx(want, rel=1e-14)
        assert F(np.array([[v]]))[0] == pytest.approx(want, rel=1e-14)


PERIOD = "4*sqrt(l/g)*elliptic_k(sin(theta0/2)**2)"  # the exact period at amplitude θ0
# The quartic oscillator V = c·x⁴ at amplitude A: T = 4∫₀^A dx/v, v = sqrt(2c(A⁴ − x⁴)/m);
# with x = A·u, T = 4·sqrt(m/(2c))/A·∫₀¹(1 − u⁴)^(−1/2)du and ∫₀¹(1 − u⁴)^(−1/2)du =
# B(1/4, 1/2)/4 = Γ(1/4)²/(4·sqrt(2π)) (Γ(1/4)Γ(3/4) = π√2), so T = Γ(1/4)²·sqrt(m)/(2A·
# sqrt(πc)) and ω = 2π/T:
QUARTIC = "4*pi**(3/2)*A*sqrt(c/m)/gamma(1/4)**2"
WELL = """\
id: lim-9702
source: test
title: a particle in a quartic well
parameters:
  m: {value: 1.0}
  c: {value: 2.0}
coordinates:
  x: {}
particles:
  p: {mass: m, position: [x]}
potential: c*x**4
"""


def _status(tmp_path, an, part: dict, symbols: dict) -> str:
    d = tmp_path / "answers" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    f = d / f"{an.problem.id.split('-')[1]}.yaml"
    f.write_text(json.dumps({"problem": an.problem.id, "source": "test", "symbols": symbols,
                             "parts": [{"part": "f", "cite": "t", **part}]}))
    out = check_problem(an, load_answers(f))[0]
    return out.status.value


@pytest.mark.parametrize("book, want", [
    (f"2*pi/({PERIOD})", "pass"),
    (f"2*pi/({PERIOD}*(1 + 1e-6))", "fail"),
    (f"2*pi/({PERIOD}) + 1e-6*sqrt(g/l)", "fail"),
])
def test_a_pendulums_exact_period(tmp_path, book, want):
    text = pendulum(1.0, 1.3, header="id: lim-9701\nsource: test\ntitle: a simple pendulum\n")
    an = load_analysis(tmp_path, text, "9701")
    part = {"quantity": "motion_frequency", "initial": {"theta": "theta0"},
            "coordinate": "theta", "book": book}
    assert _status(tmp_path, an, part, {"theta0": {"value": 1.1}}) == want


@pytest.mark.parametrize("book, want", [
    (QUARTIC, "pass"),
    (f"({QUARTIC})*(1 + 1e-6)", "fail"),
    (QUARTIC.replace("gamma(1/4)", "gamma(1/4 + 1e-6)"), "fail"),
])
def test_the_quartic_oscillators_frequency(tmp_path, book, want):
    an = load_analysis(tmp_path, WELL, "9702")
    part = {"quantity": "motion_frequency", "initial": {"x": "A"}, "coordinate": "x",
            "book": book}
    assert _status(tmp_path, an, part, {"A": {"value": 0.7}}) == want
