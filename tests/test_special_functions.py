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
    ("elliptic_e(1/2, 1/3, 1)", "takes 1 to 2 argument"),
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


# --- the incomplete elliptic integrals, Jacobi's functions, Bessel's and their zeros ------

phi, u, nu = (sp.Symbol(n, real=True) for n in ("phi", "u", "nu"))
N = sp.Symbol("n", real=True)
D50 = mpmath.mpf(10) ** -45  # what 50 digits leave of an identity


def _mp(text: str, **values):
    """The parsed `text` at `values`, at 50 digits."""
    names = {"phi": phi, "m": m, "u": u, "nu": nu, "n": N, "x": x}
    expr = parse(text, names)
    with mpmath.workdps(50):
        return evaluate_mp(expr, {names[k]: sp.Rational(v) for k, v in values.items()}, 50)


def test_the_new_names_parse_to_sympys_objects():
    from mechbook.core.special import bessel_j_zero, jacobi_cn, jacobi_dn, jacobi_sn

    names = {"phi": phi, "m": m, "u": u, "nu": nu, "n": N}
    assert parse("elliptic_f(phi, m)", names) == sp.elliptic_f(phi, m)
    assert parse("elliptic_e(phi, m)", names) == sp.elliptic_e(phi, m)
    assert parse("elliptic_pi(n, phi, m)", names) == sp.elliptic_pi(N, phi, m)
    assert parse("elliptic_pi(n, m)", names) == sp.elliptic_pi(N, m)
    assert parse("besselj(nu, u) + bessely(nu, u)", names) == \
        sp.besselj(nu, u) + sp.bessely(nu, u)
    assert parse("jacobi_sn(u, m)*jacobi_cn(u, m)/jacobi_dn(u, m)", names) == \
        jacobi_sn(u, m) * jacobi_cn(u, m) / jacobi_dn(u, m)
    assert parse("bessel_j_zero(nu, 2)", names) == bessel_j_zero(nu, 2)
    # d sn/du = cn·dn (so diff() works inside a key), sn(0, m) = 0, sn(u, 0) = sin u
    assert parse("diff(jacobi_sn(u, m), u)", names) == jacobi_cn(u, m) * jacobi_dn(u, m)
    assert parse("jacobi_sn(0, m) + jacobi_cn(u, 0)", names) == sp.cos(u)


def test_incomplete_integrals_against_identities():
    """F(π/2, m) = K(m), E(π/2, m) = E(m); at m = 0 both are φ; Π(0, φ, m) = F(φ, m), and
    Π(n, φ, 0) = ∫₀^φ dθ/(1 − n sin²θ) = atan(sqrt(1 − n)·tan φ)/sqrt(1 − n) (n < 1: with
    t = tan θ the integrand is dt/(1 + (1 − n)t²)); all at 50 digits."""
    with mpmath.workdps(50):
        m0, p0, n0 = mpmath.mpf(3) / 7, mpmath.mpf(9) / 10, mpmath.mpf(2) / 5
        F = _mp("elliptic_f(phi, m)", phi="9/10", m="3/7")
        assert abs(_mp("elliptic_f(pi/2, m)", m="3/7") - mpmath.ellipk(m0)) < D50
        assert abs(_mp("elliptic_e(pi/2, m)", m="3/7") - _mp("elliptic_e(m)", m="3/7")) < D50
        assert abs(_mp("elliptic_f(phi, 0)", phi="9/10") - p0) < D50
        assert abs(_mp("elliptic_e(phi, 0)", phi="9/10") - p0) < D50
        assert abs(_mp("elliptic_pi(0, phi, m)", phi="9/10", m="3/7") - F) < D50
        closed = mpmath.atan(mpmath.sqrt(1 - n0) * mpmath.tan(p0)) / mpmath.sqrt(1 - n0)
        assert abs(_mp("elliptic_pi(n, phi, 0)", n="2/5", phi="9/10") - closed) < D50
        # F by its defining quadrature, E too (m sin²φ < 1 on the path)
        quad = mpmath.quad(lambda t: 1 / mpmath.sqrt(1 - m0 * mpmath.sin(t) ** 2), [0, p0])
        assert abs(F - quad) < D50
        quad = mpmath.quad(lambda t: mpmath.sqrt(1 - m0 * mpmath.sin(t) ** 2), [0, p0])
        assert abs(_mp("elliptic_e(phi, m)", phi="9/10", m="3/7") - quad) < D50


