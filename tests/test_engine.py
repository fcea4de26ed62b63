"""The Lagrange engine against results derived by hand.

Every system is written as a small problem file in tmp_path and loaded the normal way.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.errors import NotEquilibriumError
from mechbook.model.problem import load_problem


def analysis(tmp_path: Path, body: str, num: str = "2001", title: str = "a test system",
             simplify: bool = True) -> Analysis:
    text = f"id: lim-{num}\nsource: hand-derived test\ntitle: {title}\n" + textwrap.dedent(body)
    path = tmp_path / f"{num}.yaml"
    path.write_text(text, encoding="utf-8")
    return Analysis(load_problem(path), simplify=simplify)


def zero(expr) -> bool:
    if isinstance(expr, sp.MatrixBase):
        return all(zero(e) for e in expr)
    return sp.simplify(expr) == 0


def syms(a: Analysis, *names: str):
    s = a.system()
    out = [s.names[n] for n in names]
    return out[0] if len(out) == 1 else out


# ---- (a) simple pendulum --------------------------------------------------------------------
PENDULUM = """\
parameters:
  m: {value: 1.3}
  l: {value: 0.7}
  g: {}
coordinates:
  theta: {}
particles:
  bob:
    mass: m
    position: [l*sin(theta), -l*cos(theta)]
gravity: {}
"""


@pytest.fixture
def pendulum(tmp_path):
    return analysis(tmp_path, PENDULUM)


def test_pendulum_lagrangian(pendulum):
    m, ell, g, th, thd = syms(pendulum, "m", "l", "g", "theta", "thetadot")
    sys = pendulum.system()
    assert zero(sys.kinetic - m * ell**2 * thd**2 / 2)
    assert zero(sys.potential + m * g * ell * sp.cos(th))
    assert zero(sys.lagrangian - (m * ell**2 * thd**2 / 2 + m * g * ell * sp.cos(th)))


def test_pendulum_acceleration(pendulum):
    ell, g, th = syms(pendulum, "l", "g", "theta")
    dyn = pendulum.dynamics()
    assert zero(dyn.accelerations[0] + g * sp.sin(th) / ell)
    assert zero(dyn.mass_matrix[0, 0] - syms(pendulum, "m") * ell**2)


def test_pendulum_equilibria(pendulum):
    th = syms(pendulum, "theta")
    points = pendulum.equilibria().symbolic
    values = sorted(float(p[th]) % (2 * np.pi) for p in points)
    assert values == pytest.approx([0.0, np.pi])


def test_pendulum_small_oscillations(pendulum):
    ell, g, th = syms(pendulum, "l", "g", "theta")
    values = pendulum.problem.values()
    low = pendulum.linear(None, {th: sp.S.Zero})
    assert len(low.frequencies) == 1
    assert zero(low.frequencies[0] - sp.sqrt(g / ell))
    assert low.numeric_frequencies(values) == pytest.approx([np.sqrt(9.81 / 0.7)])
    assert low.numeric_stability(values) == "stable"
    assert low.stability_condition == sp.true
    top = pendulum.linear(None, {th: sp.pi})
    assert top.numeric_stability(values) == "unstable"
    assert np.isnan(top.numeric_frequencies(values)).all()
    assert top.stability_condition == sp.false
    assert zero(top.K[0, 0] / top.M[0, 0] + g / ell)


def test_pendulum_default_point_is_the_stable_one(pendulum):
    th = syms(pendulum, "theta")
    assert pendulum.default_point() == {th: 0}


def test_pendulum_energy(pendulum):
    m, ell, g, th, thd = syms(pendulum, "m", "l", "g", "theta", "thetadot")
    dyn = pendulum.dynamics()
    h = dyn.energy_function
    assert zero(h - (m * ell**2 * thd**2 / 2 - m * g * ell * sp.cos(th)))
    assert dyn.energy_conserved
    # and it really is conserved along the motion
    assert zero(dyn.on_shell(pendulum.system().dt(h)))


def test_pendulum_hamiltonian(pendulum):
    m, ell, g, th = syms(pendulum, "m", "l", "g", "theta")
    dyn = pendulum.dynamics()
    p = dyn.p[0]
    assert p.name == "p_theta"
    assert zero(dyn.hamiltonian - (p**2 / (2 * m * ell**2) - m * g * ell * sp.cos(th)))
    qdot, pdot = dyn.hamilton_equations
    assert zero(qdot[0] - p / (m * ell**2))
    assert zero(pdot[0] + m * g * ell * sp.sin(th))
    assert zero(dyn.momenta[0] - m * ell**2 * syms(pendulum, "thetadot"))
    assert dyn.cyclic == {}


# ---- (b) double pendulum --------------------------------------------------------------------
DOUBLE = """\
parameters:
  m: {value: 1.3}
  l: {value: 0.7}
  g: {}
