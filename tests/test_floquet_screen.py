"""The double-precision Floquet screen and the walk's search for the engine's crossing
(issue 42): both may only save work, never change a result.

- The screen decides a point only where its bound makes the 113-bit verdict certain: far
  from a Mathieu tongue's edge (the edges a0(q), b1(q) by Hill's method here, never the
  engine's) it decides, and its verdict is the edge's side and the 113-bit verdict; a
  relative 1e-13 from an edge it cannot, and the 113-bit computation decides; a damped
  oscillator (det Φ < 1 by Liouville) is decided stable; two degrees of freedom are never
  decided stable (a multiplier on the circle is not told from one 1e-20 off it without
  the system's structure).
- The walk's search (`engine_offset`: a gallop from the previous steps' error, a
  bisection that infers what its verdicts decide) gives the same error as the plain climb
  from the floor, written out here as the reference, on synthetic engines with a crossing
  and a band without verdicts below it, from any guess; its resolution is the climb's
  wherever the missing verdicts reach the decade below the error, and elsewhere lies
  where it cannot put the step at its resolution.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
import sympy as sp
from systems import SADDLE, load_analysis

from mechbook.numerics.floquet import Floquet
from mechbook.numerics.floquet_screen import WORTH_IT, Screen
from mechbook.verify import boundary_limit
from mechbook.verify.boundary_limit import BISECTIONS, FLOQUET_FLOOR, engine_offset

pytest.importorskip("heyoka")


def _hill(kind: str, q: str, n: int = 40) -> mpmath.mpf:
    """Mathieu's characteristic value a0(q) (π-periodic even solutions) or b1(q)
    (2π-periodic odd ones, Σ B_{2r+1} sin(2r+1)τ): eigenvalues of the symmetric
    tridiagonal matrix of the three-term recurrence (α − k²)C_k = q(C_{k−2} + C_{k+2})
    (derived in tests/test_periodic.py), at 40 digits."""
    with mpmath.workdps(40):
        qq = mpmath.mpf(q)
        A = mpmath.zeros(n)
        for r in range(n):
            A[r, r] = (2 * r + (0 if kind == "a0" else 1)) ** 2
            if r + 1 < n:
                A[r, r + 1] = A[r + 1, r] = qq
        if kind == "a0":
            A[0, 1] = A[1, 0] = mpmath.sqrt(2) * qq
        else:
            A[0, 0] -= qq
        return min(mpmath.eigsy(A, eigvals_only=True))


MATHIEU = """\
id: lim-9801
source: test
title: Mathieu's equation x'' + (alpha - 2 q cos 2t) x = 0
parameters:
  alpha: {value: 1.0}
  q: {value: 0.3}
coordinates:
  x: {}
kinetic: xdot**2/2
potential: (alpha - 2*q*cos(2*t))*x**2/2
"""


def _floquet(tmp_path, text: str, num: str) -> Floquet:
    analysis = load_analysis(tmp_path, text, num)
    sys_ = analysis.system(None)
    lin = analysis.linear(None, {q: 0 for q in sys_.q})
    return Floquet.of(lin)


def _at(flo: Floquet, **values) -> dict:
    return {s: sp.Float(str(values[s.name]), 30) for s in flo.symbols}


@pytest.fixture(scope="module")
def mathieu(tmp_path_factory):
    flo = _floquet(tmp_path_factory.mktemp("screen"), MATHIEU, "9801")
    return flo, Screen(flo)


@pytest.mark.parametrize("kind,side", [("a0", -1), ("a0", 1), ("b1", -1), ("b1", 1)])
def test_the_screen_decides_far_from_an_edge_as_the_113_bit_computation(mathieu, kind,
                                                                       side):
    """A relative 1e-3 from each edge of the first stable band a0(q) < α < b1(q) (q = 0.3):
    the screen decides, its verdict is the band's (stable inside), and the 113-bit
    computation's."""
    flo, screen = mathieu
    edge = _hill(kind, "0.3")
    alpha = edge * (1 + side * mpmath.mpf("1e-3") * (1 if edge > 0 else -1))
    inside = (kind == "a0") == (side > 0)
    pt = _at(flo, alpha=mpmath.nstr(alpha, 30), q="0.3")
    got = screen.verdict(pt)
    assert got == ("stable" if inside else "unstable"), (kind, side, got)
    assert flo.stability(pt) == got


