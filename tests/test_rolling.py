"""Rolling without slipping and other velocity constraints, against closed forms derived in
tests/constrained_systems.py and against sympy.physics.mechanics' own rolling disc."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from constrained_systems import (
    COIN,
    HOOP,
    SLEIGH,
    SYMPY_DISC,
    TURNTABLE,
    check,
    key,
    write_tree,
)

from mechbook.app.authoring.validate import build_systems
from mechbook.crosscheck.newton import newton_crosscheck
from mechbook.engine.analysis import Analysis
from mechbook.errors import MechbookError
from mechbook.model.problem import load_problem
from mechbook.numerics.simulate import simulate

UPRIGHT = "    about: {phi: 0, theta: pi/2, psi: 0}\n    steady: {psi: Omega}\n"


def _analysis(tmp_path, num: str, problem: str) -> Analysis:
    ppath, _ = write_tree(tmp_path, num, problem, key(""))
    return Analysis(load_problem(ppath))


# ---- sympy's rolling disc: its test's asserted matrix ------------------------------------
def test_sympy_rolling_disc_state_matrix(tmp_path):
    """sympy's test_linearize_rolling_disc_kane asserts A at m = r = g = 1, q1d = q2 = 0 in the
    states (q1..q5, u1, u2, u3), u the disc's angular velocity in the lean frame; at that
    point u1 = q2', u2 = q3', u3 = q1', so our states (q1..q5, q1', q2', q3') are theirs
    permuted."""
    an = _analysis(tmp_path, "9501", SYMPY_DISC)
    sys = an.system()
    q1, q2, q3, q4, q5 = sys.q
    names = {str(k): k for k in an.problem.values()}
    lin = an.steady_linear(None, {q3: names["Omega"]}, {q1: names["phi0"], q2: 0, q3: 0},
                           reduce=False)
    assert lin.states == ["delta_q1", "delta_q2", "delta_q3", "delta_q4", "delta_q5",
                          "delta_q1dot", "delta_q2dot", "delta_q3dot"]
    ours = lin.state_matrix().subs({names["m"]: 1, names["r"]: 1, names["g"]: 1})
    s1, c1 = sp.sin(names["phi0"]), sp.cos(names["phi0"])
    w = names["Omega"]
    theirs = sp.Matrix([  # sympy's A_sol with q1 -> phi0, q3d -> Omega
        [0, 0, 0, 0, 0, 0, 0, 1],
        [0, 0, 0, 0, 0, 1, 0, 0],
        [0, 0, 0, 0, 0, 0, 1, 0],
        [s1 * w, 0, 0, 0, 0, -s1, -c1, 0],
        [-c1 * w, 0, 0, 0, 0, c1, -s1, 0],
        [0, sp.Rational(4, 5), 0, 0, 0, 0, 0, 6 * w / 5],
        [0, 0, 0, 0, 0, 0, 0, 0],
        [0, 0, 0, 0, 0, -2 * w, 0, 0]])
    order = [0, 1, 2, 3, 4, 7, 5, 6]  # our state k is their state order[k]
    P = sp.zeros(8, 8)
    for k, j in enumerate(order):
        P[k, j] = 1
    assert (ours - P * theirs * P.T).applyfunc(sp.simplify) == sp.zeros(8, 8)
    # and at the critical speed every exponent is zero (sympy's second assertion)
    crit = {names["m"]: 1.0, names["r"]: 1.0, names["g"]: 1.0, names["phi0"]: 0.3,
            names["Omega"]: sp.N(sp.sqrt(3) / 3, 60)}  # exact to 60 digits
    assert np.max(np.abs(lin.exponents(crit, precise=True))) < 1e-20


def _disc(parts: str) -> str:
    return key(parts.replace("ABOUT", "    about: {q1: phi0, q2: 0, q3: 0}\n"
                                      "    steady: {q3: Omega}\n"))


@pytest.mark.parametrize("book, status", [
    ("Omega**2 > g/(3*r)", "pass"),
    ("Omega**2 > 1.01*g/(3*r)", "fail"),
    ("Omega**2 > 0.99*g/(3*r)", "fail"),
    ("Omega**2 > (1 + 1e-6)*g/(3*r)", "fail"),
    ("Omega**2 > g/(4*r)", "fail"),
])
def test_sympy_disc_stability_at_its_boundary(tmp_path, book, status):
    out = check(tmp_path, "9502", SYMPY_DISC, _disc(
        f"  - part: a\n    cite: upright\n    quantity: stability\nABOUT    book: \"{book}\"\n"))
    assert out["a"].status == status, out["a"].detail


# ---- a coin and a hoop in Euler angles, the contact from the declared shape ---------------
@pytest.mark.parametrize("shape, threshold, wobble", [
    ("disk", "g/(3*R)", "sqrt((12*Omega**2 - 4*g/R)/5)"),
    ("ring", "g/(4*R)", "sqrt((8*Omega**2 - 2*g/R)/3)"),
])
def test_coin_upright_rolling(tmp_path, shape, threshold, wobble):
    problem = COIN.replace("SHAPE", shape)
    parts = (f"  - part: a\n    cite: stability\n    quantity: stability\n{UPRIGHT}"
             f"    book: \"Omega**2 > {threshold}\"\n"
             f"  - part: b\n    cite: wobble\n    quantity: frequencies\n{UPRIGHT}"
             f"    assume: [\"Omega**2 > {threshold}\"]\n    book: [\"{wobble}\"]\n"
             f"  - part: c\n    cite: moved 1 %\n    quantity: stability\n{UPRIGHT}"
             f"    book: \"Omega**2 > 1.01*{threshold}\"\n"
             f"  - part: d\n    cite: wobble 1e-6 off\n    quantity: frequencies\n{UPRIGHT}"
             f"    assume: [\"Omega**2 > {threshold}\"]\n    book: [\"(1 + 1e-6)*{wobble}\"]\n"
             "  - part: e\n    cite: freedoms\n    quantity: mode_count\n"
             "    book: {configuration: 5, velocity: 3}\n"
             "  - part: f\n    cite: freedoms\n    quantity: mode_count\n    book: 5\n")
    out = check(tmp_path, "9503", problem, key(parts))
    assert out["a"].status == "pass", out["a"].detail
    assert out["b"].status == "pass", out["b"].detail
    assert out["c"].status == "fail", out["c"].detail
    assert out["d"].status == "fail", out["d"].detail
    assert out["e"].status == "pass", out["e"].detail
    assert out["f"].status == "fail", out["f"].detail


def test_coin_energy_and_simulation_keep_the_constraints(tmp_path):
    """Rolling forces do no work: the energy is conserved (the check, and a run's drift);
    the run keeps both rolling constraints to its tolerance, reported beside the energy."""
    energy = ("m*(xdot**2 + ydot**2 + (R*cos(theta)*thetadot)**2)/2 + m*R**2*(phidot**2*"
              "sin(theta)**2 + thetadot**2)/8 + m*R**2*(psidot + phidot*cos(theta))**2/4 + "
              "m*g*R*sin(theta)")
    out = check(tmp_path, "9504", COIN.replace("SHAPE", "disk"), key(
        f"  - part: a\n    cite: energy\n    quantity: conserved\n    book: \"{energy}\"\n"))
    assert out["a"].status == "pass", out["a"].detail
    an = Analysis(load_problem(tmp_path / "problems" / "lim" / "9504.yaml"))
    sim = simulate(an, None, t_span=(0.0, 4.0), init={"theta": "1.4", "psidot": "12",
                                                      "phi": "0", "psi": "0",
                                                      "phidot": "0", "thetadot": "0"},
                   rtol=1e-10, atol=1e-12)
    drift = {d.name: d.relative for d in sim.drifts}
    assert drift["energy_function"] < 1e-8
    assert drift["constraint contact_1"] < 1e-8 and drift["constraint contact_2"] < 1e-8
    assert "xdot solved from the constraints" in sim.initial_source  # ydot stays 0


# ---- a steady motion of a constrained system: the constraints kept, their forces allowed --
@pytest.mark.parametrize("x_rate, status", [
    ("-R*Omega", "pass"),               # v_G = ω × (G − P) = (0, −Ω, 0) × (0, 0, R)
    ("-1.01*R*Omega", "fail"),          # the coin would slip
    ("-(1 + 1e-6)*R*Omega", "fail"),
    ("R*Omega", "fail"),
])
def test_a_rolling_coins_steady_motion_keeps_its_contact(tmp_path, x_rate, status):
    """Upright straight rolling: the coin's axis is −y (φ = 0, θ = π/2), so spinning at
    ψ̇ = Ω its centre moves at −RΩ along x. The free body's equations hold at any x rate
    (no force acts along x), so only the rolling rows tell the true rate from a slipping
    one."""
    out = check(tmp_path, "9510", COIN.replace("SHAPE", "disk"), key(
        "  - part: a\n    cite: rolling\n    quantity: steady_motion\n"
        "    book: {at: {y: 0, phi: 0, theta: pi/2}, rates: {x: \"" + x_rate + "\", "
        "psi: Omega}}\n"))
    assert out["a"].status == status, out["a"].detail


POLAR_BEAD = """\
id: lim-NUM
source: a particle held at radius l by a multiplier, in polar coordinates
title: particle on a circle (r, phi, one constraint)
parameters:
  m: {value: 0.5}
  l: {value: 1.3}
  w: {value: 2.0}
coordinates:
  r: {positive: true}
  phi: {}
kinetic: m*(rdot**2 + r**2*phidot**2)/2
potential: "0"
constraints:
  - {name: rod, expr: r - l}
"""


@pytest.mark.parametrize("at, status", [("l", "pass"), ("1.01*l", "fail"),
                                        ("(1 + 1e-6)*l", "fail")])
def test_a_steady_turn_needs_its_constraint_force(tmp_path, at, status):
    """Uniform turning at r = l: E_r = −m l ω² ≠ 0, the rod's pull λ = −m l ω² supplies it
    (the residual alone would fail a true motion); at r ≠ l the constraint is broken."""
    out = check(tmp_path, "9511", POLAR_BEAD, key(
        "  - part: a\n    cite: turning\n    quantity: steady_motion\n"
        f"    book: {{at: {{r: \"{at}\"}}, rates: {{phi: w}}}}\n"))
    assert out["a"].status == status, out["a"].detail


# ---- the Chaplygin sleigh: exponents of straight motion --------------------------------------
def _sleigh(book: str, quantity: str = "exponents", extra: str = "    partial: true\n") -> str:
    return key(f"  - part: a\n    cite: straight motion\n    quantity: {quantity}\n"
               f"    about: {{theta: 0}}\n    steady: {{x: v}}\n{extra}    book: {book}\n")


@pytest.mark.parametrize("book, status", [
    ('["-m*a*v/(I + m*a**2)"]', "pass"),
    ('["-1.01*m*a*v/(I + m*a**2)"]', "fail"),
    ('["-m*a*v/(I + m*a**2)", "0"]', "pass"),
    ('["m*a*v/(I + m*a**2)"]', "fail"),
])
def test_sleigh_exponents(tmp_path, book, status):
    out = check(tmp_path, "9505", SLEIGH, _sleigh(book))["a"]
    assert out.status == status, out.detail


@pytest.mark.parametrize("book, status", [("a*v > 0", "pass"), ("a*v < 0", "fail"),
                                          ("a*v > 0.01", "fail")])
def test_sleigh_turns_round_when_its_mass_trails(tmp_path, book, status):
    out = check(tmp_path, "9506", SLEIGH, _sleigh(f'"{book}"', "stability", ""))["a"]
    assert out.status == status, out.detail


def test_sleigh_freedoms_and_newton(tmp_path):
    out = check(tmp_path, "9507", SLEIGH, key(
        "  - part: a\n    cite: freedoms\n    quantity: mode_count\n"
        "    book: {configuration: 3, velocity: 2}\n"))
    assert out["a"].status == "pass", out["a"].detail
    an = Analysis(load_problem(tmp_path / "problems" / "lim" / "9507.yaml"))
    x = newton_crosscheck(an)
    assert x.status == "pass" and "constraint manifold" in x.detail, x.detail


# ---- a ball on a turntable moves on circles at 2Ω/7 ----------------------------------------
@pytest.mark.parametrize("book, status", [('["2*Omega/7"]', "pass"),
                                          ('["2.02*Omega/7"]', "fail"),
                                          ('["Omega/3"]', "fail")])
def test_ball_on_a_turntable(tmp_path, book, status):
    out = check(tmp_path, "9508", TURNTABLE, key(
        "  - part: a\n    cite: circles\n    quantity: frequencies\n"
        "    about: {x: 0, y: 0, a: 0, b: 0, c: 0}\n    steady: {c: Omega}\n    partial: true\n"
        f"    book: {book}\n"))["a"]
    assert out.status == status, out.detail


# ---- a hoop down an incline: acceleration, the friction rolling needs, energy ---------------
@pytest.mark.parametrize("part, status", [
    ("quantity: eom\n    book: [\"xddot = g*sin(alpha)/2\"]", "pass"),
    ("quantity: eom\n    book: [\"xddot = g*sin(alpha)\"]", "fail"),
    ("quantity: constraint_force\n    constraint: contact\n    coordinate: x\n"
     "    book: \"-m*g*sin(alpha)/2\"", "pass"),
    ("quantity: constraint_force\n    constraint: contact\n    coordinate: x\n"
     "    book: \"-1.01*m*g*sin(alpha)/2\"", "fail"),
    ("quantity: conserved\n    book: \"m*xdot**2/2 + m*R**2*phidot**2/2 - m*g*x*sin(alpha)\"",
     "pass"),
    ("quantity: mode_count\n    book: {configuration: 2, velocity: 1}", "pass"),
])
def test_hoop_down_an_incline(tmp_path, part, status):
    out = check(tmp_path, "9509", HOOP, key(f"  - part: a\n    cite: hoop\n    {part}\n"))["a"]
    assert out.status == status, out.detail


# ---- the cross-check sees a wrong contact -------------------------------------------------
def test_newton_on_the_manifold_rejects_a_wrong_contact(tmp_path, monkeypatch):
    """The rolling rows built with the wrong lever arm (the contact point at the centre)
    disagree with the cross-check's own contact velocity and force balance."""
    import mechbook.model.rolling as rolling

    right = rolling.relative_velocity

    def wrong(sys, spec, sub):
        v, n = right(sys, spec, sub)
        body = spec["body"]
        return sys.dt(sys.positions[body]), n  # no ω × (P − r_G): slipping allowed

    an = _analysis(tmp_path, "9510", COIN.replace("SHAPE", "disk"))
    assert newton_crosscheck(an).status == "pass"
    monkeypatch.setattr(rolling, "relative_velocity", wrong)
    bad = _analysis(tmp_path / "bad", "9510", COIN.replace("SHAPE", "disk"))
    x = newton_crosscheck(bad)
    assert x.status == "fail", x.detail


# ---- bad input: file, line, what is wrong -------------------------------------------------
@pytest.mark.parametrize("edit, message", [
    (("velocity_constraints:\n  - {name: blade, expr: \"-xdot*sin(theta) + ydot*cos(theta)\"}",
      "velocity_constraints:\n  - {name: blade, expr: \"xdot**2 - ydot\"}"),
     "not linear in the velocities"),
    (("velocity_constraints:\n  - {name: blade, expr: \"-xdot*sin(theta) + ydot*cos(theta)\"}",
      "velocity_constraints:\n  - {name: blade, expr: \"x - y\"}"),
     "holds no velocity"),
    (("velocity_constraints:\n  - {name: blade, expr: \"-xdot*sin(theta) + ydot*cos(theta)\"}",
      "velocity_constraints:\n  - {name: blade, expr: \"xddot\"}"),
     "holds an acceleration"),
    (("velocity_constraints:\n  - {name: blade, expr: \"-xdot*sin(theta) + ydot*cos(theta)\"}",
      "rolling:\n  - {name: blade, body: sled}"),
     "declares no surface to roll on"),
])
def test_bad_velocity_constraints(tmp_path, edit, message):
    old, new = edit
    problem = SLEIGH.replace(old, new)
    ppath, _ = write_tree(tmp_path, "9511", problem, key(""))
    with pytest.raises(MechbookError) as exc:
        Analysis(load_problem(ppath)).system()
    assert message in str(exc.value)
    assert "9511.yaml:" in str(exc.value)  # file and line


def test_initial_state_off_the_manifold(tmp_path):
    problem = SLEIGH + "initial: {theta: 0.3, xdot: 1.0, ydot: 1.0, thetadot: 0}\n"
    ppath, _ = write_tree(tmp_path, "9512", problem, key(""))
    an = Analysis(load_problem(ppath))
    with pytest.raises(MechbookError) as exc:
        simulate(an, None, t_span=(0.0, 1.0))
    assert "not on the constraint manifold" in str(exc.value)
    assert "blade" in str(exc.value) and "9512.yaml:" in str(exc.value)


def test_rolling_contact_that_leaves_the_surface_is_refused(tmp_path):
    """The coin's centre held at height R whatever its tilt: tilted, its rim's lowest point
    leaves the plane, so rolling there is not a velocity constraint alone."""
    problem = COIN.replace("SHAPE", "disk").replace("[x, y, R*sin(theta)]", "[x, y, R]")
    ppath, _ = write_tree(tmp_path, "9513", problem, key(""))
    with pytest.raises(MechbookError) as exc:
        build_systems(load_problem(ppath))
    assert "leaves the surface" in str(exc.value) and "9513.yaml:" in str(exc.value)


def test_dependent_constraints_are_refused(tmp_path):
    from constrained_systems import CIRCLE

    problem = CIRCLE.replace('  - {name: rod, expr: "x**2 + y**2 - l**2"}\n',
                             '  - {name: rod, expr: "x**2 + y**2 - l**2"}\n'
                             '  - {name: again, expr: "2*x**2 + 2*y**2 - 2*l**2"}\n')
    ppath, _ = write_tree(tmp_path, "9514", problem, key(""))
    with pytest.raises(MechbookError) as exc:
        build_systems(load_problem(ppath))
    assert "constraints are dependent" in str(exc.value) and "9514.yaml:" in str(exc.value)


def test_dependent_velocity_constraints_are_refused(tmp_path):
    problem = SLEIGH.replace(
        '  - {name: blade, expr: "-xdot*sin(theta) + ydot*cos(theta)"}\n',
        '  - {name: blade, expr: "-xdot*sin(theta) + ydot*cos(theta)"}\n'
        '  - {name: twice, expr: "-2*xdot*sin(theta) + 2*ydot*cos(theta)"}\n')
    ppath, _ = write_tree(tmp_path, "9515", problem, key(""))
    with pytest.raises(MechbookError) as exc:
        build_systems(load_problem(ppath))
    assert "velocity constraints are dependent" in str(exc.value)


@pytest.mark.parametrize("book, status", [
    # Newton along the slope and about the centre, with the friction λ along +x
    ('["m*xddot = m*g*sin(alpha) + lambda_contact", '
     '"m*R**2*phiddot = -R*lambda_contact"]', "pass"),
    ('["m*xddot = m*g*sin(alpha) - lambda_contact"]', "fail"),
])
def test_hoop_equations_with_the_multiplier(tmp_path, book, status):
    out = check(tmp_path, "9516", HOOP, key(
        f"  - part: a\n    cite: hoop\n    quantity: eom\n    book: {book}\n"))["a"]
    assert out.status == status, out.detail


def test_api_linearization_of_a_rolling_coin(tmp_path):
    """The Python API's Linearizer-like view: states, A, freedoms, exponents."""
    import mechbook

    write_tree(tmp_path, "9517", COIN.replace("SHAPE", "disk"), key(""))
    coin = mechbook.load("lim-9517", tmp_path, simplify=False)
    lin = coin.linearize(about={"phi": 0, "theta": "pi/2", "psi": 0}, steady={"psi": "Omega"})
    assert lin.M is None and lin.A.shape == (8, 8) and lin.B.shape == (8, 0)
    assert (lin.freedoms.configuration, lin.freedoms.velocity) == (5, 3)
    values = {"m": 0.4, "R": 0.3, "g": 9.81, "Omega": 5.0}
    wobble = np.sqrt((12 * 25.0 - 4 * 9.81 / 0.3) / 5)
    assert abs(lin.frequencies(values)[0] - wobble) < 1e-10 * wobble
    assert lin.stability(values) == "stable"
    assert lin.stability({**values, "Omega": 0.9 * np.sqrt(9.81 / 0.9)}) == "unstable"
    lam = lin.exponents(values)
    assert np.sort(np.abs(lam.imag))[-1] == pytest.approx(wobble, rel=1e-10)


def test_api_linearization_second_order(tmp_path):
    from constrained_systems import CIRCLE

    import mechbook

    write_tree(tmp_path, "9518", CIRCLE, key(""))
    p = mechbook.load("lim-9518", tmp_path, simplify=False)
    lin = p.linearize(about={"x": 0, "y": "-l"})
    g, l = (sp.Symbol("g", positive=True), sp.Symbol("l", positive=True))  # noqa: E741
    assert lin.A == sp.Matrix([[0, 1], [-g / l, 0]])
    assert lin.M is not None and lin.freedoms.velocity == 1


def test_simulated_wobble_confirms_the_first_order_linearization(tmp_path, monkeypatch):
    """The modes cross-check integrates the rolling coin itself, displaced along the
    wobble, and reads the frequency off the motion; a state matrix 1 % off fails it."""
    from mechbook.crosscheck.problem import modes_check
    from mechbook.engine.state_space import StateSpaceSystem

    an = _analysis(tmp_path, "9519", COIN.replace("SHAPE", "disk"))
    x, y, phi, theta, psi = an.system().q
    names = {str(k): k for k in an.problem.values()}
    lin = an.steady_linear(None, {psi: names["Omega"]}, {phi: 0, theta: sp.pi / 2, psi: 0},
                           reduce=False)
    values = dict(an.problem.values())
    good = modes_check(an, lin, values, "modes", {})
    assert good.status == "pass" and good.error < 1e-6, good.detail
    right = StateSpaceSystem.numeric_state_matrix
    monkeypatch.setattr(StateSpaceSystem, "numeric_state_matrix",
                        lambda self, v, core=False: 1.01 * right(self, v, core))
    bad = modes_check(an, lin, values, "modes", {})
    assert bad.status == "fail", bad.detail


def test_stability_map_of_the_rolling_disc(tmp_path):
    """`mechbook sweep` of a first-order linearization: the stacked state matrices' verdict
    against Ω² > g/(3r) over a grid (points within 1e-9 of the boundary left out)."""
    from mechbook.engine.linear_grid import STABLE, UNSTABLE
    from mechbook.engine.state_sweep import StateSweep

    an = _analysis(tmp_path, "9520", SYMPY_DISC)
    q1, q2, q3, q4, q5 = an.system().q
    names = {str(k): k for k in an.problem.values()}
    lin = an.steady_linear(None, {q3: names["Omega"]}, {q1: names["phi0"], q2: 0, q3: 0},
                           reduce=False)
    symbols = list(an.problem.values())
    sweep = StateSweep(lin, symbols)
    rng = np.random.default_rng(3)
    X = np.array([[{"m": 1.0, "r": r, "g": 9.81, "Omega": w, "phi0": 0.3}[str(s)]
                   for s in symbols] for w, r in rng.uniform([0.3, 0.1], [5.0, 3.0], (400, 2))])
    block = sweep.evaluate(X)
    w, r = X[:, symbols.index(names["Omega"])], X[:, symbols.index(names["r"])]
    margin = w**2 - 9.81 / (3 * r)
    clear = np.abs(margin) > 1e-9 * w**2
    want = np.where(margin > 0, STABLE, UNSTABLE)
    assert np.all(block.stability[clear] == want[clear])
    stable = clear & (margin > 0)
    wobble = np.sqrt(np.maximum(12 * w**2 - 4 * 9.81 / r, 0) / 5)
    assert np.allclose(block.frequencies[stable, 0], wobble[stable], rtol=1e-10)


def test_sympy_rolling_disc_by_lagrange(tmp_path):
    """sympy's test_linearize_rolling_disc_lagrange: linearized about upright rolling (q1d =
    q2d = 0, q3d free), its asserted A in the states (q1, q2, q3, q1', q2', q3')."""
    from constrained_systems import SYMPY_LAGRANGE_DISC

    import mechbook

    write_tree(tmp_path, "9521", SYMPY_LAGRANGE_DISC, key(""))
    p = mechbook.load("lim-9521", tmp_path, simplify=False)
    lin = p.linearize(about={"q1": 0, "q2": 0, "q3": 0}, steady={"q3": "Omega"}, reduce=False)
    g, r, w = (sp.Symbol(s, positive=True) for s in ("g", "r", "Omega"))
    sol = sp.Matrix([[0, 0, 0, 1, 0, 0],
                     [0, 0, 0, 0, 1, 0],
                     [0, 0, 0, 0, 0, 1],
                     [0, 0, 0, 0, -6 * w, 0],
                     [0, -4 * g / (5 * r), 0, 6 * w / 5, 0, 0],
                     [0, 0, 0, 0, 0, 0]])
    assert (lin.A - sol).applyfunc(sp.simplify) == sp.zeros(6, 6)


@pytest.mark.parametrize("book, status", [
    ('["sqrt(5*g/(7*(Rb - r)))", "sqrt(5*g/(7*(Rb - r)))"]', "pass"),
    ('["sqrt(g/(Rb - r))", "sqrt(g/(Rb - r))"]', "fail"),  # sliding, not rolling
    ('["sqrt(5*g/(7*(Rb - r)))", "1.01*sqrt(5*g/(7*(Rb - r)))"]', "fail"),
])
def test_ball_in_a_bowl(tmp_path, book, status):
    from constrained_systems import BOWL

    out = check(tmp_path, "9522", BOWL, key(
        "  - part: a\n    cite: bottom\n    quantity: frequencies\n"
        f"    about: {{x: 0, y: 0, a: 0, b: 0, c: 0}}\n    partial: true\n    book: {book}\n"
        "  - part: b\n    cite: freedoms\n    quantity: mode_count\n"
        "    book: {configuration: 5, velocity: 3}\n"))
    assert out["a"].status == status, out["a"].detail
    assert out["b"].status == "pass", out["b"].detail
