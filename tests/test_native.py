"""Compiled stepping (loops.c) against the Python reference loops and solve_ivp: the same
steps give the same numbers to rounding; failures are reported the same way."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from systems import DOUBLE, DRIVEN, OSCILLATOR, load_analysis, pendulum

from mechbook.numerics import c_library
from mechbook.numerics.integrators import integrate
from mechbook.numerics.rhs import build_model

PENDULUM = pendulum(m=1.0, l=1.0, g=1.0,
                    header="id: lim-9301\nsource: test\ntitle: simple pendulum\n")
CONSTRAINED = """\
id: lim-9304
source: test
title: particle held on a circle by a multiplier
parameters:
  m: {value: 1.3}
  l: {value: 0.7}
  g: {}
coordinates:
  x: {}
  y: {}
particles:
  bob: {mass: m, position: [x, y]}
gravity: {}
constraints:
  - {name: rod, expr: x**2 + y**2 - l**2}
"""

pytestmark = pytest.mark.skipif(c_library.library() is None,
                                reason=f"no compiled loops here: {c_library.why()}")


def model_of(tmp_path: Path, text: str, num: str):
    an = load_analysis(tmp_path, text, num)
    return build_model(an.system(None), an.dynamics(None), an.problem.values())


CASES = {"pendulum": (PENDULUM, "9301", [1.0], [0.0]),
         "double": (DOUBLE, "9302", [0.5, -0.3], [0.1, 0.2]),
         "driven": (DRIVEN, "9303", [0.4], [0.3]),
         "constrained": (CONSTRAINED, "9304", [0.7 * np.sin(0.5), -0.7 * np.cos(0.5)],
                         [0.0, 0.0])}


@pytest.mark.parametrize("case", sorted(CASES))
def test_rhs_is_the_reference(tmp_path, case):
    text, num, q0, _ = CASES[case]
    model = model_of(tmp_path, text, num)
    assert model.native is not None
    rng = np.random.default_rng(1)
    for _ in range(5):
        y = np.concatenate((q0, rng.uniform(-1, 1, model.n))) + rng.uniform(-.1, .1, 2 * model.n)
        t = float(rng.uniform(0, 3))
        assert np.allclose(model.rhs(t, y), model.rhs_python(t, y), rtol=1e-14, atol=1e-14)
        q, v = y[: model.n], y[model.n:]
        assert np.allclose(model.accelerations(t, q, v), model.accelerations_python(t, q, v),
                           rtol=1e-14, atol=1e-14)


METHODS = {"pendulum": ("RK4", "leapfrog", "yoshida4", "midpoint", "DOP853", "RK45"),
           "double": ("RK4", "midpoint", "DOP853", "RK45"),
           "driven": ("RK4", "midpoint", "DOP853", "RK45"),
           "constrained": ("RK4", "DOP853", "RK45")}


@pytest.mark.parametrize("case,method", [(c, m) for c in sorted(METHODS) for m in METHODS[c]])
def test_compiled_loop_is_the_python_loop(tmp_path, case, method):
    text, num, q0, qd0 = CASES[case]
    model = model_of(tmp_path, text, num)
    opts = ({"rtol": 1e-9, "atol": 1e-9} if method in ("DOP853", "RK45")
            else {"step": 0.01})
    ts = np.linspace(0, 4, 41)
    fast = integrate(model, (0, 4), q0, qd0, method, t_eval=ts, **opts)
    slow = integrate(model, (0, 4), q0, qd0, method, t_eval=ts, compiled=False, **opts)
    assert fast.settings.get("compiled") and not slow.settings.get("compiled")
    assert fast.success and slow.success
    assert np.array_equal(fast.t, slow.t)
    assert np.max(np.abs(fast.y - slow.y)) < 1e-12
    if method in ("DOP853", "RK45"):
        assert fast.nfev == slow.nfev  # the same steps, accepted and rejected


def test_adaptive_loop_is_solve_ivp_without_t_eval(tmp_path):
    model = model_of(tmp_path, DRIVEN, "9303")  # not chaotic: rounding stays rounding
    y0 = np.array([0.4, 0.3])
    for method in ("DOP853", "RK45"):
        fast = integrate(model, (0, 3), y0[:1], y0[1:], method, rtol=1e-8, atol=1e-10)
        ref = solve_ivp(model.rhs_python, (0, 3), y0, method=method, rtol=1e-8, atol=1e-10)
        # the error estimate cancels ~8 digits (rtol 1e-8), so rounding in the stages moves
        # the step sizes by ~1e-11 relative: the same steps, the step points up to ~1e-9
        # apart after 50 steps; the end point is the same time
        assert len(fast.t) == len(ref.t) and fast.nfev == ref.nfev
        assert np.allclose(fast.t, ref.t, rtol=1e-8, atol=1e-12)
        assert np.max(np.abs(fast.y[:, -1] - ref.y[:, -1])) < 1e-9


def test_blow_up_is_reported_like_the_python_loop(tmp_path):
    model = model_of(tmp_path, OSCILLATOR, "9305")  # ω = 2: RK4 unstable for h > 1.41
    fast = integrate(model, (0, 5000), [1.0], [0.0], "RK4", step=2.5)
    slow = integrate(model, (0, 5000), [1.0], [0.0], "RK4", step=2.5, compiled=False)
    assert not fast.success and fast.message == slow.message
    assert fast.message.startswith("non-finite state at t =")
    assert np.array_equal(fast.t, slow.t) and np.allclose(fast.y, slow.y, rtol=1e-12)


def test_without_the_library_the_python_paths_run(tmp_path, monkeypatch):
    monkeypatch.setattr(c_library, "_state", {"lib": None, "tried": True, "why": "test",
                                           "build_seconds": 0.0})
    model = model_of(tmp_path, PENDULUM, "9301")
    assert model.native is None
    traj = integrate(model, (0, 1), [1.0], [0.0], "leapfrog", step=0.01)
    assert traj.success and not traj.settings.get("compiled")


@pytest.mark.parametrize("pid", ["symon-11-08", "lim-2034", "symon-09-07"])
def test_rhs_is_the_reference_on_larger_systems(pid):
    """Three and more degrees of freedom: the solve pivots at later steps too."""
    from mechbook.engine.analysis import Analysis
    from mechbook.model.catalog import problem_path
    from mechbook.model.problem import load_problem

    root = Path(__file__).resolve().parents[1]
    problem = load_problem(problem_path(pid, root))
    an = Analysis(problem)
    name = next(iter(problem.systems))
    model = build_model(an.system(name), an.dynamics(name), problem.values())
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(300):
        y = rng.uniform(-3, 3, 2 * model.n)
        with np.errstate(all="ignore"):
            ref = model.rhs_python(0.2, y)
        if not np.all(np.isfinite(ref)):
            continue
        worst = max(worst, float(np.max(np.abs(model.rhs(0.2, y) - ref)
                                       / (1 + np.abs(ref)))))
    assert worst < 1e-10
