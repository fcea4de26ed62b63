"""The Taylor backend (heyoka) against closed forms: the pendulum's Jacobi-elliptic motion,
exp(At)·y0 for linear systems, event times against known periods, batch mode."""

from __future__ import annotations

import math
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from scipy.linalg import expm
from scipy.special import ellipj, ellipk
from systems import pendulum

from mechbook.errors import MechbookError, UnsupportedError
from mechbook.numerics.integrators import integrate
from mechbook.numerics.measure import first_event, measure, signal_functions
from mechbook.numerics.monitors import conserved_quantities, drifts
from mechbook.numerics.rhs import build_model

pytest.importorskip("heyoka")

from mechbook.numerics import taylor  # noqa: E402
from mechbook.numerics.hyexpr import Translator, solve_spd  # noqa: E402

G, LEN = 9.81, 0.7
PENDULUM = pendulum(m=1.3, l=LEN, g=G, header="id: lim-9201\nsource: test\ntitle: pendulum\n")

# two masses on springs, kinetic energy with a cross term: a full (non-diagonal) mass matrix
COUPLED = """\
id: lim-9202
source: test
title: coupled oscillators with a full mass matrix
parameters:
  m1: {value: 1.0}
  m2: {value: 2.5}
  k1: {value: 3.0}
  k2: {value: 7.0}
  c: {value: 0.4}
coordinates:
  x: {}
  y: {}
kinetic: m1*xdot**2/2 + m2*(xdot + ydot)**2/2 + c*xdot*ydot
potential: k1*x**2/2 + k2*(y - x)**2/2
"""

# the same pendulum as a particle in the plane held on the circle by a multiplier
CONSTRAINED = f"""\
id: lim-9203
source: test
title: pendulum as a constrained particle
parameters:
  m: {{value: 1.3}}
  l: {{value: {LEN}}}
  g: {{value: {G}}}
coordinates:
  x: {{}}
  y: {{}}
particles:
  bob: {{mass: m, position: [x, y]}}
gravity: {{}}
constraints:
  - {{name: rod, expr: x**2 + y**2 - l**2}}
"""


def model_of(tmp_path: Path, text: str, num: str, monitors: bool = False):
    from systems import load_analysis

    an = load_analysis(tmp_path, text, num)
    sys, dyn = an.system(None), an.dynamics(None)
    return build_model(sys, dyn, an.problem.values(),
                       conserved_quantities(sys, dyn) if monitors else None), an


