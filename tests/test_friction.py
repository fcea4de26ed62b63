"""Coulomb friction at a contact (`friction:`), through stick and slip, against closed forms:
a block sent up an incline stops at v0/(g(sin α + μ cos α)) and then sticks (tan α < μ) or
slides back at g(sin α − μ cos α) (tan α > μ); a disk sent sliding without spin starts to
roll at v0/(3μg) with speed 2v0/3 and rolls on; a block pushed by a force growing like c·t
stays stuck until c·t = μmg and then moves as c(t − t_r)³/(6m). The sliding top's Newton
cross-check (own contact velocity) is in the books' run (Symon 11-15)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mechbook.engine.analysis import Analysis
from mechbook.errors import SpecError
from mechbook.model.problem import load_problem
from mechbook.numerics.friction import Phases
from mechbook.numerics.measure import first_event, signal_functions
from mechbook.numerics.rhs import build_model

G = 9.81

INCLINE = """\
id: symon-text-test-incline
source: test
title: block on an incline
parameters:
  m: {{value: 0.4}}
  mu: {{value: {mu}}}
  alpha: {{value: 0.3}}
  g: {{}}
coordinates:
  x: {{doc: distance up the incline}}
particles:
  block: {{mass: m, position: [x*cos(alpha), x*sin(alpha)]}}
gravity: {{}}
friction:
  - {{body: block, point: [x*cos(alpha), x*sin(alpha)], normal: [-sin(alpha), cos(alpha)],
     mu: mu, normal_force: m*g*cos(alpha)}}
"""

DISK = """\
id: symon-text-test-disk
source: test
title: disk sliding on a table
parameters:
  m: {value: 0.3}
  R: {value: 0.1}
  mu: {value: 0.2}
  g: {}
coordinates:
  x: {}
  phi: {doc: "turn of the disk, counterclockwise"}
rigid_bodies:
  disk: {mass: m, position: [x, R], inertia: m*R**2/2, angular_velocity: phidot}
friction:
  - {body: disk, point: [x, 0], mu: mu, normal_force: m*g}
"""

PUSHED = """\
id: symon-text-test-pushed
source: test
title: block pushed by a growing force
parameters:
  m: {value: 0.5}
  mu: {value: 0.4}
  c: {value: 3.0}
  g: {}
coordinates:
  x: {}
particles:
  block: {mass: m, position: [x, 0]}
forces: {x: c*t}
friction:
  - {body: block, point: [x, 0], mu: mu, normal_force: m*g}
