"""Attitude chains, rate names, torques, attracting point masses and averaging, each on a
small system solved by hand, and each refusing wrong input."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.errors import SpecError, UnsupportedError
from mechbook.model.attitude import body_rates, rotation_matrix
from mechbook.model.problem import load_problem

HEADER = "id: symon-text-test-{name}\nsource: test\ntitle: test system\n"


def load(tmp_path, name: str, body: str):
    """The problem and its analysis, the system built (so a bad declaration raises)."""
    path = tmp_path / f"text-test-{name}.yaml"
    path.write_text(HEADER.format(name=name) + body)
    problem = load_problem(path)
    analysis = Analysis(problem)
    analysis.system()
    return problem, analysis


def _dt(qs, qds):
    def dt(e):
        return sum((sp.diff(e, q) * v for q, v in zip(qs, qds, strict=True)), sp.S.Zero)
    return dt


def test_zxz_chain_gives_symons_body_rates():
    """Eq. (11-44): omega1 = phidot sin(theta) sin(psi) + thetadot cos(psi), ..."""
    phi, th, ps = sp.symbols("phi theta psi")
    dph, dth, dps = sp.symbols("phidot thetadot psidot")
    w = body_rates([("z", phi), ("x", th), ("z", ps)], _dt([phi, th, ps], [dph, dth, dps]))
    symon = [dph * sp.sin(th) * sp.sin(ps) + dth * sp.cos(ps),
             dph * sp.sin(th) * sp.cos(ps) - dth * sp.sin(ps),
             dps + dph * sp.cos(th)]
    assert all(sp.expand(a - b) == 0 for a, b in zip(w, symon, strict=True))


@pytest.mark.parametrize("axes", ["xyz", "zxy", "zyz", "yxz"])
def test_chain_rates_equal_vee_of_RT_Rdot(axes):
    """Sum of rotation rates (the engine) against vee(R^T dR/dt) at a random state."""
    qs = sp.symbols("q1 q2 q3")
    qds = sp.symbols("v1 v2 v3")
    chain = list(zip(axes, qs, strict=True))
    dt = _dt(qs, qds)
    w = body_rates(chain, dt)
    R = rotation_matrix(chain)
    W = R.T * R.applyfunc(dt)
    vee = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])
    pt = dict(zip(qs + qds, np.random.default_rng(3).uniform(-1, 1, 6), strict=True))
    assert np.allclose(np.array((w - vee).subs(pt), float), 0, atol=1e-12)
    RR = np.array(R.subs(pt), float)
    assert np.allclose(RR.T @ RR, np.eye(3)) and abs(np.linalg.det(RR) - 1) < 1e-12


TOP = """\
parameters:
  I1: {value: 1.0}
  I3: {value: 1.6}
  N3: {value: 0.4}
coordinates:
  theta: {}
  phi: {}
  psi: {}
rigid_bodies:
  b:
    mass: 1
    position: [0, 0, 0]
    inertia: [[I1, 0, 0], [0, I1, 0], [0, 0, I3]]
    euler_angles: [phi, theta, psi]
    rates: [w1, w2, w3]
torques:
  - {body: b, axes: AXES, components: COMPONENTS}
"""


def test_body_torque_generalized_forces(tmp_path):
    """An axial body torque N3: Q_theta = 0, Q_phi = N3 cos(theta), Q_psi = N3."""
    problem, analysis = load(tmp_path, "bt", TOP.replace("AXES", "body")
                             .replace("COMPONENTS", "[0, 0, N3]"))
    sys = analysis.system()
    th = sys.q[0]
    N3 = problem.parameters["N3"].symbol
    assert [sp.simplify(f) for f in sys.forces] == [0, N3 * sp.cos(th), N3]
    assert sp.simplify(sys.names["w3"] - (sys.qd[2] + sys.qd[1] * sp.cos(th))) == 0
    assert sys.names["w3dot"].has(sys.qdd[2])


def test_space_torque_generalized_forces(tmp_path):
    """A torque about space z: it does work N*(phidot + psidot cos(theta))."""
    problem, analysis = load(tmp_path, "st", TOP.replace("AXES", "space")
                             .replace("COMPONENTS", "[0, 0, N3]"))
    sys = analysis.system()
    th = sys.q[0]
    N3 = problem.parameters["N3"].symbol
    assert [sp.simplify(f) for f in sys.forces] == [0, N3, N3 * sp.cos(th)]


def test_torque_on_unknown_body_and_bad_axis_are_refused(tmp_path):
    with pytest.raises(SpecError, match="no 3-D rigid body 'c'"):
        load(tmp_path, "bad1", TOP.replace("AXES", "body").replace("COMPONENTS", "[0, 0, N3]")
             .replace("body: b,", "body: c,"))
    with pytest.raises(SpecError):
        load(tmp_path, "bad2", TOP.replace("AXES", "body").replace("COMPONENTS", "[0, 0, N3]")
             .replace("euler_angles: [phi, theta, psi]", "rotation: [[w, phi], [x, theta]]"))
    with pytest.raises(SpecError, match="already taken"):
        load(tmp_path, "bad3", TOP.replace("AXES", "body").replace("COMPONENTS", "[0, 0, N3]")
             .replace("rates: [w1, w2, w3]", "rates: [w1, theta, w3]"))


RING = """\
parameters:
  m: {value: 0.3}
  a: {value: 0.4}
  Mp: {value: 5.0}
  G: {value: 1.0}
  r: {value: 2.0}
  alpha: {value: 0.7}