@pytest.mark.parametrize("mv", ["3/7", "-2", "5/2"])
def test_jacobis_functions_invert_F(mv):
    """With u = F(φ, m): sn(u, m) = sin φ, cn(u, m) = cos φ, dn(u, m) = sqrt(1 − m sin²φ),
    the definitions; m < 0 and m > 1 (there on φ with m sin²φ < 1, where u is the real
    quadrature) included: the latter goes through the reciprocal-parameter transformation."""
    with mpmath.workdps(50):
        mm, p0 = mpmath.mpf(sp.Rational(mv)), mpmath.mpf(1) / 2
        uu = mpmath.quad(lambda t: 1 / mpmath.sqrt(1 - mm * mpmath.sin(t) ** 2), [0, p0])
        at = {u: sp.Float(uu, 55), m: sp.Rational(mv)}
        for name, want in (("jacobi_sn", mpmath.sin(p0)), ("jacobi_cn", mpmath.cos(p0)),
                           ("jacobi_dn", mpmath.sqrt(1 - mm * mpmath.sin(p0) ** 2))):
            got = evaluate_mp(parse(f"{name}(u, m)", {"u": u, "m": m}), at, 50)
            assert abs(got - want) < D50, name


def test_bessel_functions_and_zeros_against_half_order_closed_forms():
    """J_{1/2}(x) = sqrt(2/(πx))·sin x and Y_{1/2}(x) = −sqrt(2/(πx))·cos x (the half-
    order Bessel functions are elementary), so j_{1/2,n} = nπ and y_{1/2,n} = (n − 1/2)π;
    J_0 vanishes at its first zero j_{0,1} = 2.404825557695772768621631879326454643124..."""
    with mpmath.workdps(50):
        x0 = mpmath.mpf(7) / 3
        amp = mpmath.sqrt(2 / (mpmath.pi * x0))
        assert abs(_mp("besselj(1/2, x)", x="7/3") - amp * mpmath.sin(x0)) < D50
        assert abs(_mp("bessely(1/2, x)", x="7/3") + amp * mpmath.cos(x0)) < D50
        for n in (1, 2, 5):
            assert abs(_mp("bessel_j_zero(1/2, n)", n=n) - n * mpmath.pi) < D50
            assert abs(_mp("bessel_y_zero(1/2, n)", n=n) - (n - mpmath.mpf(1) / 2) *
                       mpmath.pi) < D50
        j01 = _mp("bessel_j_zero(0, 1)")
        assert abs(j01 - mpmath.mpf("2.404825557695772768621631879326454643124")) < 1e-38
        assert abs(mpmath.besselj(0, j01)) < D50


@pytest.mark.parametrize("text, why", [
    ("bessel_j_zero(0, 3/2)", "index n must be a positive integer"),
    ("bessel_j_zero(0, 0)", "index n must be a positive integer"),
    ("bessel_y_zero(-1, 2)", "order ν must be ≥ 0"),
    ("elliptic_f(6/5, 2)", "m·sin²φ > 1"),           # 2·sin²(1.2) > 1: no real value
    ("elliptic_e(6/5, 2)", "m·sin²φ > 1"),
    ("elliptic_e(3)", "m > 1"),
    ("elliptic_pi(1/2, 6/5, 2)", "no real value"),
    ("bessely(0, -1)", "x > 0 only"),
    ("besselj(1/2, -1)", "is not real"),   # SymPy writes it I·J_{1/2}(1) itself
    ("jacobi_sn(1)", "takes 2 argument"),
    ("bessel_j_zero(1, 2, 3)", "takes 2 argument"),
])
def test_refused_outside_the_domain_with_the_reason(text, why):
    with pytest.raises(ExpressionError, match="outside its function's domain|takes|not real") \
            as err:
        parse(text)
    assert why in str(err.value)


def test_a_point_outside_the_domain_is_a_singular_point_not_a_complex_value():
    """At a checked point (numeval) a value outside the real domain raises a ValueError
    (the samplers treat it as a singular point and draw again), never a complex number
    that a comparison could take the real part of."""
    with pytest.raises(ValueError, match="positive integer"):
        evaluate_mp(parse("bessel_j_zero(0, n)", {"n": N}), {N: sp.Rational(3, 2)})
    with pytest.raises(ValueError, match="m·sin²φ > 1"):
        evaluate_mp(parse("elliptic_f(phi, m)", {"phi": phi, "m": m}),
                    {phi: sp.Rational(6, 5), m: 2})
    with mpmath.workdps(30):  # J_1 is odd: real at x < 0
        got = evaluate_mp(parse("besselj(1, x)", {"x": x}), {x: -1})
        assert abs(got + mpmath.besselj(1, 1)) < 1e-28


