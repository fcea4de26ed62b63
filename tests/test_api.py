"""The Python API (`mechbook.load`), the store as DataFrames (`mechbook.results`), and stored
trajectories opened by xarray through their HDF5 dimension scales."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import mechbook
from mechbook.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
m, b, g, omega = sp.symbols("m b g omega", positive=True)
theta, thetadot, thetaddot = sp.symbols("theta thetadot thetaddot", real=True)


@pytest.fixture(scope="module")
def hoop():
    return mechbook.load("lim-2031", ROOT)


def test_results_are_sympy_objects_equal_to_a_hand_derivation(hoop):
    """Bead on a hoop turning at omega (theta from the upward vertical), by hand:
    L = m b^2 (thetadot^2 + omega^2 sin^2 theta)/2 - m g b cos theta."""
    L = m * b**2 * (thetadot**2 + omega**2 * sp.sin(theta)**2) / 2 - m * g * b * sp.cos(theta)
    assert sp.simplify(hoop.lagrangian - L) == 0
    (eq,) = hoop.eom
    assert isinstance(eq, sp.Eq)
    hand = m * b**2 * thetaddot - m * b**2 * omega**2 * sp.sin(theta) * sp.cos(theta) \
        - m * g * b * sp.sin(theta)
    assert sp.simplify(eq.lhs - eq.rhs - hand) == 0
    assert sp.simplify(hoop.momenta[theta] - m * b**2 * thetadot) == 0
    assert hoop.cyclic == {}


def test_frequencies_about_a_named_point(hoop):
    # about the bottom (theta = pi): omega_0^2 = g/b - omega^2 (unstable at the defaults)
    (w,) = hoop.frequencies(about={"theta": "pi"})
    assert sp.simplify(w**2 - (g / b - omega**2)) == 0
    # off-axis: omega^2 (1 - g^2/(b^2 omega^4)), at the defaults m=0.1, b=0.5, omega=6
    off = {"theta": "acos(-g/(b*omega**2))"}
    (num,) = hoop.frequencies(about=off, numeric=True)
    assert num == pytest.approx(6 * np.sqrt(1 - (9.81 / (0.5 * 36)) ** 2), rel=1e-12)
    omegas, shapes = hoop.modes(about=off)
    assert omegas[0] == pytest.approx(num, rel=1e-9) and shapes.shape == (1, 1)
    with pytest.raises(KeyError, match="not a coordinate"):
        hoop.frequencies(about={"phi": "0"})
    with pytest.raises(InputError, match="^about=.*(not allowed|unknown)"):
        hoop.frequencies(about={"theta": "__import__('os')"})  # blamed on about=, no file


@pytest.mark.slow
def test_check_and_its_views(hoop):
    result = hoop.check(crosscheck=False)
    assert result.ok and result.error is None
    assert [o.status for o in result.outcomes] == ["pass"] * 6
    frame = result.to_frame()
    assert list(frame.part) == ["a-lagrangian", "a-eom", "b-linear", "b", "c", "c-frequency"]
    assert "<table>" in result._repr_html_() and "lim-2031: ok" in repr(result)


def test_check_fails_a_wrong_key(tmp_path):
    for kind in ("problems", "answers"):
        (tmp_path / kind / "lim").mkdir(parents=True)
    shutil.copy(ROOT / "problems" / "lim" / "2031.yaml", tmp_path / "problems" / "lim")
    text = (ROOT / "answers" / "lim" / "2031.yaml").read_text(encoding="utf-8")
    wrong = text.replace('book: ["omega*sqrt(1 - g**2/(b**2*omega**4))"]',
                         'book: ["omega*sqrt(1 + g**2/(b**2*omega**4))"]')
    assert wrong != text
    (tmp_path / "answers" / "lim" / "2031.yaml").write_text(wrong, encoding="utf-8")
    result = mechbook.load("lim-2031", tmp_path).check(crosscheck=False)
    assert not result.ok
    assert {o.part: o.status for o in result.outcomes}["c-frequency"] == "fail"


def test_notebook_views(hoop):
    assert hoop._repr_latex_().startswith("$") and r"\dot{\theta}" in hoop._repr_latex_()
    html = hoop._repr_html_()
    assert "<math" in html and "Bead on a hoop" in html and "<mover" in html


def test_several_systems_need_a_name():
    p = mechbook.load("lim-2043", ROOT, simplify=False)
    assert len(p.systems) > 1
    with pytest.raises(KeyError, match="several systems"):
        p.lagrangian  # noqa: B018
    assert p.system(p.systems[0]).lagrangian.has(sp.Symbol("g", positive=True))


@pytest.fixture(scope="module")
def store(tmp_path_factory, hoop):
    path = tmp_path_factory.mktemp("store") / "s.h5"
    hoop.check(store=path)
    run = hoop.simulate(t_end=3.0, points=301)
    return path, run, run.store(path, "test-run")


@pytest.mark.slow
def test_simulation_drift_and_store(store):
    path, run, where = store
    assert run.t[-1] == pytest.approx(3.0) and run.q.shape == (1, 301)
    assert run.drifts["energy_function"] < 1e-6  # h = E in the rotating frame is conserved
    assert where == "/problems/lim-2031/simulations/test-run"
    assert "energy_function" in run._repr_html_()


def test_trajectories_open_in_xarray(store):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    path, run, where = store
    with xr.open_dataset(path, engine="h5netcdf", group=where) as ds:
        assert ds["q"].dims == ("coordinate", "t") and ds["qdot"].dims == ("coordinate", "t")
        assert list(ds["coordinate"].values) == ["theta"]
        assert np.allclose(ds["t"].values, run.t)
        assert np.allclose(ds["q"].sel(coordinate="theta").values, run.q[0])
    with xr.open_dataset(path, engine="h5netcdf", group=where + "/monitors") as ds:
        assert ds["energy_function"].dims == ("t",)


def test_results_as_dataframes(store):
    pytest.importorskip("pandas")
    path, _, _ = store
    frames = mechbook.results(path)
    checks, cross, timings = frames
    assert list(checks.problem.unique()) == ["lim-2031"] and len(checks) == 6
    assert set(checks.status) == {"pass"} and (checks.book == "lim").all()
    assert len(cross) >= 2 and set(cross.kind) <= {"frequencies", "newton", "conserved"}
    assert timings.loc[0, "problem"] == "lim-2031" and timings.loc[0, "duration_s"] > 0
    assert timings.loc[0, "parts"] == 6
    with pytest.raises(FileNotFoundError):
        mechbook.results(path.parent / "absent.h5")


def test_mathml_dots_velocities_and_accelerations():
    from mechbook.app.output.mathml import DOT_STYLE, math

    out = math(sp.Symbol("thetadot") + sp.Symbol("x1ddot") + sp.Symbol("omega"))
    dot = f'<mo style="{DOT_STYLE}">'  # drawn large enough to read (issue 23)
    assert f'<mover accent="true"><mi>&#952;</mi>{dot}&#729;</mo></mover>' in out  # θ̇
    assert f'<msub><mover accent="true"><mi>x</mi>{dot}&#168;</mo></mover><mi>1</mi></msub>' \
        in out  # ẍ₁: the dots on the letter, not on the subscript
    assert "&#969;" in out and "ddot" not in out


# ---- the habits of SymPy and pandas users (issue 34 item 5) -----------------------------------
def test_equilibria_are_indexed_by_name_or_symbol(hoop):
    down = next(e for e in hoop.equilibria if e[theta] == sp.pi)
    assert down["theta"] == down[theta] == sp.pi
    assert "theta" in down and down.get("theta") == sp.pi and down.get("phi") is None
    with pytest.raises(KeyError):
        down["phi"]  # noqa: B018


def test_params_on_every_numeric_method(hoop):
    """At omega = 8 the off-axis frequency is omega*sqrt(1 - (g/(b*omega**2))**2) (the
    hand derivation above), on every method that computes a number."""
    off = {"theta": "acos(-g/(b*omega**2))"}
    hand = 8 * np.sqrt(1 - (9.81 / (0.5 * 64)) ** 2)
    (w,) = hoop.frequencies(about=off, numeric=True, params={"omega": 8})
    assert w == pytest.approx(hand, rel=1e-12)
    assert hoop.frequencies(about=off, numeric=True, params={omega: "4*2"}) == [w]
    (expr,) = hoop.frequencies(about=off, params={"omega": 8})
    assert float(expr.subs({b: 0.5, g: 9.81})) == pytest.approx(hand, rel=1e-12)
    assert hoop.modes(about=off, params={"omega": 8})[0][0] == pytest.approx(hand, rel=1e-9)
    lin = hoop.linearize(about=off)
    assert lin.frequencies(params={"omega": 8})[0] == pytest.approx(hand, rel=1e-9)
    assert lin.stability(params={"omega": 8}) in ("stable", "marginal")
    # the bottom is stable below omega^2 = g/b and unstable above: params decide
    bottom = hoop.linearize(about={"theta": "pi"})
    assert bottom.stability(params={"omega": 6}) == "unstable"
    assert bottom.stability(params={"omega": 2}) != "unstable"
    f6, f8 = hoop.ode_function(), hoop.ode_function(params={"omega": 8})
    y = f6.initial({"theta": 1.0})
    # theta'' = sin(theta)*(omega^2*cos(theta) + g/b) from the Lagrangian above
    for f, om in ((f6, 6), (f8, 8)):
        assert f(0.0, y)[1] == pytest.approx(np.sin(1) * (om**2 * np.cos(1) + 9.81 / 0.5),
                                             rel=1e-12)


def test_a_parameter_name_that_is_not_one_is_refused(hoop):
    with pytest.raises(KeyError, match="'omgea' is not a parameter.*did you mean 'omega'"):
        hoop.frequencies(about={"theta": "pi"}, numeric=True, params={"omgea": 8})
    with pytest.raises(KeyError, match="'omgea' is not a parameter"):
        hoop.linearize(about={"theta": "pi"}).stability(params={"omgea": 8})
    with pytest.raises(ValueError, match="positive"):
        hoop.modes(about={"theta": "pi"}, params={"b": -1})


def test_changing_the_defaults_is_refused_not_ignored(hoop):
    assert dict(hoop.parameters) == {"m": 0.1, "b": 0.5, "omega": 6.0, "g": 9.81}
    with pytest.raises(TypeError, match="params="):
        hoop.parameters["omega"] = 8
    with pytest.raises(TypeError, match="params="):
        del hoop.parameters["omega"]


def test_simulate_names_the_keyword_it_takes(hoop):
    for wrong, meant in (("initial", "init"), ("parameters", "params"), ("y0", "init"),
                         ("rtoll", "rtol")):
        with pytest.raises(TypeError, match=f"unexpected keyword argument '{wrong}'.*"
                                            f"'{meant}'"):
            hoop.simulate(t_end=1, **{wrong: 1})
    run = hoop.simulate(t_end=0.5, init={theta: 1.0}, params={"omega": 8}, points=11)
    assert run.q[0, 0] == 1.0 and "omega=8" in run.run.settings()["parameters"]