@pytest.mark.parametrize("kind,side", [("a0", -1), ("a0", 1), ("b1", -1), ("b1", 1)])
def test_the_screen_escalates_at_an_edge(mathieu, kind, side):
    """A relative 1e-13 from an edge the multipliers are ~3e-7 from ±1 and tr Φ within
    ~1e-13 of ±2, inside the double integration's bound: no verdict from the screen; the
    113-bit computation gives the edge's side."""
    flo, screen = mathieu
    edge = _hill(kind, "0.3")
    with mpmath.workdps(40):
        alpha = edge * (1 + side * mpmath.mpf("1e-13") * (1 if edge > 0 else -1))
    inside = (kind == "a0") == (side > 0)
    pt = _at(flo, alpha=mpmath.nstr(alpha, 35), q="0.3")
    before = screen.escalated
    assert screen.verdict(pt) is None
    assert screen.escalated == before + 1
    assert flo.stability(pt) == ("stable" if inside else "unstable")


def test_wherever_the_screen_decides_it_agrees_with_113_bits(mathieu):
    """Points across the first band and beyond both edges, drawn closer and closer to the
    edges (relative 1e-1 … 1e-14): every verdict the screen gives is the 113-bit one, and
    it both decides and escalates along the way."""
    flo, screen = mathieu
    rng = np.random.default_rng(42)
    decided = escalated = 0
    for kind in ("a0", "b1"):
        edge = _hill(kind, "0.3")
        for k in range(1, 15):
            for side in (-1, 1):
                with mpmath.workdps(40):
                    off = mpmath.mpf(10) ** -k * (1 + mpmath.mpf(rng.uniform(0, 1)))
                    alpha = edge + side * off * abs(edge)
                pt = _at(flo, alpha=mpmath.nstr(alpha, 35), q="0.3")
                quick = screen.verdict(pt)
                if quick is None:
                    escalated += 1
                    continue
                decided += 1
                assert quick == flo.stability(pt), (kind, k, side, quick)
    assert decided >= 10 and escalated >= 10, (decided, escalated)


def test_a_damped_oscillator_is_decided_stable_by_its_determinant(tmp_path):
    """x'' + c x' + (α − 2q cos 2t)x = 0 with c = 0.1: det Φ = exp(−cT) < 1 (Liouville).
    At α = 0.4, inside the first band a0(0.3) ≈ −0.045 < α < b1(0.3) ≈ 0.69, the
    multipliers are a complex pair of modulus exp(−cT/2): stable, by the screen and in 113
    bits. At α = 1, in the first tongue, the growth (~q/2 = 0.15) beats the damping
    (c/2 = 0.05): unstable, by both."""
    text = MATHIEU.replace("lim-9801", "lim-9802").replace(
        "  q: {value: 0.3}\n", "  q: {value: 0.3}\n  c: {value: 0.1}\n") + \
        "dissipation: c*xdot**2/2\n"
    flo = _floquet(tmp_path, text, "9802")
    screen = Screen(flo)
    assert _hill("a0", "0.3") < 0.4 < _hill("b1", "0.3") < 1
    pt = _at(flo, alpha="0.4", q="0.3", c="0.1")
    assert screen.verdict(pt) == "stable"
    assert flo.stability(pt) == "stable"
    assert not flo.traceless
    pt = _at(flo, alpha="1.0", q="0.3", c="0.1")
    assert screen.verdict(pt) == "unstable"
    assert flo.stability(pt) == "unstable"




def test_two_degrees_of_freedom_are_decided_unstable_only(tmp_path):
    """The rotating saddle (k = 1, κ = 2) is stable exactly where 1 < Ω² < 9/8 (the closed
    form derived in tests/test_periodic.py). The screen is built only once the 113-bit
    computation has found WORTH_IT points unstable (before, it has nothing to offer a
    claim of stability). Then: inside, no verdict (four multipliers on the circle); at
    Ω = 1.2, beyond the window, a multiplier wholly outside the circle: unstable, as in
    113 bits."""
    flo = _floquet(tmp_path, SADDLE, "9803")
    screen = Screen(flo)
    inside = _at(flo, m="1", k="1", kappa="2", Omega="1.03")
    outside = _at(flo, m="1", k="1", kappa="2", Omega="1.2")
    assert screen.verdict(outside) is None and screen._tight is None  # not built yet
    for _ in range(WORTH_IT):
        screen.note(flo.stability(outside))
    assert screen.verdict(inside) is None
    assert flo.stability(inside) == "stable"
    assert screen.verdict(outside) == "unstable"
    assert flo.stability(outside) == "unstable"