coordinates:
  a: {}
  b: {}
particles:
  p1:
    mass: m
    position: [l*sin(a), -l*cos(a)]
  p2:
    mass: m
    position: [l*sin(a) + l*sin(b), -l*cos(a) - l*cos(b)]
gravity: {}
"""


def test_double_pendulum_frequencies(tmp_path):
    an = analysis(tmp_path, DOUBLE, "2002")
    ell, g, a, b, m = syms(an, "l", "g", "a", "b", "m")
    lin = an.linear(None, {a: sp.S.Zero, b: sp.S.Zero})
    assert zero(lin.M - sp.Matrix([[2, 1], [1, 1]]) * m * ell**2)
    assert zero(lin.K - sp.Matrix([[2, 0], [0, 1]]) * m * g * ell)
    expected = [(2 - sp.sqrt(2)) * g / ell, (2 + sp.sqrt(2)) * g / ell]
    got = sorted(lin.frequencies, key=lambda w: float(w.subs({g: 9.81, ell: 0.7})))
    assert len(got) == 2
    for w, w2 in zip(got, expected, strict=True):
        assert zero(w**2 - w2)
    values = an.problem.values()
    num = np.sort(lin.numeric_frequencies(values))
    assert num == pytest.approx(np.sqrt([(2 - np.sqrt(2)) * 9.81 / 0.7,
                                         (2 + np.sqrt(2)) * 9.81 / 0.7]), rel=1e-10)
    other = {sym: v * 1.7 for sym, v in values.items()}
    num = np.sort(lin.numeric_frequencies(other))
    assert num == pytest.approx(np.sqrt([(2 - np.sqrt(2)), (2 + np.sqrt(2))]
                                        ) * np.sqrt(9.81 / 0.7), rel=1e-10)  # g/ell unchanged


def test_double_pendulum_modes(tmp_path):
    an = analysis(tmp_path, DOUBLE, "2002")
    a, b = syms(an, "a", "b")
    lin = an.linear(None, {a: sp.S.Zero, b: sp.S.Zero})
    w2, modes = lin.numeric_modes(an.problem.values())
    assert w2 == pytest.approx(np.array([2 - np.sqrt(2), 2 + np.sqrt(2)]) * 9.81 / 0.7)
    # slow mode: b/a = sqrt(2); fast mode: b/a = -sqrt(2)
    assert modes[1, 0] / modes[0, 0] == pytest.approx(np.sqrt(2))
    assert modes[1, 1] / modes[0, 1] == pytest.approx(-np.sqrt(2))


def test_double_pendulum_equilibria(tmp_path):
    an = analysis(tmp_path, DOUBLE, "2002")
    a, b = syms(an, "a", "b")
    points = {(float(p[a]) % (2 * np.pi), float(p[b]) % (2 * np.pi))
              for p in an.equilibria().symbolic}
    expected = {(0.0, 0.0), (0.0, np.pi), (np.pi, 0.0), (np.pi, np.pi)}
    assert {tuple(np.round(p, 9)) for p in points} == {tuple(np.round(p, 9)) for p in expected}
    values = an.problem.values()
    stable = [p for p in an.equilibria().symbolic
              if an.linear(None, p).numeric_stability(values) == "stable"]
    assert stable == [{a: 0, b: 0}]


# ---- (c) bead on a rotating hoop ------------------------------------------------------------
HOOP = """\
parameters:
  m: {value: 0.1}
  b: {value: 0.5}
  omega: {value: 6.0}
  g: {}