"""


def _analysis(tmp_path, text: str) -> Analysis:
    name = text.split("\n", 1)[0].removeprefix("id: symon-")
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    return Analysis(load_problem(path))


@pytest.mark.parametrize("mu", [0.5, 0.2])
def test_block_on_an_incline_stops_then_sticks_or_slides_back(tmp_path, mu):
    a = _analysis(tmp_path, INCLINE.format(mu=mu))
    phases = Phases(a.system(), a.dynamics(), a.problem.values())
    alpha, v0 = 0.3, 2.0
    up = G * (math.sin(alpha) + mu * math.cos(alpha))
    t_stop, x_stop = v0 / up, v0**2 / (2 * up)
    r = phases.solve_ivp((0.0, 1.0), [0.0, v0])
    (t_switch, _, _), = r.switches[:1]
    assert abs(t_switch / t_stop - 1) < 1e-6
    x_end = r.y[0, -1]
    if math.tan(alpha) < mu:
        assert [s[2] for s in r.switches] == ["stick"]
        assert abs(x_end - x_stop) < 1e-7 and r.y[1, -1] == 0.0
    else:
        assert [s[2] for s in r.switches] == ["through"]
        down = G * (math.sin(alpha) - mu * math.cos(alpha))
        assert abs(x_end - (x_stop - down * (1.0 - t_stop) ** 2 / 2)) < 1e-7


def test_a_sliding_disk_starts_to_roll(tmp_path):
    a = _analysis(tmp_path, DISK)
    phases = Phases(a.system(), a.dynamics(), a.problem.values())
    v0, mu = 1.5, 0.2
    r = phases.solve_ivp((0.0, 2.0), [0.0, 0.0, v0, 0.0])
    assert [s[2] for s in r.switches] == ["stick"]
    assert abs(r.switches[0][0] / (v0 / (3 * mu * G)) - 1) < 1e-6
    xdot, phidot = r.y[2, -1], r.y[3, -1]
    assert abs(xdot / (2 * v0 / 3) - 1) < 1e-8
    assert abs(xdot + 0.1 * phidot) < 1e-9          # rolling: the contact at rest


def test_a_block_breaks_free_when_the_push_exceeds_mu_m_g(tmp_path):
    a = _analysis(tmp_path, PUSHED)
    phases = Phases(a.system(), a.dynamics(), a.problem.values())
    m, mu, c = 0.5, 0.4, 3.0
    t_r = mu * m * G / c
    r = phases.solve_ivp((0.0, 1.5), [0.0, 0.0])
    assert [s[2] for s in r.switches] == ["slip"]
    assert abs(r.switches[0][0] / t_r - 1) < 1e-6
    assert abs(r.y[0, -1] / (c * (1.5 - t_r) ** 3 / (6 * m)) - 1) < 1e-6


def test_the_measurements_integrate_through_stick_and_slip(tmp_path):
    """first_event uses the phases: the disk slides to t_r = v0/(3μg), then rolls at 2v0/3;
    it reaches x_r + 0.5 at t_r + 0.5/(2v0/3)."""
    a = _analysis(tmp_path, DISK)
    sys, dyn = a.system(), a.dynamics()
    values = a.problem.values()
    model = build_model(sys, dyn, values)
    v0, mu = 1.5, 0.2
    t_r = v0 / (3 * mu * G)
    x_r = v0 * t_r - mu * G * t_r**2 / 2
    fn = signal_functions(sys, dyn, values, sys.q[0] - (x_r + 0.5))
    t, _ = first_event(model, fn, np.zeros(2), np.array([v0, 0.0]), 0.1)
    assert abs(t / (t_r + 0.5 / (2 * v0 / 3)) - 1) < 1e-6


def test_a_normal_force_with_accelerations_is_refused(tmp_path):
    with pytest.raises(SpecError, match="no accelerations"):
        _analysis(tmp_path, PUSHED.replace("normal_force: m*g", "normal_force: m*(g + xddot)")
                  ).system()


def _reference(phases: Phases, t: float, y: np.ndarray, mode: str):
    """The accelerations (and a stuck contact's force) as first written: the compiled
    function's own result sliced, np.linalg.solve and np.linalg.norm (one contact)."""
    n = phases.n
    out = np.asarray(phases._fn(np.concatenate(([t], y))), float)
    M, f = out[: n * n].reshape(n, n), out[n * n: n * n + n].copy()
    _, d, k, T = phases.contacts[0]
    vt, J = out[k: k + d], out[k + d: k + d + d * n].reshape(d, n)
    bias, mu, N = out[k + d + d * n: k + 2 * d + d * n], out[k + 2 * d + d * n], out[-1]
    if mode == "slip":
        return np.linalg.solve(M, f - mu * N * (J.T @ (vt / np.linalg.norm(vt)))), None
    A = T @ J
    m = A.shape[0]
    big = np.zeros((n + m, n + m))
    big[:n, :n], big[:n, n:], big[n:, :n] = M, -A.T, A
    sol = np.linalg.solve(big, np.concatenate((f, -(T @ bias))))
    return sol[:n], T.T @ sol[n:]


@pytest.mark.parametrize("backend", ["llvm", "symengine", "sympy"])
def test_the_right_hand_side_is_the_reference_to_the_bit(tmp_path, monkeypatch, backend):
    """The kernel writing into a buffer, LAPACK's dgesv and sqrt(v·v) give what the compiled
    function, np.linalg.solve and np.linalg.norm give, to the bit, with every compile
    backend, sliding and stuck; a state evaluated last is reused only when it is the same."""
    import functools

    import mechbook.numerics.friction as friction
    from mechbook.core.compile import compile_exprs

    monkeypatch.setattr(friction, "compile_exprs",
                        functools.partial(compile_exprs, backend=backend))
    a = _analysis(tmp_path, DISK)
    phases = Phases(a.system(), a.dynamics(), a.problem.values())
    for y in np.random.default_rng(1).normal(size=(20, 4)):
        t = float(y[0])
        acc, _ = _reference(phases, t, y, "slip")
        assert phases.rhs(t, y, ["slip"], [None]).tobytes() == np.concatenate(
            (y[2:], acc)).tobytes()
        acc, force = _reference(phases, t, y, "stick")
        got, forces = phases._accelerations(t, y, ["stick"], [None])
        assert got.tobytes() == acc.tobytes() and forces[0].tobytes() == force.tobytes()
        kept = phases._out.copy()
        phases._evaluate(t, y, reuse=True)
        assert phases._out.tobytes() == kept.tobytes()
        moved = y.copy()
        moved[2] += 1.0
        phases._evaluate(t, moved, reuse=True)  # not the last state: evaluated anew
        assert phases._out.tobytes() == np.asarray(
            phases._fn(np.concatenate(([t], moved))), float).tobytes()


CASES = [(INCLINE.format(mu=0.5), [0.0, 2.0], 1.0), (INCLINE.format(mu=0.2), [0.0, 2.0], 1.0),
         (DISK, [0.0, 0.0, 1.5, 0.0], 2.0), (PUSHED, [0.0, 0.0], 1.5)]


@pytest.mark.parametrize("text, y0, t_end", CASES, ids=["sticks", "slides-back", "disk", "push"])
def test_sliding_phases_in_the_compiled_loop_agree_with_scipy(tmp_path, text, y0, t_end):
    """Phases where every contact slides run in the compiled DOP853 loop on the smooth
    model, the step of an event again in SciPy: the same switches, at the same times, the
    same end state (to 1e-10), and every crossing of a non-terminal event of the caller's
    found as a whole run in SciPy finds it; the caller's non-terminal event changes nothing
    in the motion (as in solve_ivp).

    The times agree to 1e-12 when both runs see |v_t| fall below ε at a step's end. The
    window is ~2ε/|a| ≈ 1e-9 s wide, and a step may straddle it: the smooth model then
    slides through v_t = 0 and back, and the stop is found a few ns later (both SciPy and
    the compiled loop do this). Which run does it depends on rounding here: these motions
    are polynomials in t, DOP853's error estimate of them is rounding noise, and so are the
    step sizes of the compiled loop (the smooth model) and the reference (this class's
    right-hand side). Hence 1e-8 for the switches."""
    a = _analysis(tmp_path, text)
    sys, dyn, values = a.system(), a.dynamics(), a.problem.values()
    model = build_model(sys, dyn, values)
    if model.native is None:
        pytest.skip("no compiled loops here (no C compiler or another backend)")

    def level(t, y):  # crosses zero both ways in most of these motions
        return y[0] - 0.05

    level.terminal, level.direction = False, 0
    reference = Phases(sys, dyn, values).solve_ivp((0.0, t_end), y0, [level])
    before = model.native.nfev()
    fast = Phases(sys, dyn, values, model).solve_ivp((0.0, t_end), y0, [level])
    if text != PUSHED:  # the pushed block starts stuck, then slides the way it is pushed
        assert model.native.nfev() > before  # the compiled loop ran
    assert [s[1:] for s in fast.switches] == [s[1:] for s in reference.switches]
    for (tf, *_), (tr, *_) in zip(fast.switches, reference.switches, strict=True):
        assert abs(tf - tr) <= 1e-8 * max(1.0, abs(tr))
    alone = Phases(sys, dyn, values, model).solve_ivp((0.0, t_end), y0)
    assert alone.switches == fast.switches
    assert np.array_equal(alone.y, fast.y)
    assert np.allclose(fast.y[:, -1], reference.y[:, -1], rtol=1e-10, atol=1e-12)
    assert len(fast.t_events[0]) == len(reference.t_events[0]) >= 1
    assert np.allclose(fast.t_events[0], reference.t_events[0], rtol=1e-12)