# ---- the walk's search against the plain climb ------------------------------------------
def _climb(verdict, below, above, reach, floor):
    """The search as it was until issue 42 (the reference): offsets climbing by decades
    from the floor until the engine agrees on both sides, then ten bisections."""
    missing = 0.0
    sigma, previous = floor, None
    while sigma <= reach:
        lo, hi = verdict(-1, sigma), verdict(1, sigma)
        if lo is None or hi is None:
            missing = sigma
        if lo == below and hi == above:
            if previous is None:
                return floor, floor
            s_in, below_ok, _ = previous
            side, want = (-1, below) if not below_ok else (1, above)
            s_out = sigma
            for _ in range(BISECTIONS):
                mid = math.sqrt(s_in * s_out)
                got = verdict(side, mid)
                if got is None:
                    missing = max(missing, mid)
                if got == want:
                    s_out = mid
                else:
                    s_in = mid
            return math.sqrt(s_in * s_out), max(floor, missing)
        previous = (sigma, lo == below, hi == above)
        sigma *= 10
    return math.inf, max(floor, missing)


class _Line:
    """A synthetic ray: the point at t is t itself."""

    def point(self, t):
        return {"t": t}


def _engine(t_star, crossing: float, silent: float, side: int):
    """An engine whose boundary is `crossing` beyond the book's on `side`, with no verdict
    (marginal) within `silent` of the book's boundary; the book: stable above t*."""
    def classify(pt, near):
        off = float(pt["t"] - t_star)
        if abs(off) < silent:
            return None
        return off > side * crossing
    return classify


@pytest.mark.parametrize("crossing", [3e-26, 4.4e-15, 2.7e-9, 4.4e-5, 0.3])
@pytest.mark.parametrize("silent", [0.0, 1e-27, 1e-21, 0.5])
@pytest.mark.parametrize("side", [-1, 1])
def test_the_search_finds_the_climbs_error(crossing, silent, side):
    """From no guess, the right one, a decade off either way, far off, and infinite: the
    error is the climb's to the last bit; the resolution is the climb's, or lies two
    decades or more below the error (it cannot put the step at its resolution)."""
    t_star, reach = mpmath.mpf("0.37"), 1.0
    verdict_calls = []

    def counted(engine):
        def classify(pt, near):
            verdict_calls.append(1)
            return engine(pt, near)
        return classify

    engine = _engine(t_star, crossing, silent, side)

    def plain(s, offset):
        with mpmath.workdps(50):
            return engine({"t": t_star + s * mpmath.mpf(offset)}, True)

    want_e, want_r = _climb(plain, False, True, reach, FLOQUET_FLOOR)
    for guess in (None, crossing, crossing * 10, crossing / 10, 1e-20, 0.5, math.inf):
        verdict_calls.clear()
        e, r = engine_offset(counted(engine), _Line(), t_star, False, True, reach,
                              FLOQUET_FLOOR, guess)
        assert e == want_e, (guess, e, want_e)
        if r != want_r:
            assert r < want_r and e >= 10 * want_r and e >= 10 * r, (guess, r, want_r, e)
    verdict_calls.clear()
    engine_offset(counted(engine), _Line(), t_star, False, True, reach, FLOQUET_FLOOR,
                   crossing * 1.0001)
    if math.isfinite(want_e) and want_e > FLOQUET_FLOOR and silent < crossing / 10:
        assert len(verdict_calls) <= 8, len(verdict_calls)  # the climb took up to 68


def test_a_missing_verdict_up_to_the_error_is_the_resolution():
    """Verdicts missing up to just below the crossing (the step at its resolution): the
    resolution is the climb's, the largest offset without a verdict."""
    t_star = mpmath.mpf("0.5")
    for crossing in (4.6e-21, 3e-18):
        engine = _engine(t_star, crossing, crossing * 0.999, 1)

        def plain(s, offset, engine=engine):
            with mpmath.workdps(50):
                return engine({"t": t_star + s * mpmath.mpf(offset)}, True)

        want = _climb(plain, False, True, 1.0, FLOQUET_FLOOR)
        for guess in (None, crossing, crossing * 30):
            got = engine_offset(engine, _Line(), t_star, False, True, 1.0, FLOQUET_FLOOR,
                                 guess)
            assert got == want, (crossing, guess, got, want)
            assert got[0] < 10 * got[1]  # at the resolution