coordinates:
  theta: {}
  phi: {}
  psi: {}
rigid_bodies:
  ring:
    mass: m
    position: [r*cos(alpha), r*sin(alpha), 0]
    inertia: {shape: ring, radius: a}
    euler_angles: [phi, theta, psi]
attractors:
  star: {mass: Mp}
"""


def test_attractor_quadrupole_against_the_ring_integrated(tmp_path):
    """MacCullagh's term for a ring against the potential of 4000 point masses on it: they
    differ by the next order, (a/r)**4 relative to the monopole."""
    problem, analysis = load(tmp_path, "ring", RING)
    sys = analysis.system()
    th, ph, ps = sys.q
    vals = {**problem.values(), th: 0.8, ph: 0.3, ps: 0.0}
    engine = float(sp.N(sys.potential.subs(vals)))
    R = np.array(rotation_matrix([("z", 0.3), ("x", 0.8), ("z", 0.0)]), float)
    s = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    ring = 0.4 * np.stack([np.cos(s), np.sin(s), np.zeros_like(s)])
    centre = 2.0 * np.array([np.cos(0.7), np.sin(0.7), 0.0])
    points = centre[:, None] + R @ ring
    exact = -5.0 * 0.3 * np.mean(1 / np.linalg.norm(points, axis=0))
    monopole = -5.0 * 0.3 / 2.0
    assert abs(engine - exact) < 2 * abs(monopole) * (0.4 / 2.0) ** 4
    assert abs(monopole - exact) > 10 * abs(engine - exact)  # the quadrupole term matters


def test_average_over_an_orbit(tmp_path):
    """<1 - 3 sin(theta)**2 sin(phi - alpha)**2> over alpha = 1 - 3 sin(theta)**2 / 2."""
    problem, analysis = load(tmp_path, "avg", RING + "average: {alpha: [0, 2*pi]}\n")
    sys = analysis.system()
    th = sys.q[0]
    p = problem.parameters
    G, Mp, m, a, r = (p[k].symbol for k in ("G", "Mp", "m", "a", "r"))
    expected = -G * Mp * m / r - G * Mp * m * a**2 * (1 - sp.Rational(3, 2) * sp.sin(th)**2) \
        / (4 * r**3)
    assert sp.simplify(sys.potential - expected) == 0
    assert not sys.lagrangian.has(p["alpha"].symbol)
    with pytest.raises(SpecError, match="declared parameter"):
        load(tmp_path, "avg2", RING + "average: {beta: [0, 2*pi]}\n")


def test_steady_motion_at_a_chart_singularity_says_so(tmp_path):
    """The sleeping top in z-x-z Euler angles: the cyclic rates are not determined there."""
    problem, analysis = load(tmp_path, "sing", TOP.replace("AXES", "body")
                             .replace("COMPONENTS", "[0, 0, 0]"))
    sys = analysis.system()
    th, ph, ps = sys.q
    with pytest.raises(UnsupportedError, match="singular point of the coordinates"):
        analysis.steady_linear(None, {ph: 0, ps: 3}, {th: 0})


def test_the_mean_of_a_trigonometric_polynomial_by_symengine_is_sympys():
    """The Fourier constant term by SymEngine (loads._laurent_constant) is the closed-form
    mean and, term for term, the expression SymPy's exponential path gives (what a
    problem's averaged Lagrangian was before); a wrong constant term would fail both."""
    from mechbook.model import loads

    x, a, b, th, ph = sp.symbols("x a b theta phi", real=True)
    means = {  # each mean over a period worked out by hand
        sp.cos(x) ** 2: sp.Rational(1, 2),
        sp.sin(x) ** 2 * sp.cos(th): sp.cos(th) / 2,
        (a * sp.cos(x) + b * sp.sin(x + th)) ** 2: (a**2 + b**2) / 2 + a * b * sp.sin(th),
        sp.sin(3 * x) * sp.sin(3 * x - 1): sp.cos(1) / 2,
        sp.cos(x) ** 4 * sp.sin(th) + sp.sin(2 * x) * sp.cos(x) ** 2: 3 * sp.sin(th) / 8,
        sp.cos(x - th) * sp.cos(x) * a: a * sp.cos(th) / 2,
        sp.cos(2 * x + ph) * sp.cos(x) ** 2: sp.cos(ph) / 4,
        (sp.sin(th) ** 2 + sp.cos(th) ** 2) * sp.sin(x) ** 2: sp.Rational(1, 2),
    }
    for expr, mean in means.items():
        fast = loads._laurent_constant(expr, x)
        assert sp.simplify(fast - mean) == 0, expr
        assert fast == _sympys_mean(loads, expr, x), expr
    # a function other than sin and cos is left to SymPy's path
    assert loads._laurent_constant(sp.sin(x) ** 2 * sp.tan(th), x) is None


def _sympys_mean(loads, expr, x):
    saved = loads._laurent_constant
    loads._laurent_constant = lambda *args: None
    try:
        return loads._fourier_constant(expr, x)
    finally:
        loads._laurent_constant = saved