coordinates:
  theta: {doc: from the upward vertical}
particles:
  bead:
    mass: m
    position: [b*sin(theta)*cos(omega*t), b*sin(theta)*sin(omega*t), b*cos(theta)]
gravity: {}
"""


@pytest.fixture
def hoop(tmp_path):
    return analysis(tmp_path, HOOP, "2031")


def test_hoop_equation_of_motion(hoop):
    b, g, w, th = syms(hoop, "b", "g", "omega", "theta")
    acc = hoop.dynamics().accelerations[0]
    assert zero(acc - (w**2 * sp.sin(th) * sp.cos(th) + g * sp.sin(th) / b))


def test_hoop_equilibria(hoop):
    b, g, w, th = syms(hoop, "b", "g", "omega", "theta")
    values = hoop.problem.values()
    points = hoop.equilibria().symbolic
    cosines = sorted(float(sp.cos(p[th]).subs(values)) for p in points)
    off = -9.81 / (0.5 * 36)
    assert cosines == pytest.approx(sorted([1.0, -1.0, off, off]))
    # the off-axis points satisfy cos(theta) = -g/(b omega^2) symbolically
    offaxis = [p for p in points if not zero(sp.sin(p[th]))]
    assert len(offaxis) == 2
    for p in offaxis:
        assert zero(sp.cos(p[th]) + g / (b * w**2))


def test_hoop_critical_spin(hoop):
    b, g, w, th, m = syms(hoop, "b", "g", "omega", "theta", "m")
    bottom = hoop.linear(None, {th: sp.pi})
    assert zero(bottom.K[0, 0] / bottom.M[0, 0] - (g / b - w**2))
    cond = bottom.stability_condition
    base = {m: 0.1, b: 0.5, g: 9.81}
    critical = np.sqrt(9.81 / 0.5)
    for factor in (0.3, 0.9, 0.99):
        pt = {**base, w: critical * factor}
        assert bool(cond.subs(pt)) is True
        assert bottom.numeric_stability(pt) == "stable"
    for factor in (1.01, 1.1, 3.0):
        pt = {**base, w: critical * factor}
        assert bool(cond.subs(pt)) is False
        assert bottom.numeric_stability(pt) == "unstable"
    top = hoop.linear(None, {th: sp.S.Zero})
    assert top.numeric_stability({**base, w: 0.5 * critical}) == "unstable"
    assert top.numeric_stability({**base, w: 3 * critical}) == "unstable"


def test_hoop_off_axis_frequency(hoop):
    b, g, w, th = syms(hoop, "b", "g", "omega", "theta")
    point = {th: sp.acos(-g / (b * w**2))}
    lin = hoop.linear(None, point)
    expected = w**2 * (1 - g**2 / (b**2 * w**4))  # = omega^2 sin^2(theta0)
    assert zero(lin.frequencies[0] ** 2 - expected)
    values = hoop.problem.values()
    assert lin.numeric_frequencies(values) == pytest.approx(
        [6.0 * np.sqrt(1 - (9.81 / (0.5 * 36)) ** 2)], rel=1e-10)
    assert lin.numeric_stability(values) == "stable"


def test_hoop_jacobi_integral(hoop):
    m, b, g, w, th, thd = syms(hoop, "m", "b", "g", "omega", "theta", "thetadot")
    dyn = hoop.dynamics()
    h = m * b**2 * thd**2 / 2 - m * b**2 * w**2 * sp.sin(th) ** 2 / 2 + m * g * b * sp.cos(th)
    assert zero(dyn.energy_function - h)
    assert dyn.energy_conserved
    sys = hoop.system()
    assert not zero(h - (sys.kinetic + sys.potential))  # h is not the energy T + V


# ---- (d) free particle in polar coordinates -------------------------------------------------
POLAR = """\
parameters:
  m: {value: 1.3}
coordinates:
  r: {}
  phi: {}
particles:
  p:
    mass: m
    position: [r*cos(phi), r*sin(phi)]
