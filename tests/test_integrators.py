"""Integrators: symplectic ones keep the energy error bounded, explicit Runge–Kutta lets it
grow; orders of convergence; applicability."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from systems import DOUBLE, OSCILLATOR, load_analysis, pendulum

from mechbook.numerics.integrators import IntegratorError, integrate
from mechbook.numerics.monitors import conserved_quantities, drifts
from mechbook.numerics.rhs import build_model, structure

PENDULUM = pendulum(m=1.0, l=1.0, g=1.0,
                    header="id: lim-9101\nsource: test\ntitle: simple pendulum\n")




def model_of(tmp_path: Path, text: str, num: str):
    an = load_analysis(tmp_path, text, num)
    sys, dyn = an.system(), an.dynamics()
    return build_model(sys, dyn, an.problem.values(), conserved_quantities(sys, dyn))


@pytest.fixture(scope="module")
def pendulum(tmp_path_factory):
    return model_of(tmp_path_factory.mktemp("pend"), PENDULUM, "9101")


def energy_error(model, traj) -> np.ndarray:
    (d,) = drifts(model, traj)
    assert d.name == "energy_function"
    return d.values - d.initial


def test_symplectic_energy_bounded_over_10000_periods_rk_grows(pendulum):
    """Leapfrog: the energy error oscillates with the same bound at the start and the end of
    10^4 periods; classical RK4 with the same step drifts secularly."""
    period = 2 * np.pi  # small-oscillation period; the swing (θ0 = 1) is 12 % longer
    span = (0.0, 1e4 * period)
    h = period / 20
    leap = integrate(pendulum, span, [1.0], [0.0], "leapfrog", step=h, max_points=20001)
    rk = integrate(pendulum, span, [1.0], [0.0], "RK4", step=h, max_points=20001)
    assert leap.success and rk.success
    e_leap, e_rk = energy_error(pendulum, leap), energy_error(pendulum, rk)
    tenth = len(e_leap) // 10
    first, last = np.abs(e_leap[:tenth]).max(), np.abs(e_leap[-tenth:]).max()
    assert first < 0.02  # |h| = 0.54 at θ0 = 1; error O(h²)
    assert last < 1.05 * first  # bounded: no secular growth
    rk_first, rk_last = np.abs(e_rk[:tenth]).max(), np.abs(e_rk[-tenth:]).max()
    assert rk_last > 3 * rk_first  # grows with time
    assert rk_last > 10 * last
    slope_rk = np.polyfit(rk.t, e_rk, 1)[0]
    slope_leap = np.polyfit(leap.t, e_leap, 1)[0]
    assert abs(slope_rk) > 1e3 * abs(slope_leap)


def test_adaptive_explicit_rk_also_drifts(pendulum):
    """SciPy's RK45 at a loose tolerance loses energy steadily over 1000 periods."""
    span = (0.0, 1e3 * 2 * np.pi)
    traj = integrate(pendulum, span, [1.0], [0.0], "RK45", rtol=1e-5, atol=1e-8,
                     t_eval=np.linspace(*span, 2001))
    e = energy_error(pendulum, traj)
    assert abs(e[-1]) > 5 * np.abs(e[:200]).max()


@pytest.mark.parametrize("method, order", [("leapfrog", 2), ("yoshida4", 4), ("RK4", 4),
                                           ("midpoint", 2)])
def test_order_of_convergence(pendulum, method, order):
    ref = integrate(pendulum, (0, 5.0), [1.0], [0.0], "DOP853", rtol=1e-13, atol=1e-14)
    errors = []
    for h in (0.05, 0.025):
        traj = integrate(pendulum, (0, 5.0), [1.0], [0.0], method, step=h)
        errors.append(abs(traj.q[0, -1] - ref.q[0, -1]))
    rate = np.log2(errors[0] / errors[1])
    assert abs(rate - order) < 0.3, (method, errors, rate)


def test_implicit_midpoint_non_separable_energy_bounded(tmp_path):
    model = model_of(tmp_path, DOUBLE, "9102")
    st = structure(model, (0.0, np.array([0.5, -0.3]), np.zeros(2)))
    assert st.canonical and not st.separable
    with pytest.raises(IntegratorError, match="separable"):
        integrate(model, (0, 1), [0.5, -0.3], [0, 0], "leapfrog", step=0.01)
    traj = integrate(model, (0, 400.0), [0.5, -0.3], [0.0, 0.0], "midpoint", step=0.1)
    e = energy_error(model, traj)
    tenth = len(e) // 10
    assert np.abs(e).max() < 5e-3
    assert np.abs(e[-tenth:]).max() < 1.5 * np.abs(e[:tenth]).max() + 1e-12


def test_midpoint_keeps_quadratic_energy_exactly(tmp_path):
    model = model_of(tmp_path, OSCILLATOR, "9103")
    traj = integrate(model, (0, 200.0), [0.3], [0.1], "midpoint", step=0.2)
    e = energy_error(model, traj)
    assert np.abs(e).max() < 1e-13


