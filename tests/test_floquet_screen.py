"""The double-precision Floquet screen and the walk's search for the engine's crossing
(issue 42): both may only save work, never change a result.

- The screen decides a point only where its bound makes the 113-bit verdict certain: far
  from a Mathieu tongue's edge (the edges a0(q), b1(q) by Hill's method here, never the
  engine's) it decides, and its verdict is the edge's side and the 113-bit verdict; a
  relative 1e-13 from an edge it cannot, and the 113-bit computation decides; a damped
  oscillator (det Φ < 1 by Liouville) is decided stable; two degrees of freedom are
  decided stable only where the equations are Lagrange's of a quadratic Lagrangian (the
  rotating saddle, inside its window by the closed form), never without that structure
  (a multiplier on the circle is not told from one 1e-20 off it).
- The walk's search (`engine_offset`: a gallop from the previous steps' error, a
  bisection that infers what its verdicts decide) gives the same error as the plain climb
  from the floor, written out here as the reference, on synthetic engines with a crossing
  and a band without verdicts below it, from any guess; its resolution is the climb's
  wherever the missing verdicts reach the decade below the error, and elsewhere lies
  where it cannot put the step at its resolution.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import mpmath
import numpy as np
import pytest
import sympy as sp
from systems import KAPITZA, SADDLE, load_analysis

from mechbook.errors import MechbookError
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




def _window(omega: str) -> bool:
    """The rotating saddle's stability (k = 1, κ = 2), derived here: in axes turning with
    the saddle, u″ − 2Ωw′ + (k − Ω²)u = 0, w″ + 2Ωu′ − (κ + Ω²)w = 0, whose exponents λ
    have x = λ² solving x² + (k − κ + 2Ω²)x − (k − Ω²)(κ + Ω²) = 0. Stable where both
    roots are real and negative: product −(k − Ω²)(κ + Ω²) > 0 (Ω² > k = 1), sum < 0
    (2Ω² > κ − k), discriminant (k − κ + 2Ω²)² + 4(k − Ω²)(κ + Ω²) = 9 − 8Ω² > 0."""
    w2 = mpmath.mpf(omega) ** 2
    return 1 < w2 < mpmath.mpf(9) / 8


def test_a_hamiltonian_system_is_decided_stable_by_its_symmetry(tmp_path):
    """The rotating saddle is Lagrange's equation of a quadratic Lagrangian (C = 0, K
    symmetric): its multipliers come with 1/μ̄, so an isolated Bauer–Fike disc holds one on
    the circle. Well inside the window 1 < Ω² < 9/8 the screen decides stable, as 113 bits
    do; beyond it unstable, as 113 bits do; a relative 1e-13 inside the window's upper
    edge (two multipliers meeting on the circle) and just above Ω² = 1 (a pair near −1)
    it gives no stable verdict: the discs are not isolated."""
    flo = _floquet(tmp_path, SADDLE, "9803")
    screen = Screen(flo)
    assert screen.symplectic
    for omega in ("1.01", "1.03", "1.05"):
        pt = _at(flo, m="1", k="1", kappa="2", Omega=omega)
        assert _window(omega)
        assert screen.verdict(pt) == "stable", omega
        assert flo.stability(pt) == "stable", omega
    for omega in ("0.9", "1.07", "1.2", "2.0"):
        pt = _at(flo, m="1", k="1", kappa="2", Omega=omega)
        assert not _window(omega)
        assert screen.verdict(pt) == "unstable", omega
        assert flo.stability(pt) == "unstable", omega
    with mpmath.workdps(40):
        edge = mpmath.sqrt(mpmath.mpf(9) / 8 * (1 - mpmath.mpf("1e-13")))
        near_one = mpmath.sqrt(1 + mpmath.mpf("1e-9"))
    for omega in (edge, near_one):
        text = mpmath.nstr(omega, 35)
        assert _window(text)
        pt = _at(flo, m="1", k="1", kappa="2", Omega=text)
        assert screen.verdict(pt) is None, text
        assert flo.stability(pt) in ("stable", "marginal"), text


def test_every_stable_verdict_of_the_symmetry_lies_in_the_window(tmp_path):
    """Ω drawn across the window and beyond both edges, closer and closer to them
    (relative 1e-1 … 1e-12): every verdict the screen gives is the closed form's side
    and the 113-bit verdict, and it both decides and escalates along the way."""
    flo = _floquet(tmp_path, SADDLE, "9807")
    screen = Screen(flo)
    rng = np.random.default_rng(7)
    decided = escalated = 0
    for edge in (mpmath.mpf(1), mpmath.sqrt(mpmath.mpf(9) / 8)):
        for k in range(1, 13, 2):
            for side in (-1, 1):
                with mpmath.workdps(40):
                    omega = edge * (1 + side * mpmath.mpf(10) ** -k *
                                    (1 + mpmath.mpf(rng.uniform(0, 1))))
                text = mpmath.nstr(omega, 35)
                pt = _at(flo, m="1", k="1", kappa="2", Omega=text)
                quick = screen.verdict(pt)
                if quick is None:
                    escalated += 1
                    continue
                decided += 1
                assert quick == ("stable" if _window(text) else "unstable"), (text, quick)
                assert quick == flo.stability(pt), (text, quick)
    assert decided >= 6 and escalated >= 6, (decided, escalated)


DAMPED_SADDLE = SADDLE.replace("lim-9406", "lim-9408").replace(
    "  Omega: {value: 1.03}\n", "  Omega: {value: 1.03}\n  c: {value: 0.01}\n") + \
    "dissipation: c*xdot**2/2\n"


def test_two_degrees_of_freedom_without_the_structure_are_decided_unstable_only(tmp_path):
    """The rotating saddle damped along x (C = diag(c, 0): not antisymmetric) has no
    symplectic monodromy: the screen is built only once the 113-bit computation has found
    WORTH_IT points unstable (before, it has nothing to offer a claim of stability), then
    never says stable (at Ω = 1.03, inside the undamped window), and says unstable at
    Ω = 1.2, beyond it, as 113 bits do."""
    flo = _floquet(tmp_path, DAMPED_SADDLE, "9808")
    screen = Screen(flo)
    assert not screen.symplectic
    inside = _at(flo, m="1", k="1", kappa="2", Omega="1.03", c="0.01")
    outside = _at(flo, m="1", k="1", kappa="2", Omega="1.2", c="0.01")
    assert screen.verdict(outside) is None and screen._tight is None  # not built yet
    for _ in range(WORTH_IT):
        screen.note(flo.stability(outside))
    assert screen.verdict(inside) is None
    assert screen.verdict(outside) == "unstable"
    assert flo.stability(outside) == "unstable"


def _lin(M, C, K, t):
    return SimpleNamespace(M=sp.Matrix(M), C=sp.Matrix(C), K=sp.Matrix(K),
                           dyn=SimpleNamespace(sys=SimpleNamespace(t=t)))


def _euler_lagrange(L, qs, t):
    """M, C, K of Lagrange's equations of a Lagrangian quadratic in q and q̇, derived here
    (d/dt ∂L/∂q̇ − ∂L/∂q, q(t) as functions of t)."""
    fs = [sp.Function(f"f{i}")(t) for i in range(len(qs))]
    Lt = L.subs({**{qd: f.diff(t) for (q, qd), f in zip(qs, fs, strict=True)},
                 **{q: f for (q, _), f in zip(qs, fs, strict=True)}})
    eqs = [sp.expand(sp.diff(sp.diff(Lt, f.diff(t)), t) - sp.diff(Lt, f)) for f in fs]
    M = [[e.coeff(g.diff(t, 2)) for g in fs] for e in eqs]
    C = [[e.coeff(g.diff(t)) for g in fs] for e in eqs]
    K = [[e.subs({g.diff(t, 2): 0 for g in fs}).subs({g.diff(t): 0 for g in fs}).coeff(g)
          for g in fs] for e in eqs]
    return M, C, K


def test_the_hamiltonian_structure_is_recognized():
    """Lagrange's equations of quadratic Lagrangians, derived here, are recognized — a
    mass m(t), a gyroscopic term q1·n(t)·q̇2 (C antisymmetric but for Ṁ, K with Ȧ as
    its antisymmetric part), a modulated stiffness — and equations that are none are not:
    damping, a non-symmetric mass, a gyroscopic C whose time derivative K lacks."""
    from mechbook.numerics.floquet_screen import hamiltonian

    t, x, y, xd, yd = sp.symbols("t x y xd yd")
    m, n, k = (sp.Function(f)(t) for f in ("m", "n", "k"))
    L = m * (xd**2 + yd**2) / 2 + x * n * yd - k * (x**2 + 3 * y**2) / 2 + sp.cos(t) * x * y
    M, C, K = _euler_lagrange(L, [(x, xd), (y, yd)], t)
    assert C != [[0, 0], [0, 0]] and K[0][1] != K[1][0]  # the structure is not trivial
    assert hamiltonian(_lin(M, C, K, t))
    assert hamiltonian(_lin([[1]], [[0]], [[1 + sp.cos(t)]], t))
    c = sp.Symbol("c", positive=True)
    assert not hamiltonian(_lin([[1, 0], [0, 1]], [[c, 0], [0, 0]], [[1, 0], [0, 1]], t))
    assert not hamiltonian(_lin([[1, t], [0, 1]], [[0, 0], [0, 0]], [[1, 0], [0, 1]], t))
    g = sp.sin(t)
    assert not hamiltonian(_lin([[1, 0], [0, 1]], [[0, g], [-g, 0]], [[1, 0], [0, 1]], t))
    assert hamiltonian(_lin([[1, 0], [0, 1]], [[0, g], [-g, 0]], [[1, g.diff(t)], [0, 1]], t))


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
        want = 1 + abs(g - a * w * w) / ell
        assert float(flo._rate(pt)) == pytest.approx(want, rel=1e-14)
        assert flo._rate_in_double(pt) == pytest.approx(want, rel=1e-13)
    saddle = _floquet(tmp_path / "saddle", SADDLE, "9805")
    pt = _at(saddle, m="1.5", k="1", kappa="2.5", Omega="1.03")
    assert float(saddle._rate(pt)) == pytest.approx(3.5, rel=1e-14)
    assert saddle._rate_in_double(pt) == pytest.approx(3.5, rel=1e-13)
    assert saddle._rate_in_double({}) is None  # a value missing: the 30-digit path


def test_the_period_guards_pass_in_double_only_far_from_their_limits(tmp_path, monkeypatch):
    """The rotating saddle's period (c/Ω) against its rate 1 + max(k, κ) (closed form above):
    T·rate from 1e-12 to 1e-6 (Ω huge) and T·√rate from 1e3 to 1e7 (Ω tiny) across the
    guards' limits SHORTEST = 1e-9 and LONGEST = 1e5: the 30-digit rate is read exactly
    where one of them lies within RATE_MARGIN of its limit, and the period is refused
    exactly where the closed form puts it beyond one (the double rate never decides a
    refusal)."""
    import mechbook.numerics.floquet as fq

    saddle = _floquet(tmp_path, SADDLE, "9806")
    exact = []
    real = fq.Floquet._rate
    monkeypatch.setattr(fq.Floquet, "_rate", lambda self, v: exact.append(1) or real(self, v))
    rate = 1 + 2.5
    omega_sym = next(s for s in saddle.symbols if s.name == "Omega")
    per = float(saddle.period * omega_sym)  # the period the engine found is per/Ω
    for x in np.geomspace(1e-12, 1e-6, 13).tolist() + np.geomspace(1e3, 1e7, 13).tolist():
        short = x < 1
        T = x / rate if short else x / math.sqrt(rate)  # T·rate = x, or T·√rate = x
        omega = per / T
        pt = _at(saddle, m="1", k="1", kappa="2.5", Omega=repr(omega))
        exact.clear()
        refused = short and x < fq.SHORTEST or not short and x > fq.LONGEST
        near = (fq.SHORTEST / fq.RATE_MARGIN <= x <= fq.RATE_MARGIN * fq.SHORTEST) if short \
            else (fq.LONGEST / fq.RATE_MARGIN <= x <= fq.RATE_MARGIN * fq.LONGEST)
        try:
            saddle.period_at(pt)
            assert not refused, x
        except MechbookError:
            assert refused, x
        assert bool(exact) == (refused or near or (short and x < fq.SHORTEST * fq.RATE_MARGIN)
                               or (not short and x > fq.LONGEST / fq.RATE_MARGIN)), x


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


def test_the_early_escalation_never_drops_a_verdict(mathieu):
    """The screen escalates before it measures the parameters' moves wherever the bounds
    without them decide nothing (its verdicts are monotone in the bounds). Across both
    edges of the first band (relative 1e-1 … 1e-14, Hill's edges): wherever the cheap
    bounds give no verdict the full ones give none either, and every verdict the full
    bounds give is the edge's side (stable inside a0 < α < b1)."""
    flo, screen = mathieu
    assert screen._build()
    early = decided = 0
    for kind in ("a0", "b1"):
        edge = _hill(kind, "0.3")
        for k in range(1, 15):
            for side in (-1, 1):
                with mpmath.workdps(40):
                    alpha = edge + side * mpmath.mpf(10) ** -k * abs(edge)
                inside = (kind == "a0") == (side > 0)
                pars = np.array([float(alpha) if s.name == "alpha" else 0.3
                                 for s in flo.symbols])
                T = math.pi
                a, b = screen._run(screen._tight, pars, T), screen._run(screen._loose, pars, T)
                phi = a[:-1].reshape(2, 2).T
                scale = float(np.max(np.abs(phi)))
                cheap = screen._judge(phi, a, b, scale, (0.0, 0.0))
                full = screen._judge(phi, a, b, scale, screen._rounding(pars, T, a))
                if cheap is None:
                    early += 1
                    assert full is None, (kind, k, side, full)
                if full is not None:
                    decided += 1
                    assert full == ("stable" if inside else "unstable"), (kind, k, side)
    assert early >= 4 and decided >= 10, (early, decided)
