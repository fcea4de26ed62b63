"""Continuous fields (`field:`): the field equation, normal frequencies by separation and by
collocation, conserved currents, and bad input; against closed forms derived here.

Closed forms (derived in the docstrings of the tests, never read from the engine):
a rectangular membrane ω = c·π·sqrt((m/a)² + (n/b)²); a disk membrane ω = c·j_{n,s}/R (J_n's
zeros, n ≥ 1 twice); a clamped–free beam βL = 1.8751… (1 + cos βL·cosh βL = 0); a
hinged–hinged beam ω = (nπ/L)²·sqrt(EI/ρA); Klein–Gordon ω² = c²k² + m² with k = nπ/L;
a string fixed at 0 with a mass M at L: τk·cos kL = Mω²·sin kL, ω = ck.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.engine.continuum import field_equation, squared_frequencies
from mechbook.engine.spectral import rectangle_eigenvalues, segment_eigenvalues
from mechbook.errors import SpecError
from mechbook.model.problem import load_problem
from mechbook.records import Status
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem
from mechbook.verify.wellformed import validate_key

MEMBRANE = ("sigma*u_t**2/2 - tau*(u_x**2 + u_y**2)/2", "{rectangle: [a, b]}", "{all: fixed}",
            {"sigma": 0.8, "tau": 5.0, "a": 2.0, "b": 1.3})
DISK = ("sigma*u_t**2/2 - tau*(u_r**2 + u_theta**2/r**2)/2", "{disk: R}", "{edge: fixed}",
        {"sigma": 0.3, "tau": 12.0, "R": 0.25})
BEAM = ("rhoA*u_t**2/2 - EI*u_xx**2/2", "{segment: L}", "{left: clamped, right: free}",
        {"EI": 2.0, "rhoA": 0.5, "L": 1.5})
HINGED = ("rhoA*u_t**2/2 - EI*u_xx**2/2", "{segment: L}", "{all: hinged}",
          {"EI": 2.0, "rhoA": 0.5, "L": 1.5})
KLEIN_GORDON = ("u_t**2/2 - c**2*u_x**2/2 - m**2*u**2/2", "{segment: L}", "{all: fixed}",
                {"c": 1.5, "m": 2.0, "L": 1.2})
END_MASS = ("rho*u_t**2/2 - tau*u_x**2/2", "{segment: L}", "{left: fixed, right: {mass: M}}",
            {"rho": 0.5, "tau": 3.0, "L": 1.2, "M": 0.7})


@pytest.fixture(autouse=True)
def thirty_digits():
    """The closed forms in 30-digit arithmetic (the checker's precision)."""
    with mp.workdps(30):
        yield


def problem_text(system: tuple) -> str:
    density, domain, boundary, params = system
    lines = "\n".join(f"  {k}: {{value: {v}}}" for k, v in params.items())
    return (f"id: lim-9701\nsource: test\ntitle: a field\nparameters:\n{lines}\nfield:\n"
            f"  domain: {domain}\n  density: {density}\n  boundary: {boundary}\n")


def write_problem(tmp_path, system: tuple):
    d = tmp_path / "problems" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    path = d / "9701.yaml"
    path.write_text(problem_text(system))
    return path


def check(tmp_path, system: tuple, quantity: str, book, extra: str = "") -> Status:
    """One part's outcome for `book` (a YAML value written as given)."""
    analysis = Analysis(load_problem(write_problem(tmp_path, system)))
    key = tmp_path / "key.yaml"
    key.write_text(f"problem: lim-9701\nsource: test\nparts:\n  - part: a\n    cite: c\n"
                   f"    quantity: {quantity}\n{extra}    book: {book}\n")
    answers = load_answers(key)
    assert validate_key(analysis, answers) == {}
    (outcome,) = check_problem(analysis, answers)
    return outcome


def engine_frequencies(tmp_path, system: tuple, count: int) -> list[float]:
    analysis = Analysis(load_problem(write_problem(tmp_path, system)))
    model = analysis.built.field()
    point = {p.symbol: sp.Float(p.value, 30) for p in analysis.problem.parameters.values()}
    with mp.workdps(30):
        return [mp.sqrt(v) for v in squared_frequencies(model, point, count)]


# ---- frequencies against closed forms ------------------------------------------------------
def test_rectangular_membrane(tmp_path):
    """ω_mn = c·π·sqrt((m/a)² + (n/b)²), c = sqrt(τ/σ): sin(mπx/a)·sin(nπy/b) separates the
    wave equation with u = 0 on the four edges."""
    p = MEMBRANE[3]
    c = mp.sqrt(mp.mpf(p["tau"]) / mp.mpf(p["sigma"]))
    exact = sorted(c * mp.pi * mp.sqrt((m / mp.mpf(p["a"]))**2 + (n / mp.mpf(p["b"]))**2)
                   for m in range(1, 8) for n in range(1, 8))[:8]
    got = engine_frequencies(tmp_path, MEMBRANE, 8)
    assert all(abs(g - e) < mp.mpf(10)**-25 * e for g, e in zip(got, exact, strict=True))


SQUARE = "    restrict: {b: a}\n"  # a square at every parameter point drawn


def test_square_membrane_degenerate_pair(tmp_path):
    """On a square (1,2) and (2,1) share c·π·sqrt(5)/a: listed twice, as a string's double
    modes are."""
    square = (*MEMBRANE[:3], {"sigma": 1.0, "tau": 1.0, "a": 1.0, "b": 1.0})
    got = engine_frequencies(tmp_path, square, 3)
    assert abs(got[1] - got[2]) < mp.mpf(10)**-25
    assert abs(got[1] - mp.pi * mp.sqrt(5)) < mp.mpf(10)**-25
    w = "pi*sqrt(tau/sigma)*sqrt(5)/a"
    assert check(tmp_path, square, "field_frequencies",
                 f'["pi*sqrt(2*tau/sigma)/a", "{w}", "{w}"]', SQUARE).status == Status.PASS
    # the pair listed once, then the next mode: the list is not the lowest three
    assert check(tmp_path, square, "field_frequencies",
                 f'["pi*sqrt(2*tau/sigma)/a", "{w}", "pi*sqrt(8*tau/sigma)/a"]', SQUARE
                 ).status == Status.FAIL


def test_disk_membrane(tmp_path):
    """ω = c·j_{n,s}/R: J_n(kr)·cos nθ is regular at the centre, J_n(kR) = 0 at the rim;
    n = 0, 1, 2 and the second zero of J_0 are the six lowest (n ≥ 1 twice)."""
    p = DISK[3]
    c = mp.sqrt(mp.mpf(p["tau"]) / mp.mpf(p["sigma"])) / mp.mpf(p["R"])
    zeros = [mp.besseljzero(0, 1), mp.besseljzero(1, 1), mp.besseljzero(1, 1),
             mp.besseljzero(2, 1), mp.besseljzero(2, 1), mp.besseljzero(0, 2)]
    got = engine_frequencies(tmp_path, DISK, 6)
    assert all(abs(g - c * z) < mp.mpf(10)**-25 * c * z for g, z in zip(got, zeros, strict=True))


def test_cantilever_beam(tmp_path):
    """X = cosh βx − cos βx + B(sinh βx − sin βx) clamps x = 0; X″(L) = X‴(L) = 0 gives
    1 + cos βL·cosh βL = 0, βL = 1.8751…, and ω = β²·sqrt(EI/ρA)."""
    p = BEAM[3]
    with mp.workdps(30):
        roots = [mp.findroot(lambda z: 1 + mp.cos(z) * mp.cosh(z), g) for g in (1.9, 4.7, 7.85)]
    assert abs(roots[0] - mp.mpf("1.8751040687")) < 1e-10
    scale = mp.sqrt(mp.mpf(p["EI"]) / mp.mpf(p["rhoA"])) / mp.mpf(p["L"])**2
    got = engine_frequencies(tmp_path, BEAM, 3)
    assert all(abs(g - z**2 * scale) < mp.mpf(10)**-25 * g for g, z in zip(got, roots,
                                                                           strict=True))


def test_hinged_beam(tmp_path):
    """sin(nπx/L) has u = u_xx = 0 at both ends: ω = (nπ/L)²·sqrt(EI/ρA)."""
    p = HINGED[3]
    got = engine_frequencies(tmp_path, HINGED, 3)
    for n, g in enumerate(got, 1):
        exact = (n * mp.pi / mp.mpf(p["L"]))**2 * mp.sqrt(mp.mpf(p["EI"]) / mp.mpf(p["rhoA"]))
        assert abs(g - exact) < mp.mpf(10)**-25 * exact


def test_klein_gordon(tmp_path):
    """u_tt = c²u_xx − m²u with u = sin(kx)·cos ωt: ω² = c²k² + m², k = nπ/L."""
    p = KLEIN_GORDON[3]
    got = engine_frequencies(tmp_path, KLEIN_GORDON, 3)
    for n, g in enumerate(got, 1):
        k = n * mp.pi / mp.mpf(p["L"])
        exact = mp.sqrt(mp.mpf(p["c"])**2 * k**2 + mp.mpf(p["m"])**2)
        assert abs(g - exact) < mp.mpf(10)**-25 * exact


def test_string_with_an_end_mass(tmp_path):
    """u = sin(kx)·cos ωt, ω = ck: the mass's equation M·u_tt = −τ·u_x at x = L gives
    τk·cos kL = Mω²·sin kL, i.e. tan(kL) = τ/(M c² k) = ρ/(M k)."""
    p = END_MASS[3]
    rho, M, L = (mp.mpf(p[k]) for k in ("rho", "M", "L"))
    c = mp.sqrt(mp.mpf(p["tau"]) / rho)
    with mp.workdps(30):
        ks = [mp.findroot(lambda k: mp.tan(k * L) - rho / (M * k), g / L)
              for g in (0.9, 3.4, 6.5)]
    got = engine_frequencies(tmp_path, END_MASS, 3)
    for g, k in zip(got, ks, strict=True):
        assert abs(g - c * k) < mp.mpf(10)**-24 * g


# ---- the spectral discretization converges to the same values ------------------------------
def test_collocation_converges_to_the_beam_and_the_membrane():
    """Chebyshev collocation against the closed forms: the clamped–free beam's λ = β⁴ to
    1e-11 at 16-48 points, a π×π membrane's λ = m² + n² to 1e-12 at 20 points per side."""
    exact = [1.875104068711961166**4, 4.694091132974174576**4]
    for points in (16, 24, 48):
        got = segment_eigenvalues([0, 0, 0, 0, -1.0], 1.0, 1.0,
                                  [([1, 0, 0, 0], 0), ([0, 1, 0, 0], 0)],
                                  [([0, 0, 1, 0], 0), ([0, 0, 0, 1], 0)], 2, points)
        assert got == pytest.approx(exact, rel=1e-10), points
    got = rectangle_eigenvalues({(2, 0): 1, (0, 2): 1}, 1, (np.pi, np.pi),
                                {e: [1, 0] for e in ("x0", "x1", "y0", "y1")}, 6)
    assert got == pytest.approx([2, 5, 5, 8, 10, 10], rel=1e-11)


# ---- the field equation ------------------------------------------------------------------
def test_field_equations_derived():
    """Euler–Lagrange by hand: the beam −ρA·u_tt − EI·u_xxxx, the disk's polar Laplacian."""
    from mechbook.model.continuum import field_of
    from mechbook.model.yamlio import loads

    for system, want in ((BEAM, "-rhoA*u_tt - EI*u_xxxx"),
                         (DISK, "-sigma*u_tt + tau*(u_rr + u_r/r + u_thetatheta/r**2)"),
                         (KLEIN_GORDON, "-u_tt + c**2*u_xx - m**2*u")):
        doc = loads(problem_text(system), "x.yaml")
        params = {k: sp.Symbol(k, positive=True) for k in system[3]}
        model = field_of(doc, params)
        names = dict(model.names)
        assert sp.expand(field_equation(model) - sp.sympify(want, locals=names)) == 0


@pytest.mark.parametrize("book, status", [
    ('"sigma*u_tt = tau*(u_xx + u_yy)"', Status.PASS),
    ('"2*sigma*u_tt - 2*tau*(u_xx + u_yy) = 0"', Status.PASS),  # a factor: the same PDE
    ('"sigma*u_tt = tau*(u_xx + 1.01*u_yy)"', Status.FAIL),
    ('"sigma*u_tt = tau*(u_xx + (1 + 1e-6)*u_yy)"', Status.FAIL),
    ('"sigma*u_tt = tau*(u_xx - u_yy)"', Status.FAIL),
    ('"sigma*u_tt = x*tau*(u_xx + u_yy)"', Status.FAIL)])  # a factor that is not constant
def test_field_equation_mutations(tmp_path, book, status):
    assert check(tmp_path, MEMBRANE, "field_equation", book).status == status


# ---- the frequencies' check fails 1 % and 1e-6 wrong values ---------------------------------
@pytest.mark.parametrize("factor, status", [("1", Status.PASS), ("1.01", Status.FAIL),
                                            ("(1 + 1e-6)", Status.FAIL)])
def test_frequency_mutations(tmp_path, factor, status):
    """The hinged beam's (nπ/L)²·sqrt(EI/ρA), the second value mutated."""
    w = "(pi/L)**2*sqrt(EI/rhoA)"
    book = f'["{w}", "{factor}*4*{w}", "9*{w}"]'
    assert check(tmp_path, HINGED, "field_frequencies", book).status == status


@pytest.mark.parametrize("factor, status", [("1", Status.PASS), ("1.01", Status.FAIL),
                                            ("(1 + 1e-6)", Status.FAIL)])
def test_klein_gordon_partial_mutations(tmp_path, factor, status):
    """`partial:` one value among the lowest: ω_2 = sqrt(c²(2π/L)² + m²)."""
    book = f'["{factor}*sqrt(c**2*(2*pi/L)**2 + m**2)"]'
    assert check(tmp_path, KLEIN_GORDON, "field_frequencies", book,
                 "    partial: true\n").status == status


# ---- currents ----------------------------------------------------------------------------
@pytest.mark.parametrize("density, flux, status", [
    ("rhoA*u_t**2/2 + EI*u_xx**2/2", "[EI*(u_t*u_xxx - u_tx*u_xx)]", Status.PASS),
    ("rhoA*u_t**2/2 + 1.01*EI*u_xx**2/2", "[EI*(u_t*u_xxx - u_tx*u_xx)]", Status.FAIL),
    ("rhoA*u_t**2/2 + EI*u_xx**2/2", "[EI*(u_t*u_xxx - (1 + 1e-6)*u_tx*u_xx)]", Status.FAIL)])
def test_beam_energy_current(tmp_path, density, flux, status):
    """e = ρA·u_t²/2 + EI·u_xx²/2, j = EI(u_t·u_xxx − u_xt·u_xx): D_t e + D_x j =
    u_t(ρA·u_tt + EI·u_xxxx) = 0 on solutions."""
    book = f'{{density: "{density}", flux: ["{flux[1:-1]}"]}}'
    assert check(tmp_path, BEAM, "field_current", book, "    noether: t\n").status == status


def test_momentum_current_of_klein_gordon(tmp_path):
    """Translation in x: ρ = u_t·u_x (the canonical u_x·∂ℒ/∂u_t), j = −(u_t² + c²u_x² −
    m²u²)/2: D_t ρ + D_x j = u_x(u_tt − c²u_xx + m²u) = 0 on solutions; a current of the
    wrong symmetry (the energy's density with this flux) fails."""
    flux = '["-(u_t**2 + c**2*u_x**2 - m**2*u**2)/2"]'
    assert check(tmp_path, KLEIN_GORDON, "field_current",
                 f'{{density: "u_t*u_x", flux: {flux}}}',
                 "    noether: x\n").status == Status.PASS
    assert check(tmp_path, KLEIN_GORDON, "field_current",
                 f'{{density: "u_t*u_x", flux: {flux}}}',
                 "    noether: t\n").status == Status.FAIL
    assert check(tmp_path, KLEIN_GORDON, "field_current",
                 '{density: "u_t*u_x", flux: ["-(u_t**2 + c**2*u_x**2)/2"]}'
                 ).status == Status.FAIL


# ---- bad input: file and line, nothing built -------------------------------------------------
def test_a_beam_with_one_condition_per_end_does_not_close(tmp_path):
    bad = (BEAM[0], BEAM[1], "{left: fixed, right: free}", BEAM[3])
    path = write_problem(tmp_path, bad)
    with pytest.raises(SpecError, match=r"9701\.yaml:\d+: field/boundary/left: the boundary "
                                        r"conditions do not close.*order four.*2 conditions"):
        load_problem(path)


def test_a_clamped_string_does_not_close(tmp_path):
    bad = (END_MASS[0], END_MASS[1], "{left: clamped, right: fixed}", END_MASS[3])
    with pytest.raises(SpecError, match=r"field/boundary/left: the boundary conditions do not "
                                        r"close.*'clamped' gives 2"):
        load_problem(write_problem(tmp_path, bad))


@pytest.mark.parametrize("density, boundary, match", [
    ("sigma*u_t**2/2 - tau*u_x**2/2", "{x0: fixed}", "edge 'x1' has no boundary condition"),
    ("sigma*u_t**2/2 - tau*u_x**2/2", "{all: fixed, left: free}", "no edge 'left'"),
    ("sigma*u_t**2/2 - tau*u_x**2/2 - u_tx**2", "{all: fixed}", "mixed ones with t"),
    ("0 - tau*(u_x**2 + u_y**2)/2", "{all: fixed}", "no kinetic term"),
    ("sigma*u_t**2/2 - tau*v_x**2", "{all: fixed}", "v_x")])
def test_bad_fields(tmp_path, density, boundary, match):
    bad = (density, "{rectangle: [a, b]}", boundary, MEMBRANE[3])
    with pytest.raises(SpecError, match=rf"9701\.yaml:\d+: .*{match}"):
        load_problem(write_problem(tmp_path, bad))


# ---- mode shapes ---------------------------------------------------------------------------
@pytest.mark.parametrize("frequency, shape, status", [
    ("4*(pi/L)**2*sqrt(EI/rhoA)", "sin(2*pi*x/L)", Status.PASS),
    ("1.01*4*(pi/L)**2*sqrt(EI/rhoA)", "sin(2*pi*x/L)", Status.FAIL),
    ("(1 + 1e-6)*4*(pi/L)**2*sqrt(EI/rhoA)", "sin(2*pi*x/L)", Status.FAIL),
    ("4*(pi/L)**2*sqrt(EI/rhoA)", "sin(2*pi*x/L) + 1e-6*x", Status.FAIL),  # not hinged
    ("4*(pi/L)**2*sqrt(EI/rhoA)", "cos(2*pi*x/L)", Status.FAIL)])  # u(0) = 1
def test_hinged_beam_mode(tmp_path, frequency, shape, status):
    """sin(nπx/L): u = u_xx = 0 at both ends, EI·(nπ/L)⁴ = ρA·ω²."""
    book = f'{{frequency: "{frequency}", shape: "{shape}"}}'
    assert check(tmp_path, HINGED, "field_mode", book).status == status


def test_membrane_mode_and_a_free_edge(tmp_path):
    """sin(πx/a)·sin(2πy/b) at c·π·sqrt(1/a² + 4/b²) on a fixed rectangle; with the x
    edges free, cos(πx/a)·sin(πy/b) (u_x = 0 at x = 0, a) and sin does not."""
    w = "pi*sqrt(tau/sigma)*sqrt(1/a**2 + 4/b**2)"
    assert check(tmp_path, MEMBRANE, "field_mode",
                 f'{{frequency: "{w}", shape: "sin(pi*x/a)*sin(2*pi*y/b)"}}'
                 ).status == Status.PASS
    free = (MEMBRANE[0], MEMBRANE[1], "{x0: free, x1: free, y0: fixed, y1: fixed}",
            MEMBRANE[3])
    w = "pi*sqrt(tau/sigma)*sqrt(1/a**2 + 1/b**2)"
    assert check(tmp_path, free, "field_mode",
                 f'{{frequency: "{w}", shape: "cos(pi*x/a)*sin(pi*y/b)"}}'
                 ).status == Status.PASS
    assert check(tmp_path, free, "field_mode",
                 f'{{frequency: "{w}", shape: "sin(pi*x/a)*sin(pi*y/b)"}}'
                 ).status == Status.FAIL


def test_string_end_mass_mode(tmp_path):
    """sin(kx) with ω = ck solves the string; at x = L the mass's M·u_tt = −τ·u_x holds
    only where τk·cos kL = Mω²·sin kL (a k off that root fails)."""
    p = END_MASS[3]
    rho, M, L = (mp.mpf(p[k]) for k in ("rho", "M", "L"))
    k = mp.findroot(lambda k: mp.tan(k * L) - rho / (M * k), 0.9 / L)
    # with M = rho*L (the key's `restrict:`) the root z = kL of tan z = 1/z is universal
    z = mp.findroot(lambda z: mp.tan(z) - 1 / z, 0.86)  # tan z = 1/z when M = rho*L
    assert abs(k * L - mp.findroot(lambda z: mp.tan(z) - rho * L / (M * z), 0.9)) < 1e-25
    book = f'{{frequency: "{mp.nstr(z, 28)}*sqrt(tau/rho)/L", shape: "sin({mp.nstr(z, 28)}*x/L)"}}'
    restrict = "    restrict: {M: rho*L}\n"
    assert check(tmp_path, END_MASS, "field_mode", book, restrict).status == Status.PASS
    wrong = book.replace(mp.nstr(z, 28), mp.nstr(z * 1.01, 28))
    assert check(tmp_path, END_MASS, "field_mode", wrong, restrict).status == Status.FAIL


def test_angular_momentum_current_of_the_disk(tmp_path):
    """Rotation θ → θ + ε: with the action density r·ℒ, Noether gives
    ∂_t(σu_t·u_θ) + (1/r)∂_r(r·(−τu_r·u_θ)) + (1/r)∂_θ(−τu_θ²/r − r·ℒ) = 0 on solutions,
    ρ = u_θ·∂ℒ/∂u_t the canonical density of the translation in θ; the flux without its
    −r·ℒ term fails."""
    lag = "(sigma*u_t**2/2 - tau*(u_r**2 + u_theta**2/r**2)/2)"
    flux = f'["-tau*u_r*u_theta", "-tau*u_theta**2/r - r*{lag}"]'
    assert check(tmp_path, DISK, "field_current",
                 f'{{density: "sigma*u_t*u_theta", flux: {flux}}}',
                 "    noether: theta\n").status == Status.PASS
    assert check(tmp_path, DISK, "field_current",
                 '{density: "sigma*u_t*u_theta", flux: ["-tau*u_r*u_theta", '
                 '"-tau*u_theta**2/r"]}', "    noether: theta\n").status == Status.FAIL


def test_annulus_and_free_disk(tmp_path):
    """An annulus fixed at r = a and b: R = J_n(kr)Y_n(ka) − J_n(ka)Y_n(kr) vanishes at a,
    and at b where J_n(ka)Y_n(kb) = J_n(kb)Y_n(ka); the lowest (n = 0) found here by
    findroot near the estimate π/(b − a). A disk with a free rim: J_n′(kR) = 0, so after
    the rigid mode (ω = 0) come c·j′_{1,1}/R twice and c·j′_{2,1}/R twice."""
    annulus = ("sigma*u_t**2/2 - tau*(u_r**2 + u_theta**2/r**2)/2", "{annulus: [R1, R2]}",
               "{all: fixed}", {"sigma": 1.0, "tau": 1.0, "R1": 1.0, "R2": 2.0})
    k = mp.findroot(lambda k: mp.besselj(0, k) * mp.bessely(0, 2 * k)
                    - mp.besselj(0, 2 * k) * mp.bessely(0, k), mp.pi)
    got = engine_frequencies(tmp_path, annulus, 3)
    assert abs(got[0] - k) < mp.mpf(10)**-25 * k
    assert abs(got[1] - got[2]) < mp.mpf(10)**-25  # n = 1, cos and sin
    free = (DISK[0], DISK[1], "{edge: free}", DISK[3])
    c = mp.sqrt(mp.mpf(12.0) / mp.mpf(0.3)) / mp.mpf(0.25)
    got = engine_frequencies(tmp_path, free, 5)
    want = [0, *[c * mp.besseljzero(1, 1, derivative=1)] * 2,
            *[c * mp.besseljzero(2, 1, derivative=1)] * 2]
    assert all(abs(g - w) < mp.mpf(10)**-25 * c for g, w in zip(got, want, strict=True))


def test_disk_pair_listed_once_fails(tmp_path):
    """j_01, j_11, j_21: the (1, cos)/(1, sin) pair counted once is not the lowest three."""
    c = "sqrt(tau/sigma)/R"
    z = [mp.nstr(mp.besseljzero(n, 1), 30) for n in (0, 1, 2)]
    assert check(tmp_path, DISK, "field_frequencies",
                 f'["{z[0]}*{c}", "{z[1]}*{c}", "{z[1]}*{c}"]').status == Status.PASS
    assert check(tmp_path, DISK, "field_frequencies",
                 f'["{z[0]}*{c}", "{z[1]}*{c}", "{z[2]}*{c}"]').status == Status.FAIL


@pytest.mark.parametrize("system", [MEMBRANE, DISK, BEAM, HINGED, KLEIN_GORDON, END_MASS,
                                    (DISK[0], "{annulus: [R, 2*R]}", "{inner: free, "
                                     "outer: fixed}", DISK[3])],
                         ids=["membrane", "disk", "beam", "hinged", "klein-gordon",
                              "end-mass", "annulus"])
def test_collocation_agrees_with_separation(tmp_path, system):
    """The spectral cross-check's discretization (no separation) within 1e-9 of the
    separated ω² for every kind of domain and edge."""
    from mechbook.crosscheck.spectral import discretized

    analysis = Analysis(load_problem(write_problem(tmp_path, system)))
    model = analysis.built.field()
    point = {p.symbol: sp.Float(p.value, 30) for p in analysis.problem.parameters.values()}
    separated = [float(v) for v in squared_frequencies(model, point, 5)]
    assert discretized(model, point, 5) == pytest.approx(separated, rel=1e-9, abs=1e-9)


def test_a_negative_mode_frequency_fails(tmp_path):
    """Only ω² enters u = φ·cos ωt's equations: the sign is checked on its own."""
    book = '{frequency: "-4*(pi/L)**2*sqrt(EI/rhoA)", shape: "sin(2*pi*x/L)"}'
    assert check(tmp_path, HINGED, "field_mode", book).status == Status.FAIL


def test_string_with_an_end_spring(tmp_path):
    """A spring K at x = L: −τ·u_x − K·u = 0 there, so with u = sin(kx):
    τk·cos kL + K·sin kL = 0, tan kL = −τk/K; ω = ck (roots past π/2, 3π/2, ...)."""
    spring = (END_MASS[0], END_MASS[1], "{left: fixed, right: {spring: K}}",
              {"rho": 0.5, "tau": 3.0, "L": 1.2, "K": 4.0})
    tau, K, L = mp.mpf(3.0), mp.mpf(4.0), mp.mpf(1.2)
    c = mp.sqrt(tau / mp.mpf(0.5))
    ks = [mp.findroot(lambda k: tau * k * mp.cos(k * L) + K * mp.sin(k * L),
                      ((2 * n - 1) * mp.pi / 2 / L + 1e-9, n * mp.pi / L), solver="anderson")
          for n in (1, 2, 3)]
    got = engine_frequencies(tmp_path, spring, 3)
    for g, k in zip(got, ks, strict=True):
        assert abs(g - c * k) < mp.mpf(10)**-24 * g


def test_the_spectral_crosscheck_can_fail(tmp_path, monkeypatch):
    """The cross-check passes the membrane's separated values and fails them 1e-6 off
    (as a wrong separation would be)."""
    import mechbook.crosscheck.spectral as spectral

    analysis = Analysis(load_problem(write_problem(tmp_path, MEMBRANE)))
    key = tmp_path / "key.yaml"
    key.write_text("problem: lim-9701\nsource: test\nparts:\n  - part: a\n    cite: c\n"
                   "    quantity: field_frequencies\n    book: [1, 2, 3]\n")
    part = load_answers(key).parts[0]
    assert spectral.spectral_part(analysis, part, {}).status == Status.PASS
    real = spectral.squared_frequencies
    monkeypatch.setattr(spectral, "squared_frequencies",
                        lambda *a: [v * (1 + mp.mpf("1e-6")) for v in real(*a)])
    got = spectral.spectral_part(analysis, part, {})
    assert got.status == Status.FAIL and got.error > 1e-7, got.detail


def test_a_second_order_transfer_matrix_in_closed_form():
    """exp(A·L) of a 2×2 mode matrix by e^{tL}[cosh(sL)·I + sinh(sL)/s·(A − tI)]: against
    the oscillator's own closed form (φ″ = −k²φ: [[cos kL, sin kL/k], [−k sin kL, cos kL]]),
    the growing one's (cosh, sinh), a double root (φ″ − φ′ + φ/4 = 0: e^{L/2}(1 − L/2, L;
    −L/4, 1 + L/2)), and mpmath's series to 38 digits."""
    from mechbook.engine.continuum import transfer_matrix

    with mp.workdps(40):
        k, L = mp.mpf("2.7"), mp.mpf("1.3")
        osc = transfer_matrix(mp.matrix([[0, 1], [-k * k, 0]]), L)
        want = mp.matrix([[mp.cos(k * L), mp.sin(k * L) / k], [-k * mp.sin(k * L),
                                                                mp.cos(k * L)]])
        assert mp.mnorm(osc - want, 1) < mp.mpf(10) ** -38
        grow = transfer_matrix(mp.matrix([[0, 1], [k * k, 0]]), L)
        want = mp.matrix([[mp.cosh(k * L), mp.sinh(k * L) / k], [k * mp.sinh(k * L),
                                                                  mp.cosh(k * L)]])
        assert mp.mnorm(grow - want, 1) < mp.mpf(10) ** -37 * mp.mnorm(want, 1)
        double = transfer_matrix(mp.matrix([[0, 1], [-mp.mpf(1) / 4, 1]]), L)
        want = mp.exp(L / 2) * mp.matrix([[1 - L / 2, L], [-L / 4, 1 + L / 2]])
        assert mp.mnorm(double - want, 1) < mp.mpf(10) ** -38
        A = mp.matrix([[mp.mpf("0.3"), mp.mpf("-1.7")], [mp.mpf("2.2"), mp.mpf("-0.9")]])
        assert mp.mnorm(transfer_matrix(A, L) - mp.expm(A * L), 1) < mp.mpf(10) ** -38


def test_a_beams_transfer_matrix_in_closed_form(monkeypatch):
    """exp(A·L) of the companion matrix of φ⁗ = β⁴φ (a uniform beam) is f0·I + f1·A +
    f2·A² + f3·A³ (A⁴ = β⁴I) with, from the solution basis cosh, sinh, cos, sin (derived
    here: each f_k solves φ⁗ = β⁴φ with φ^(j)(0) = δ_jk): f0 = (cosh βL + cos βL)/2,
    f1 = (sinh βL + sin βL)/(2β), f2 = (cosh βL − cos βL)/(2β²), f3 = (sinh βL −
    sin βL)/(2β³); of φ‴ = ν³φ, from e^{νx} and e^{−νx/2}·(cos, sin)(√3νx/2): f0 = (e^{νL}
    + 2e^{−νL/2}cos(√3νL/2))/3; of φ⁗ = −4γ⁴φ (roots γ(±1 ± i)): f0 = cosh γL·cos γL. To
    38 digits, without mpmath's series (which runs only where a middle coefficient is not
    zero, as for φ⁗ + φ″ = μφ)."""
    from mechbook.engine import continuum
    from mechbook.engine.continuum import transfer_matrix

    def companion(last):
        n = len(last)
        A = mp.zeros(n, n)
        for i in range(n - 1):
            A[i, i + 1] = 1
        for k, a in enumerate(last):
            A[n - 1, k] = a
        return A

    with mp.workdps(40):
        b, L = mp.mpf("1.9"), mp.mpf("1.3")
        calls = []
        monkeypatch.setattr(continuum.mp, "expm", lambda *a: calls.append(a) or
                            mp.matrix(4, 4))
        A = companion([b**4, 0, 0, 0])
        got = transfer_matrix(A, L)
        ch, sh, c, s = mp.cosh(b * L), mp.sinh(b * L), mp.cos(b * L), mp.sin(b * L)
        f = [(ch + c) / 2, (sh + s) / (2 * b), (ch - c) / (2 * b**2), (sh - s) / (2 * b**3)]
        want = f[0] * mp.eye(4) + f[1] * A + f[2] * A * A + f[3] * A * A * A
        assert mp.mnorm(got - want, 1) < mp.mpf(10) ** -37 * mp.mnorm(want, 1)
        nu = mp.mpf("0.8")
        got = transfer_matrix(companion([nu**3, 0, 0]), L)
        want = (mp.exp(nu * L) + 2 * mp.exp(-nu * L / 2) * mp.cos(mp.sqrt(3) * nu * L / 2)) / 3
        assert abs(got[0, 0] - want) < mp.mpf(10) ** -38
        g = mp.mpf("1.1")
        got = transfer_matrix(companion([-4 * g**4, 0, 0, 0]), L)
        assert abs(got[0, 0] - mp.cosh(g * L) * mp.cos(g * L)) < mp.mpf(10) ** -38
        assert not calls
        transfer_matrix(companion([b**4, 0, 1, 0]), L)  # φ⁗ = φ″ + β⁴φ: the series
        assert len(calls) == 1


def test_squared_frequencies_are_computed_once_per_point(tmp_path, monkeypatch):
    """A part's default point is its spectral cross-check's: the second asks no root of
    the boundary determinant, and gets the same 30-digit values whatever its precision."""
    import mechbook.engine.continuum as continuum

    an = Analysis(load_problem(write_problem(tmp_path, MEMBRANE)))
    model = an.built.field()
    point = {p.symbol: sp.Float(p.value, 30) for p in an.problem.parameters.values()}
    with mp.workdps(30):
        first = squared_frequencies(model, point, 3)
    calls = []
    real = continuum._polish
    monkeypatch.setattr(continuum, "_polish", lambda *a: calls.append(a) or real(*a))
    again = squared_frequencies(model, point, 3)  # at the default 15 digits
    assert again == first and not calls
    other = squared_frequencies(model, {**point, next(iter(point)): sp.Float(0.9, 30)}, 3)
    assert calls and other != first