def test_the_new_functions_compiled_agree_with_mpmath():
    exprs = [parse(t, {"x": x}) for t in (
        "elliptic_f(x, 1/2)", "elliptic_e(x, 1/3)", "elliptic_pi(1/4, x, 1/2)",
        "jacobi_sn(x, 1/2)", "jacobi_cn(x, 3)", "jacobi_dn(x, -1)", "besselj(1, x)",
        "bessely(0, x)", "bessel_j_zero(x, 2)")]
    f, _ = compile_exprs([x], exprs)
    F = compile_batch([x], exprs)
    for v in (0.3, 0.7):
        want = [mpmath.ellipf(v, 0.5), mpmath.ellipe(v, 1 / 3), mpmath.ellippi(0.25, v, 0.5),
                mpmath.ellipfun("sn", v, m=0.5),
                mpmath.ellipfun("dn", v * 3**0.5, m=1 / 3),   # cn(u, m) = dn(√m·u, 1/m)
                mpmath.ellipfun("dn", v, m=-1), mpmath.besselj(1, v), mpmath.bessely(0, v),
                mpmath.besseljzero(v, 2)]
        want = [float(mpmath.re(w)) for w in want]
        assert f(np.array([v])) == pytest.approx(want, rel=1e-13)
        assert F(np.array([[v]]))[0] == pytest.approx(want, rel=1e-13)
    assert np.isnan(compile_batch([x], [parse("bessely(0, x)", {"x": x})])(
        np.array([[-1.0]]))[0, 0])  # outside the domain: NaN, never an exception


# The time a pendulum released at the bottom with amplitude θ0 takes to reach θ (< θ0):
# energy, θ̇² = (2g/l)(cos θ − cos θ0) = (4g/l)(k² − sin²(θ/2)) with k = sin(θ0/2); put
# sin(θ/2) = k·sin φ, so ½cos(θ/2)dθ = k·cos φ dφ and θ̇ = 2·sqrt(g/l)·k·cos φ; then
# dt = dθ/θ̇ = sqrt(l/g)·dφ/sqrt(1 − k² sin²φ): t(θ) = sqrt(l/g)·F(asin(sin(θ/2)/k), k²).
# The start at the bottom with that amplitude: θ̇(0) = 2·sqrt(g/l)·k.
TIME_TO = "sqrt(l/g)*elliptic_f(asin(sin(theta1/2)/sin(theta0/2)), sin(theta0/2)**2)"


@pytest.mark.parametrize("book, want", [
    (TIME_TO, "pass"),
    (f"({TIME_TO})*(1 + 1e-6)", "fail"),
    (f"({TIME_TO})*(1 + 1e-12)", "fail"),   # the level set's quadrature: exact to 1e-15
    (f"({TIME_TO})*1.01", "fail"),
    (TIME_TO.replace("sin(theta0/2)**2)", "sin(theta0/2))"), "fail"),  # k for m = k²
])
def test_a_pendulums_time_to_an_angle(tmp_path, book, want):
    text = pendulum(1.0, 1.3, header="id: lim-9703\nsource: test\ntitle: a pendulum\n")
    an = load_analysis(tmp_path, text, "9703")
    part = {"quantity": "event_time", "initial": {"theta": 0,
                                                  "thetadot": "2*sqrt(g/l)*sin(theta0/2)"},
            "event": "theta - theta1", "book": book}
    symbols = {"theta0": {"value": 1.6}, "theta1": {"value": 0.8}}
    assert _status(tmp_path, an, part, symbols) == want


def test_a_time_across_the_bottom_from_rest(tmp_path):
    """Released from rest at θ0 (a turning point: the quadrature's inverse square root at
    its start) the pendulum reaches −θ1 past the bottom: a quarter period plus the time
    from the bottom, sqrt(l/g)·(K(m) + F(φ1, m))."""
    text = pendulum(1.0, 1.3, header="id: lim-9705\nsource: test\ntitle: a pendulum\n")
    an = load_analysis(tmp_path, text, "9705")
    both = ("sqrt(l/g)*(elliptic_k(sin(theta0/2)**2) + "
            "elliptic_f(asin(sin(theta1/2)/sin(theta0/2)), sin(theta0/2)**2))")
    for book, want in ((both, "pass"), (f"({both})*(1 + 1e-6)", "fail")):
        part = {"quantity": "event_time", "initial": {"theta": "theta0"},
                "event": "theta + theta1", "book": book}
        assert _status(tmp_path, an, part, {"theta0": {"value": 1.6},
                                            "theta1": {"value": 0.8}}) == want


def test_a_key_outside_the_domain_is_an_error_at_its_line(tmp_path):
    """A book value outside a function's domain is refused where the key says it, with
    the file and line, before anything is checked."""
    text = pendulum(1.0, 1.3, header="id: lim-9704\nsource: test\ntitle: a pendulum\n")
    an = load_analysis(tmp_path, text, "9704")
    d = tmp_path / "answers" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    f = d / "9704.yaml"
    f.write_text("problem: lim-9704\nsource: test\nparts:\n  - part: a\n    cite: t\n"
                 "    quantity: lagrangian\n    book: bessel_j_zero(0, 2.5)\n")
    from mechbook.verify.wellformed import validate_key

    fault = str(validate_key(an, load_answers(f))["a"])
    assert "9704.yaml:7" in fault and "positive integer" in fault
