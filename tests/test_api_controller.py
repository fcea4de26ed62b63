"""The Python API for a controller and a notebook (issue 43 item 3): `ode_function` with
inputs per call, f(t, y, u); `linearize(steady=...)` solving for the rates a velocity
constraint fixes; docstrings on every property; a bad `about=` blamed on itself; and
`Simulation.animate()` / `plot()` shown inline. Every expected value is derived here by
hand, never taken from the engine."""

from __future__ import annotations

import inspect

import numpy as np
import pytest
from constrained_systems import COIN, key, write_tree
from scipy.integrate import solve_ivp

import mechbook
from mechbook.app.api import Problem
from mechbook.app.api.system import SystemView
from mechbook.errors import InputError, NotFoundError

FORCED = """\
id: lim-9601
source: a test problem
title: a mass on a spring pushed by a force F
parameters:
  m: {value: 1.5}
  k: {value: 6.0}
  F: {doc: the force a controller sets, value: 0.0, positive: false}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: k*x**2/2 - F*x
"""


# ---- ode_function: inputs per call -------------------------------------------------------------
def test_a_free_driven_support_is_an_input():
    """lim-2029 `general`: x_b = y + l sin θ, y_b = −l cos θ, so
    L = m(ẏ² + 2 l ẏ θ̇ cos θ + l² θ̇²)/2 + m g l cos θ and θ̈ = −(g sin θ + ÿ cos θ)/l."""
    f = mechbook.load("lim-2029").ode_function(system="general")
    assert f.states == ["theta", "thetadot"] and f.inputs == ["y", "ydot", "yddot"]
    g, length = 9.81, 0.9
    for th, w, ydd in ((0.3, 0.2, 2.0), (-1.1, 1.4, -0.7), (2.0, 0.0, 0.0)):
        want = [w, -(g * np.sin(th) + ydd * np.cos(th)) / length]
        assert np.allclose(f(0.0, [th, w], [0.1, 0.5, ydd]), want, rtol=1e-12, atol=1e-14)
        named = f(0.0, [th, w], {"y": 0.1, "ydot": 0.5, "yddot": ydd})
        assert np.allclose(named, want, rtol=1e-12, atol=1e-14)
    with pytest.raises(InputError, match="3 values wanted"):
        f(0.0, [0.3, 0.2], [1.0])
    with pytest.raises(InputError, match="missing: yddot"):
        f(0.0, [0.3, 0.2], {"y": 0.0, "ydot": 0.0})
    assert "u = (y, ydot, yddot)" in repr(f)


def test_a_parameter_as_input_driven_by_a_controller(tmp_path):
    """m ẍ = −k x + F. With the controller F = −c ẋ the motion is a damped oscillator:
    x(t) = e^{−γt}(cos ω_d t + (γ/ω_d) sin ω_d t) from x = 1, ẋ = 0, γ = c/(2m),
    ω_d² = k/m − γ²."""
    write_tree(tmp_path, "9601", FORCED, key(""))
    p = mechbook.load("lim-9601", tmp_path)
    f = p.ode_function(inputs=["F"])
    assert f.inputs == ["F"] and f.parameters == {"m": 1.5, "k": 6.0}
    m, k = 1.5, 6.0
    assert np.allclose(f(0.0, [0.2, -0.4], [3.0]), [-0.4, (3.0 - k * 0.2) / m], rtol=1e-14)
    c = 0.9
    sol = solve_ivp(lambda t, y: f(t, y, [-c * y[1]]), (0, 6), [1.0, 0.0], rtol=1e-11,
                    atol=1e-13, t_eval=np.linspace(0, 6, 61))
    gamma = c / (2 * m)
    wd = np.sqrt(k / m - gamma**2)
    x = np.exp(-gamma * sol.t) * (np.cos(wd * sol.t) + gamma / wd * np.sin(wd * sol.t))
    assert np.max(np.abs(sol.y[0] - x)) < 1e-8
    with pytest.raises(NotFoundError, match="'G' is not a parameter"):
        p.ode_function(inputs=["G"])


def test_without_inputs_it_is_the_simulated_function():
    """The bead on the hoop (lim-2031): θ̈ = ω² sin θ cos θ + (g/b) sin θ."""
    p = mechbook.load("lim-2031")
    f, fu = p.ode_function(), p.ode_function(inputs=["omega"])
    assert f.inputs == [] and fu.inputs == ["omega"]
    th, w = 1.0, 0.3
    by_hand = 36 * np.sin(th) * np.cos(th) + 9.81 / 0.5 * np.sin(th)
    assert np.allclose(f(0.0, [th, w]), [w, by_hand], rtol=1e-12)
    assert np.allclose(fu(0.0, [th, w], [6.0]), [w, by_hand], rtol=1e-12)
    with pytest.raises(InputError, match="no inputs"):
        f(0.0, [th, w], [6.0])