"""


def test_polar_equations(tmp_path):
    an = analysis(tmp_path, POLAR, "2003")
    m, r, phi, rd, phid = syms(an, "m", "r", "phi", "rdot", "phidot")
    dyn = an.dynamics()
    acc = dict(zip(an.system().qdd, dyn.accelerations, strict=True))
    rdd, phidd = an.system().qdd
    assert zero(acc[rdd] - r * phid**2)
    assert zero(acc[phidd] + 2 * rd * phid / r)
    assert zero(dyn.momenta[1] - m * r**2 * phid)
    assert zero(dyn.momenta[0] - m * rd)
    # the angular momentum is conserved along the motion
    assert zero(dyn.on_shell(an.system().dt(dyn.momenta[1])))
    assert not zero(dyn.on_shell(an.system().dt(dyn.momenta[0])))


def test_polar_phi_is_cyclic(tmp_path):
    """phi is cyclic although L built from the particle position holds phi until simplified."""
    an = analysis(tmp_path, POLAR, "2003")
    m, r, phi, phid = syms(an, "m", "r", "phi", "phidot")
    cyclic = an.dynamics().cyclic
    assert set(cyclic) == {phi}
    assert zero(cyclic[phi] - m * r**2 * phid)


def test_cyclic_found_when_lagrangian_is_explicit(tmp_path):
    body = """\
    parameters:
      m: {value: 1.3}
    coordinates:
      r: {}
      phi: {}
    kinetic: m*(rdot**2 + r**2*phidot**2)/2
    """
    an = analysis(tmp_path, body, "2003")
    m, r, phi, phid = syms(an, "m", "r", "phi", "phidot")
    cyclic = an.dynamics().cyclic
    assert set(cyclic) == {phi}
    assert zero(cyclic[phi] - m * r**2 * phid)


# ---- (e) Lagrange multiplier: pendulum in Cartesian coordinates -----------------------------
CARTESIAN = """\
parameters:
  m: {value: 1.3}
  l: {value: 0.7}
  g: {}
coordinates:
  x: {}
  y: {}
particles:
  p:
    mass: m
    position: [x, y]
gravity: {}
constraints:
  - name: rod
    expr: x**2 + y**2 - l**2
"""


def test_multiplier_gives_tension_at_rest_at_bottom(tmp_path):
    an = analysis(tmp_path, CARTESIAN, "2004")
    m, ell, g, x, y, xd, yd = syms(an, "m", "l", "g", "x", "y", "xdot", "ydot")
    dyn = an.dynamics()
    lam = dyn.multipliers[0]
    A = dyn.constraint_jacobian
    assert zero(A - sp.Matrix([[2 * x, 2 * y]]))
    state = {x: 0, y: -ell, xd: 0, yd: 0}
    force = [sp.simplify((dyn.solved[lam] * A[0, i]).subs(state)) for i in range(2)]
    assert zero(force[0])
    assert zero(force[1] - m * g)  # the string pulls up with m g
    xdd, ydd = an.system().qdd
    assert zero(dyn.solved[xdd].subs(state))
    assert zero(dyn.solved[ydd].subs(state))


def test_multiplier_gives_tension_in_motion(tmp_path):
    """At angle th from the downward vertical with speed v the string pulls toward the
    pivot with m g cos(th) + m v^2/l, and the tangential acceleration is -g sin(th)."""
    an = analysis(tmp_path, CARTESIAN, "2004")
    m, ell, g, x, y, xd, yd = syms(an, "m", "l", "g", "x", "y", "xdot", "ydot")
    th, v = sp.symbols("th v", real=True)
    dyn = an.dynamics()
    lam = dyn.multipliers[0]
    state = {x: ell * sp.sin(th), y: -ell * sp.cos(th), xd: v * sp.cos(th), yd: v * sp.sin(th)}
    force = sp.Matrix([dyn.solved[lam] * dyn.constraint_jacobian[0, i] for i in range(2)])
    force = force.subs(state)
    tension = m * g * sp.cos(th) + m * v**2 / ell
    toward_pivot = sp.Matrix([-sp.sin(th), sp.cos(th)])
    assert zero(force - tension * toward_pivot)
    xdd, ydd = an.system().qdd
    acc = sp.Matrix([dyn.solved[xdd], dyn.solved[ydd]]).subs(state)
    tangent = sp.Matrix([sp.cos(th), sp.sin(th)])
    assert zero((acc.T * tangent)[0] + g * sp.sin(th))
    assert zero((acc.T * toward_pivot)[0] - v**2 / ell)  # centripetal


def test_multiplier_constraint_residual_convention(tmp_path):
    """E_i = d/dt dL/dqdot - dL/dq - Q - lambda df/dq vanishes with the solved values."""
    an = analysis(tmp_path, CARTESIAN, "2004")
    dyn = an.dynamics()
    lam = dyn.multipliers[0]
    for i, e in enumerate(dyn.residuals):
        full = e - lam * dyn.constraint_jacobian[0, i]
        assert zero(full.subs(dyn.solved))


def test_equilibria_with_multipliers_on_the_constraint(tmp_path):
    """With a multiplier constraint the equilibria are found on the constraint (the
    multiplier an unknown too): the bob at the bottom and at the top, nowhere else."""
    an = analysis(tmp_path, CARTESIAN, "2004")
    x, y = an.system().q
    l = next(s for s in an.problem.values() if s.name == "l")  # noqa: E741
    points = an.equilibria().symbolic
    assert sorted((p[x], p[y]) for p in points) == sorted([(0, -l), (0, l)])



# ---- (f) driven support ---------------------------------------------------------------------
DRIVEN = """\
parameters:
  m: {{value: 1.3}}
  l: {{value: 0.7}}
  g: {{}}
  y0: {{value: 0.01, small: {small}}}
  omega: {{value: 2.0}}