def test_trajectory_shapes_and_settings(pendulum):
    traj = integrate(pendulum, (0, 2.0), [0.2], [0.0], "DOP853", rtol=1e-9, atol=1e-11,
                     t_eval=np.linspace(0, 2, 11))
    assert traj.q.shape == (1, 11) and traj.qd.shape == (1, 11) and traj.y.shape == (2, 11)
    assert traj.settings["rtol"] == 1e-9 and traj.settings["method"] == "DOP853"
    fixed = integrate(pendulum, (0, 2.0), [0.2], [0.0], "yoshida4", step=0.01)
    assert fixed.settings["steps"] == 200 and fixed.settings["order"] == 4
    assert fixed.t[-1] == pytest.approx(2.0)
    with pytest.raises(IntegratorError, match="unknown method"):
        integrate(pendulum, (0, 1), [0.1], [0.0], "Euler")


@pytest.mark.parametrize("method", ["RK45", "DOP853", "Radau", "LSODA"])
def test_scipy_methods_agree(pendulum, method):
    traj = integrate(pendulum, (0, 3.0), [0.4], [0.0], method, rtol=1e-10, atol=1e-12)
    ref = integrate(pendulum, (0, 3.0), [0.4], [0.0], "yoshida4", step=1e-3)
    assert traj.q[0, -1] == pytest.approx(ref.q[0, -1], abs=1e-7)


@pytest.mark.parametrize("method, option, value, why", [
    ("leapfrog", "rtol", 1e-10, "no tolerance"),
    ("RK4", "atol", 1e-10, "RK4"),
    ("DOP853", "step", 0.01, "chooses its own steps"),
    ("RK45", "tol", 1e-12, "rtol"),
    ("yoshida4", "max_iter", 10, "only the implicit midpoint rule iterates"),
    ("taylor", "atol", 1e-12, "relative only"),
    ("taylor", "compiled", False, "always compiled"),
])
def test_an_option_that_cannot_apply_is_refused_not_dropped(pendulum, method, option, value,
                                                             why):
    """An option the method does not take would have no effect: refused, naming the option,
    the method and why (issue: contracts by imitation, item 4)."""
    from mechbook.errors import MechbookError
    from mechbook.numerics.integrators import make_integrator

    with pytest.raises(IntegratorError, match=rf"option '{option}' does not apply to method "
                                              rf"'{method}' \(.*{why}") as info:
        make_integrator(method, **{option: value})
    assert isinstance(info.value, MechbookError)


def test_options_given_as_none_and_those_a_method_takes_are_kept(pendulum):
    from mechbook.numerics.integrators import make_integrator

    # the command line passes every option, None when not given
    scipy = make_integrator("DOP853", rtol=1e-9, atol=None, step=None, max_step=None)
    assert scipy.options == {"rtol": 1e-9, "atol": None, "max_step": None}
    fixed = make_integrator("leapfrog", step=0.01, rtol=None, atol=None, max_step=None)
    assert fixed.options == {"step": 0.01}
    assert make_integrator("midpoint", tol=1e-12, max_iter=20).options == {
        "tol": 1e-12, "max_iter": 20}
    assert make_integrator("taylor", rtol=1e-14, atol=None).options == {"rtol": 1e-14}


def test_cli_refuses_an_option_the_method_does_not_take():
    from click.testing import CliRunner

    from mechbook.app.cli import main

    root = Path(__file__).resolve().parents[1]
    res = CliRunner().invoke(main, ["--root", str(root), "simulate", "lim-2031", "--method",
                                    "leapfrog", "--rtol", "1e-10", "--t-end", "0.1",
                                    "--no-store"])
    assert res.exit_code != 0
    assert "--rtol does not apply to the fixed method leapfrog" in res.output  # said by the CLI
    assert "Traceback" not in res.output


def test_each_method_is_one_entry_of_the_table_naming_its_class(pendulum):
    """numerics.methods.METHODS is the one table of methods (issue 35, item 4): each
    name's entry names a module of mechbook.numerics and an Integrator subclass there,
    which make_integrator builds under the name its results carry (an alias's, the
    method's own); the lists the command line offers are read from it."""
    import importlib

    from mechbook.numerics.integrator_base import Integrator
    from mechbook.numerics.integrators import make_integrator
    from mechbook.numerics.methods import ALIASES, CHOICES, METHODS, OPTIONS, kind

    assert CHOICES == ("RK45", "DOP853", "Radau", "LSODA", "RK4", "leapfrog", "yoshida4",
                       "midpoint", "taylor")
    assert ALIASES == {"verlet": "leapfrog", "forest-ruth": "yoshida4"}
    for name, entry in METHODS.items():
        assert entry.module.startswith("mechbook.numerics.") and entry.family in OPTIONS
        cls = getattr(importlib.import_module(entry.module), entry.cls)
        assert issubclass(cls, Integrator)
        made = make_integrator(name)
        assert type(made) is cls and made.name == ALIASES.get(name, name)
        assert kind(name) == entry.family
    assert kind("nosuch") is None
    with pytest.raises(IntegratorError, match=r"unknown method 'nosuch'; known: RK45, "
                                              r"DOP853, .*, forest-ruth, midpoint, taylor$"):
        make_integrator("nosuch")
    run = integrate(pendulum, (0.0, 0.1), [0.5], [0.0], "verlet", step=0.01)
    assert run.success and run.method == "leapfrog" and run.settings["order"] == 2