# ---- linearize(steady=...): the rates a velocity constraint fixes -------------------------------
@pytest.mark.parametrize("heading", [0.0, np.pi / 3])
def test_a_rolling_coin_spun_needs_no_centre_rate(tmp_path, heading):
    """A uniform disk rolling upright at spin rate Ω, heading φ: the contact does not slip,
    so its centre moves at ẋ = −R Ω cos φ, ẏ = −R Ω sin φ (the sign of the Euler angles'
    spin), and the wobble frequency is ω² = (12 Ω² − 4 g/R)/5 (tests/constrained_systems)."""
    write_tree(tmp_path, "9602", COIN.replace("SHAPE", "disk"), key(""))
    coin = mechbook.load("lim-9602", tmp_path, simplify=False)
    about = {"x": 0, "y": 0, "phi": float(heading), "theta": "pi/2", "psi": 0}
    lin = coin.linearize(about=about, steady={"psi": 5})
    rates = {str(q): float(v.subs({s: 0.3 for s in v.free_symbols if str(s) == "R"}))
             for q, v in lin.rates.items()}
    R, spin = 0.3, 5.0
    assert rates["psi"] == spin
    assert rates["x"] == pytest.approx(-R * spin * np.cos(heading), abs=1e-12)
    assert rates.get("y", 0.0) == pytest.approx(-R * spin * np.sin(heading), abs=1e-12)
    wobble = np.sqrt((12 * spin**2 - 4 * 9.81 / R) / 5)
    assert lin.frequencies()[0] == pytest.approx(wobble, rel=1e-10)


def test_a_rate_the_constraints_contradict_is_still_refused(tmp_path):
    """The centre's rate stated against the spin: the contact would slip."""
    from mechbook.errors import NotEquilibriumError

    write_tree(tmp_path, "9603", COIN.replace("SHAPE", "disk"), key(""))
    coin = mechbook.load("lim-9603", tmp_path, simplify=False)
    about = {"x": 0, "y": 0, "phi": 0, "theta": "pi/2", "psi": 0}
    with pytest.raises(NotEquilibriumError):
        coin.linearize(about=about, steady={"psi": 5, "x": 1.0})


# ---- docstrings, messages ----------------------------------------------------------------------
@pytest.mark.parametrize("cls", [Problem, SystemView])
def test_every_public_property_has_a_docstring(cls):
    missing = [name for name, member in inspect.getmembers(cls)
               if isinstance(member, property) and not name.startswith("_")
               and not (member.__doc__ or "").strip()]
    assert not missing, f"{cls.__name__}: no docstring on {missing}"
    assert "Lagrangian" in Problem.lagrangian.__doc__


@pytest.mark.parametrize("method", ["frequencies", "linearize"])
def test_a_bad_about_is_blamed_on_about(method):
    p = mechbook.load("lim-2031")
    with pytest.raises(InputError) as err:
        getattr(p, method)(about={"theta": "acos(-g/(b*omega**2)"})
    text = str(err.value)
    assert text.startswith("about={'theta': 'acos(-g/(b*omega**2)'}: syntax error"), text
    assert ".yaml" not in text and "line" not in text


def test_a_bad_steady_is_blamed_on_steady():
    p = mechbook.load("lim-2031")
    with pytest.raises(InputError, match=r"^steady=\{'theta': '1 \+'\}"):
        p.linearize(about={"theta": 0}, steady={"theta": "1 +"})


# ---- animate() and plot(), inline --------------------------------------------------------------
def test_animate_and_plot_show_inline(tmp_path, monkeypatch):
    """The bead at θ from the upward vertical of a hoop of radius b: it moves on the
    sphere of radius b about the centre, and starts at distance b sin θ₀ from the axis."""
    p = mechbook.load("lim-2031")
    monkeypatch.chdir(tmp_path)
    run = p.simulate(t_end=2, init={"theta": 1.0}, points=201)
    anim = run.animate()
    assert anim.frames == 201
    html = anim._repr_html_()
    assert '<figure class="animation">' in html and "<canvas" in html
    assert "requestAnimationFrame" in html  # the script that draws it comes with it
    path = np.array(anim.motion["bodies"][0]["path"])
    start = 0.5 * np.sin(1.0) if anim.motion["axes"] == ["x", "y"] else 0.5
    assert np.hypot(*path[0]) == pytest.approx(start, abs=1e-4)
    assert np.all(np.hypot(path[:, 0], path[:, 1]) <= 0.5 + 1e-4)
    assert run.animate(frames=20).frames <= 21
    picture = run.plot()
    assert picture._repr_png_().startswith(b"\x89PNG\r\n\x1a\n")
    assert list(tmp_path.iterdir()) == []  # inline: nothing written
    written = run.plot(tmp_path / "run.png")
    assert written.read_bytes().startswith(b"\x89PNG")


def test_a_loaded_problem_keeps_the_contract_its_systems_read():
    """api.system names the problem's type through api.loaded (below both: no import cycle,
    not even for a hint); a `Problem` keeps that contract, with each attribute a system reads."""
    from mechbook.app.api.loaded import LoadedProblem

    p = mechbook.load("lim-2031")
    assert isinstance(p, LoadedProblem)
    assert not isinstance(object(), LoadedProblem)
    assert p.system(p.systems[0]).problem is p