coordinates:
  theta: {{}}
driven:
  y: y0*cos(omega*t)
particles:
  bob:
    mass: m
    position: {position}
gravity: {{}}
"""
HORIZONTAL = "[y + l*sin(theta), -l*cos(theta)]"
VERTICAL = "[l*sin(theta), y - l*cos(theta)]"


def test_driven_support_forcing(tmp_path):
    """Support moved sideways by y0 cos(omega t): m l^2 th'' + m g l th = m l y0 omega^2 cos."""
    an = analysis(tmp_path, DRIVEN.format(small="true", position=HORIZONTAL), "2005")
    m, ell, g, y0, w, th = syms(an, "m", "l", "g", "y0", "omega", "theta")
    t = an.system().t
    lin = an.linear(None, {th: sp.S.Zero})
    assert zero(lin.M[0, 0] - m * ell**2)
    assert zero(lin.K[0, 0] - m * g * ell)
    assert zero(lin.C[0, 0])
    assert zero(lin.F[0] - m * ell * y0 * w**2 * sp.cos(w * t))
    assert not an.dynamics().energy_conserved
    eq = lin.equations()[0]
    thdd = an.system().qdd[0]
    expected = m * ell**2 * thdd + m * g * ell * th - m * ell * y0 * w**2 * sp.cos(w * t)
    assert zero(eq - expected)


def test_vertically_driven_support_is_parametric(tmp_path):
    """Moving the support vertically enters as y0*theta (second order): no first-order F."""
    an = analysis(tmp_path, DRIVEN.format(small="true", position=VERTICAL), "2005")
    m, ell, g, th = syms(an, "m", "l", "g", "theta")
    lin = an.linear(None, {th: sp.S.Zero})
    assert zero(lin.F[0])
    assert zero(lin.K[0, 0] - m * g * ell)
    # the full equation does carry the support acceleration
    y0, w = syms(an, "y0", "omega")
    t = an.system().t
    acc = an.dynamics().accelerations[0]
    assert zero(acc - (-g + w**2 * y0 * sp.cos(w * t)) * sp.sin(th) / ell)


def test_driven_amplitude_not_small_is_not_an_equilibrium(tmp_path):
    an = analysis(tmp_path, DRIVEN.format(small="false", position=HORIZONTAL), "2005")
    th = syms(an, "theta")
    with pytest.raises(NotEquilibriumError, match="not an equilibrium"):
        an.linear(None, {th: sp.S.Zero})