def test_the_expected_error_extrapolates_the_fall():
    assert boundary_limit.expected([]) is None
    assert boundary_limit.expected([1e-5]) == pytest.approx(10 ** -5.5)
    assert boundary_limit.expected([1e-5], order=3) == pytest.approx(1e-7)
    assert boundary_limit.expected([1e-5, 1e-6]) == pytest.approx(1e-7)
    assert boundary_limit.expected([1e-6, 1e-6]) == 1e-6
    assert boundary_limit.expected([math.inf]) == math.inf


KAPITZA = """\
id: lim-9804
source: test
title: pendulum on a pivot driven up and down
parameters:
  m: {value: 1.0}
  l: {value: 1.0}
  a: {value: 0.1}
  omega: {value: 45.0}
  g: {value: 9.81}
coordinates:
  theta: {}
driven:
  y0: a*cos(omega*t)
particles:
  bob: {mass: m, position: [l*sin(theta), y0 - l*cos(theta)]}
gravity: {}
"""


def test_the_rate_guard_reads_the_coefficients_at_t0(tmp_path):
    """The rate the period guards use, 1 + the largest entry of M⁻¹K and M⁻¹C at t = 0,
    against closed forms: about θ = π the pendulum's l δθ̈ − (g + ÿ0) δθ = 0 with
    ÿ0(0) = −aω² gives 1 + |g − aω²|/l; the rotating saddle at t = 0 has M⁻¹K =
    diag(k, −κ): 1 + max(k, κ)."""
    analysis = load_analysis(tmp_path, KAPITZA, "9804")
    theta = analysis.system(None).q[0]
    flo = Floquet.of(analysis.linear(None, {theta: sp.pi}))
    for a, w, g, ell in ((0.1, 45.0, 9.81, 1.0), (0.003, 1500.0, 9.81, 0.7),
                         (1e-6, 2.0, 9.81, 3.0)):
        pt = _at(flo, a=a, omega=w, g=g, l=ell, m=2.0)
        assert float(flo._rate(pt)) == pytest.approx(1 + abs(g - a * w * w) / ell,
                                                     rel=1e-14)
    saddle = _floquet(tmp_path / "saddle", SADDLE, "9805")
    pt = _at(saddle, m="1.5", k="1", kappa="2.5", Omega="1.03")
    assert float(saddle._rate(pt)) == pytest.approx(3.5, rel=1e-14)


def test_the_bound_covers_the_parameters_rounding_to_doubles(mathieu):
    """The double integration runs at the doubles of the 30-digit values; the screen moves
    each parameter and the period by NUDGE ulps and adds how far Φ moves. For q = 0 (a
    harmonic oscillator over T = π) Φ is closed-form, [[cos wT, sin wT/w], [−w sin wT,
    cos wT]] with w = √α: the moves the screen measures are those of the closed form
    (α and T moved; q = 0 is exact and does not move)."""
    from mechbook.numerics.floquet_screen import EPS, NUDGE

    flo, screen = mathieu
    assert screen._build()
    alpha, T = 2.0, math.pi
    pars = np.array([alpha if s.name == "alpha" else 0.0 for s in flo.symbols])
    a = screen._run(screen._tight, pars, T)
    moved = screen._rounding(pars, T, a)

    def phi(al, t):
        with mpmath.workdps(40):
            w = mpmath.sqrt(al)
            return [mpmath.cos(w * t), -w * mpmath.sin(w * t), mpmath.sin(w * t) / w,
                    mpmath.cos(w * t)]

    with mpmath.workdps(40):
        nudge = 1 + NUDGE * mpmath.mpf(EPS)
        base = phi(mpmath.mpf(alpha), mpmath.pi)
        want = sum(max(abs(x - y) for x, y in zip(phi(al, t), base, strict=True))
                   for al, t in ((alpha * nudge, mpmath.pi), (alpha, mpmath.pi * nudge)))
    assert abs(moved[0] / float(want) - 1) < 0.2, (moved, float(want))