def pendulum_exact(theta0: float, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """θ(t), θ̇(t) released at rest from θ0: θ = 2 asin(k sn(K − ω0 t | k²))."""
    w0 = math.sqrt(G / LEN)
    k = math.sin(theta0 / 2)
    sn, cn, _, _ = ellipj(ellipk(k * k) - w0 * t, k * k)
    return 2 * np.arcsin(k * sn), -2 * k * w0 * cn


def test_pendulum_against_the_jacobi_elliptic_solution(tmp_path):
    model, _ = model_of(tmp_path, PENDULUM, "9201")
    theta0 = 1.0
    period = 4 * math.sqrt(LEN / G) * ellipk(math.sin(theta0 / 2) ** 2)
    ts = np.linspace(0, 10 * period, 97)
    traj = integrate(model, (0, ts[-1]), [theta0], [0.0], "taylor", t_eval=ts, tol=1e-15)
    th, thd = pendulum_exact(theta0, ts)
    assert traj.success
    assert np.max(np.abs(traj.q[0] - th)) < 1e-12
    assert np.max(np.abs(traj.qd[0] - thd)) < 1e-11
    assert traj.settings["compile_s"] > 0


def test_linear_system_against_the_matrix_exponential(tmp_path):
    model, _ = model_of(tmp_path, COUPLED, "9202")
    y0 = np.array([0.3, -0.1, 0.2, 0.5])
    ts = np.linspace(0, 20, 11)
    traj = integrate(model, (0, 20), y0[:2], y0[2:], "taylor", t_eval=ts)
    # y' = A y, A from COUPLED's T and V by hand at 40 digits: M = [[m1 + m2, m2 + c],
    # [m2 + c, m2]], K = [[k1 + k2, -k2], [-k2, k2]], q̈ = -M⁻¹K q (an A rounded to
    # doubles, e.g. from model.rhs, is itself ~1e-12 off the motion by t = 20)
    with mp.workdps(40):
        # the parameters as the problem holds them: doubles (0.4 is not 2/5), taken exactly
        m1, m2, k1, k2, c = (mp.mpf(x) for x in (1.0, 2.5, 3.0, 7.0, 0.4))
        acc = -(mp.matrix([[m1 + m2, m2 + c], [m2 + c, m2]]) ** -1
                * mp.matrix([[k1 + k2, -k2], [-k2, k2]]))
        Am = mp.zeros(4, 4)
        Am[0, 2] = Am[1, 3] = 1
        for i in range(2):
            for j in range(2):
                Am[2 + i, j] = acc[i, j]
        ym = mp.matrix(y0.tolist())
        exact = np.column_stack([[float(v) for v in mp.expm(Am * t) * ym] for t in ts])
        A = np.array(Am.tolist(), dtype=float)
    assert np.max(np.abs(traj.y - exact)) < 1e-13
    assert np.max(np.abs(expm(A * 2.0) @ y0 - exact[:, 1])) < 1e-11  # scipy: float only
    assert np.allclose(A, np.column_stack([model.rhs(0.0, e) for e in np.eye(4)]),
                       rtol=1e-14, atol=1e-14)  # the model's equations are these


def test_constrained_particle_is_the_pendulum(tmp_path):
    model, _ = model_of(tmp_path, CONSTRAINED, "9203")
    theta0 = 0.8
    ts = np.linspace(0, 3, 31)
    x0 = [LEN * math.sin(theta0), -LEN * math.cos(theta0)]
    traj = integrate(model, (0, 3), x0, [0.0, 0.0], "taylor", t_eval=ts)
    th, _ = pendulum_exact(theta0, ts)
    # the multiplier form drifts off the circle at the integrator's accuracy only
    assert np.max(np.abs(np.arctan2(traj.q[0], -traj.q[1]) - th)) < 1e-9


def test_energy_of_a_long_run_is_held(tmp_path):
    model, _ = model_of(tmp_path, PENDULUM, "9201", monitors=True)
    period = 4 * math.sqrt(LEN / G) * ellipk(math.sin(0.5) ** 2)
    ts = np.arange(1001) * period
    traj = integrate(model, (0, ts[-1]), [1.0], [0.0], "taylor", t_eval=ts)
    energy = next(d for d in drifts(model, traj) if d.name == "energy_function")
    assert energy.relative < 1e-13


def test_turning_points_and_event_times_against_the_period(tmp_path):
    model, an = model_of(tmp_path, PENDULUM, "9201")
    sys = an.system(None)
    theta = sys.q[0]
    for theta0 in (0.3, 1.2, 2.5):
        period = 4 * math.sqrt(LEN / G) * ellipk(math.sin(theta0 / 2) ** 2)
        fn = signal_functions(sys, an.dynamics(None), an.problem.values(), theta)
        got = measure(model, fn, np.array([theta0]), np.array([0.0]), 1.0, method="taylor")
        assert got.period() == pytest.approx(period, rel=1e-11)
        assert got.low == pytest.approx(-theta0, abs=1e-11)
        assert got.high == pytest.approx(theta0, abs=1e-11)
        ref = measure(model, fn, np.array([theta0]), np.array([0.0]), 1.0)
        assert np.allclose(got.times, ref.times, rtol=1e-9)
        assert list(got.kinds) == list(ref.kinds)
        t, y = first_event(model, fn, np.array([theta0]), np.array([0.0]), 0.1,
                           method="taylor")
        assert t == pytest.approx(period / 4, rel=1e-12)
        assert abs(y[0]) < 1e-12


def test_batch_mode_matches_single_runs(tmp_path):
    model, _ = model_of(tmp_path, PENDULUM, "9201")
    starts = np.array([[a, 0.0] for a in np.linspace(0.1, 2.0, 7)])
    ends = taylor.propagate_batch(model, starts, 5.0)
    for s, e in zip(starts, ends, strict=True):
        th, thd = pendulum_exact(s[0], np.array([5.0]))
        assert abs(e[0] - th[0]) < 1e-12 and abs(e[1] - thd[0]) < 1e-11
    grid = np.linspace(0, 3, 5)
    samples = taylor.propagate_batch(model, starts, 3.0, grid=grid)
    th, _ = pendulum_exact(starts[3, 0], grid)
    assert samples.shape == (7, 5, 2) and np.max(np.abs(samples[3, :, 0] - th)) < 1e-12
    # the parameters are heyoka runtime parameters: one compiled integrator, other g
    names = [str(p) for p in taylor.system_of(model).params]
    pars = np.tile(taylor.system_of(model).pars, (2, 1))
    pars[1, names.index("g")] = 4 * G
    two = taylor.propagate_batch(model, np.array([[1.0, 0.0], [1.0, 0.0]]), 0.5, pars=pars)
    w0 = math.sqrt(4 * G / LEN)
    k = math.sin(0.5)
    sn = ellipj(ellipk(k * k) - w0 * 0.5, k * k)[0]
    assert two[1, 0] == pytest.approx(2 * np.arcsin(k * sn), abs=1e-12)


def test_ldlt_solve_matches_numpy():
    import heyoka as hy

    rng = np.random.default_rng(3)
    B = rng.normal(size=(4, 4))
    M = B @ B.T + 4 * np.eye(4)
    b = rng.normal(size=4)
    x = solve_spd([[hy.expression(float(v)) for v in row] for row in M],
                  [hy.expression(float(v)) for v in b], lambda e: e is None)
    dummy = hy.make_vars("z")
    fn = hy.cfunc([xi + 0.0 * dummy for xi in x], [dummy])
    got = fn(np.array([0.0]))
    assert np.allclose(got, np.linalg.solve(M, b), rtol=1e-13, atol=1e-14)


def test_translator_refuses_what_it_does_not_know():
    import heyoka as hy

    x = sp.Symbol("x")
    tr = Translator({x: hy.make_vars("x")})
    tr(sp.sin(x) ** 2 + sp.sec(x) + sp.atan2(x, 2) + sp.sqrt(x) + x ** sp.Rational(3, 2))
    with pytest.raises(UnsupportedError, match="Abs"):
        tr(sp.Abs(x))
    with pytest.raises(UnsupportedError, match="no value"):
        tr(sp.Symbol("k") * x)


ABS_WELL = """\
id: lim-9204
source: test
title: particle in a well with an Abs term
parameters:
  m: {value: 1.0}
  k: {value: 2.0}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: k*(x**2 + Abs(x)**3)
"""


def test_simulate_with_taylor_and_its_fallback(tmp_path):
    from systems import load_analysis

    from mechbook.numerics.simulate import simulate

    an = load_analysis(tmp_path, PENDULUM, "9201")
    sim = simulate(an, init={"theta": "1"}, t_span=(0, 20), method="taylor", points=101)
    assert sim.trajectory.method == "taylor" and sim.trajectory.success
    assert len(sim.trajectory.t) == 101
    assert sim.drifts[0].relative < 1e-14
    # asked for by name, taylor is used or refused (issue 34): never another method
    well = load_analysis(tmp_path, ABS_WELL, "9204")
    with pytest.raises(MechbookError, match="taylor method cannot run.*no heyoka translation"):
        simulate(well, init={"x": "0.5"}, t_span=(0, 5), method="taylor")
    # chosen by --accuracy (taylor is the rule's method at 1e-10), it falls back, saying so
    sim = simulate(well, init={"x": "0.5"}, t_span=(0, 5), accuracy=1e-10)
    assert sim.trajectory.method == "DOP853"
    assert any("taylor method unavailable" in n and "no heyoka translation" in n
               for n in sim.notes)


def test_accuracy_rule_offers_taylor_only_where_installed():
    from mechbook.numerics import accuracy

    tight = min(t for t, row in accuracy.TABLE.items() if "taylor" in row)
    assert accuracy.choose(tight, taylor_available=True).method == "taylor"
    without = accuracy.choose(tight, taylor_available=False)
    assert without.method != "taylor"
    assert accuracy.choose(1e-6, method="taylor", taylor_available=True).method == "taylor"


def test_amplitude_frequencies_in_batch_mode(tmp_path):
    """The finite-amplitude frequency of the pendulum, ω(a) = π ω0 / (2 K(sin²(a/2))),
    measured one amplitude at a time (DOP853) and all at once (Taylor batch)."""
    from systems import load_analysis

    from mechbook.crosscheck.amplitude import amplitude_response

    an = load_analysis(tmp_path, PENDULUM, "9201")
    sys = an.system(None)
    lin = an.linear(None, {sys.q[0]: 0})
    values = an.problem.values()
    amps = np.array([0.05, 0.3, 0.8, 1.5, 2.2])
    w0 = math.sqrt(G / LEN)
    exact = np.array([math.pi * w0 / (2 * ellipk(math.sin(a / 2) ** 2)) for a in amps])
    lin_d, one = amplitude_response(an, lin, values, amps)
    lin_t, batch = amplitude_response(an, lin, values, amps, method="taylor")
    assert lin_d[0] == pytest.approx(w0, rel=1e-12) and lin_t[0] == lin_d[0]
    assert np.allclose(one[:, 0], exact, rtol=1e-9)
    assert np.allclose(batch[:, 0], exact, rtol=1e-11)


QUARTIC = """\
id: lim-9205
source: test
title: quartic oscillator
parameters:
  m: {value: 1.0}
  k: {value: 3.0}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: k*x**4/4
"""


def test_integer_powers_are_smooth_at_zero(tmp_path):
    """x³ at x = 0: heyoka's pow recurrence divides by the base (NaN there); the
    translator writes integer powers as products."""
    model, _ = model_of(tmp_path, QUARTIC, "9205")
    ts = np.linspace(0, 10, 11)
    tay = integrate(model, (0, 10), [0.0], [1.0], "taylor", t_eval=ts)
    ref = integrate(model, (0, 10), [0.0], [1.0], "DOP853", t_eval=ts, rtol=1e-13,
                    atol=1e-14)
    assert tay.success and np.max(np.abs(tay.y - ref.y)) < 1e-11


OSCILLATOR = """\
id: lim-9205
source: test
title: mass on a spring
parameters:
  m: {value: 1.5}
  k: {value: 6.1}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: k*x**2/2
"""


def test_simulate_taylor_holds_the_harmonic_oscillator_over_many_periods(tmp_path):
    from systems import load_analysis

    from mechbook.numerics.simulate import simulate

    an = load_analysis(tmp_path, OSCILLATOR, "9205")
    with mp.workdps(30):  # x = x0 cos(ωt), ω = √(k/m) of the doubles the problem holds
        w = mp.sqrt(mp.mpf(6.1) / mp.mpf(1.5))
        t_end = float(1000 * 2 * mp.pi / w)
        sim = simulate(an, init={"x": "0.7"}, t_span=(0, t_end), method="taylor",
                       points=2001, rtol=1e-15)
        t = sim.trajectory.t
        x = np.array([float(mp.mpf(0.7) * mp.cos(w * mp.mpf(s))) for s in t])
        v = np.array([float(-mp.mpf(0.7) * w * mp.sin(w * mp.mpf(s))) for s in t])
    assert sim.trajectory.success and len(t) == 2001
    # 1000 periods at tol 1e-15: the error stays at rounding level (2.8e-15 measured), and a
    # frequency off by 1e-12 (relative) would be 4e-9 off by the end
    assert np.max(np.abs(sim.trajectory.q[0] - x)) < 2e-14
    assert np.max(np.abs(sim.trajectory.qd[0] - v)) < 5e-14


def test_the_pendulum_costs_what_heyoka_written_by_hand_costs(tmp_path):
    import heyoka as hy

    model, _ = model_of(tmp_path, PENDULUM, "9201")
    ta = taylor.integrator(model, 1e-15, key="plain")
    th, v = hy.make_vars("th", "v")
    by_hand = hy.taylor_adaptive([(th, v), (v, -(G / LEN) * hy.sin(th))], [1.0, 0.0],
                                 tol=1e-15)
    # m·l²·(sin² + cos²) and −g·l·m simplified and hoisted: −(g/l) as one parameter
    assert len(ta.decomposition) == len(by_hand.decomposition)
    assert ta.pars[0] == pytest.approx(-G / LEN, rel=1e-16)
    ts = np.linspace(0, 50, 11)
    traj = integrate(model, (0, 50), [1.0], [0.0], "taylor", t_eval=ts, tol=1e-15)
    by_hand.time, by_hand.state[:] = 0.0, [1.0, 0.0]
    assert np.max(np.abs(traj.q[0] - np.asarray(by_hand.propagate_grid(ts)[5])[:, 0])) < 1e-14


def test_derived_parameters_follow_the_parameters_in_quadruple_precision(tmp_path):
    import heyoka as hy

    if not hasattr(hy, "real128"):
        pytest.skip("heyoka without real128")
    model, _ = model_of(tmp_path, PENDULUM, "9201")
    ta = taylor.integrator(model, 1e-30, key="q", fp_type=hy.real128)
    with mp.workdps(40):  # −g/l of the doubles 9.81 and 0.7, to real128's 113 bits
        want = -mp.mpf(G) / mp.mpf(LEN)
        assert abs(mp.mpf(str(ta.pars[0])) / want - 1) < 1e-32


def test_a_parameter_combination_that_is_not_real_is_refused(tmp_path):
    text = """\
id: lim-9206
source: test
title: a spring whose stiffness is a root of the parameters
parameters:
  m: {value: 1.0}
  a: {value: 1.0}
  b: {value: 2.0}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: sqrt(a - b)*x**2/2
"""
    model, _ = model_of(tmp_path, text, "9206")
    with pytest.raises(UnsupportedError, match="not real"):
        taylor.integrator(model, 1e-12, key="plain")


def test_parameter_only_subexpressions_become_one_parameter_each():
    from mechbook.numerics.taylor_form import Hoisted, tidy

    x, t = sp.symbols("x t")
    g, l, m, w = sp.symbols("g l m w", positive=True)  # noqa: E741
    h = Hoisted(frozenset([x, t]), frozenset([g, l, m, w]))
    mass = tidy(m * l**2 * (sp.sin(x) ** 2 + sp.cos(x) ** 2))
    assert mass == m * l**2
    acc = h(-g * l * m * sp.sin(x) / mass + 3 * sp.cos(w * t) / (m * l) + sp.pi * x)
    assert set(h.derived) == {-g / l, 3 / (m * l), w}  # and π stays a number
    p = dict(zip(h.derived, h.symbols, strict=True))
    assert acc == (p[-g / l] * sp.sin(x) + p[3 / (m * l)] * sp.cos(p[w] * t)
                   + sp.Float(sp.pi.evalf(40), 40) * x)
    assert h(-g * l * m * sp.sin(x) / mass) == p[-g / l] * sp.sin(x)  # shared, not a new one
    at = {g: 9.81, l: 1.3, m: 2.0, w: 0.1}
    with mp.workdps(40):
        want = {-g / l: -mp.mpf(9.81) / mp.mpf(1.3), 3 / (m * l): 3 / (mp.mpf(2.0) * mp.mpf(1.3)),
                w: mp.mpf(0.1)}
        for e, value in zip(h.derived, h.values(at), strict=True):
            assert abs(mp.mpf(str(value)) - want[e]) < mp.mpf(10) ** -38
