"""`mechbook simulate`: compiled right-hand sides, initial conditions, monitors, the store
and the plot."""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

import mechbook.app.store as store
import mechbook.app.store.writer as store_writer
from mechbook.app.cli import main
from mechbook.engine.analysis import Analysis
from mechbook.errors import MechbookError
from mechbook.model.problem import load_problem
from mechbook.model.system import system_of
from mechbook.numerics.monitors import conserved_quantities
from mechbook.numerics.rhs import BACKENDS, build_model, structure
from mechbook.numerics.simulate import simulate

ROOT = Path(__file__).resolve().parents[1]


def problem(pid: str):
    book, num = pid.split("-", 1)
    return load_problem(ROOT / "problems" / book / f"{num}.yaml")


@pytest.mark.parametrize("pid, system", [("lim-2036", None), ("lim-2042", "spring"),
                                         ("lim-2037", None), ("symon-09-20", None)])
def test_backends_agree_with_the_symbolic_accelerations(pid, system):
    p = problem(pid)
    an = Analysis(p)
    sys, dyn = system_of(p, system), an.dynamics(system)
    n = len(sys.q)
    rng = np.random.default_rng(3)
    q = rng.uniform(0.1, 0.4, n)
    v = rng.uniform(-1, 1, n)
    env = {**p.values(), **dict(zip(sys.q, q, strict=True)), **dict(zip(sys.qd, v, strict=True)),
           sys.t: 0.3}
    exact = np.array([float(a.subs(env)) for a in dyn.accelerations])
    for backend in BACKENDS:
        model = build_model(sys, dyn, p.values(), backend=backend)
        assert model.backend == backend
        got = model.accelerations(0.3, q, v)
        assert np.allclose(got, exact, rtol=1e-10, atol=1e-12), backend


def test_structure_classifies_separable_canonical_gyroscopic():
    for pid, system, separable in (("lim-2031", None, True), ("lim-2036", None, False),
                                   ("lim-2037", None, False)):
        p = problem(pid)
        an = Analysis(p)
        model = build_model(system_of(p, system), an.dynamics(system), p.values())
        st = structure(model, (0.0, np.full(model.n, 0.3), np.zeros(model.n)))
        assert st.canonical and st.separable == separable, (pid, st)
    p = problem("lim-2037")
    model = build_model(system_of(p), Analysis(p).dynamics(), p.values())
    assert "linear in the velocities" in structure(model).reason


def test_monitors_energy_and_cyclic_momentum():
    p = problem("lim-2040")
    an = Analysis(p)
    names = list(conserved_quantities(system_of(p), an.dynamics()))
    assert names == ["energy_function", "p_theta"]
    sim = simulate(an, init={"r": "0.3", "thetadot": "4", "rdot": "0.2"}, t_span=(0, 5),
                   method="DOP853", rtol=1e-11, atol=1e-12)
    assert sim.trajectory.success
    assert {d.name for d in sim.drifts} == {"energy_function", "p_theta"}
    assert all(d.relative < 1e-8 for d in sim.drifts)


def test_initial_conditions_from_file_and_command_line(tmp_path):
    src = (ROOT / "problems/lim/2031.yaml").read_text()
    (tmp_path / "problems/lim").mkdir(parents=True)
    path = tmp_path / "problems/lim/2031.yaml"
    path.write_text(src + "initial: {theta: pi/2, thetadot: 0.5}\n")
    an = Analysis(load_problem(path))
    sim = simulate(an, t_span=(0, 0.1))
    assert sim.initial["theta"] == pytest.approx(np.pi / 2)
    assert sim.initial["thetadot"] == 0.5
    assert sim.initial_source == "problem file `initial:`"
    sim = simulate(an, init={"thetadot": "omega/4"}, t_span=(0, 0.1))
    assert sim.initial["thetadot"] == pytest.approx(1.5) and "command line" in sim.initial_source
    with pytest.raises(MechbookError, match="not a coordinate"):
        simulate(an, init={"phi": "1"})
    with pytest.raises(MechbookError):
        simulate(an, init={"theta": "__import__('os')"})


def test_fallback_start_near_a_stable_equilibrium():
    an = Analysis(problem("lim-2031"))
    sim = simulate(an, t_span=(0, 0.5))
    assert sim.initial_source == "fallback"
    assert any("no initial conditions" in n for n in sim.notes)


@pytest.mark.slow
def test_cli_simulate_done_criterion(tmp_path):
    """`mechbook simulate lim-2031 --method DOP853 --rtol 1e-10 --plot out.png` plots,
    stores the trajectory and prints the energy-function drift."""
    out, h5 = tmp_path / "out.png", tmp_path / "m.h5"
    res = CliRunner().invoke(main, ["--root", str(ROOT), "simulate", "lim-2031", "--method",
                                    "DOP853", "--rtol", "1e-10", "--plot", str(out),
                                    "--store", str(h5)])
    assert res.exit_code == 0, res.output
    assert "drift of energy_function" in res.output
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rec = store.read_simulation("lim-2031", "main-DOP853", h5)
    assert rec["attrs"]["method"] == "DOP853" and rec["attrs"]["setting_rtol"] == 1e-10
    assert rec["arrays"]["q"].shape == (1, 2001) and rec["arrays"]["t"][-1] == 10.0
    e = rec["array_attrs"]["monitors/energy_function"]
    assert e["relative_drift"] < 1e-8
    assert rec["attrs"]["rhs_backend"] == "llvm"


@pytest.mark.slow
def test_cli_symplectic_method_refused_when_not_separable(tmp_path):
    res = CliRunner().invoke(main, ["--root", str(ROOT), "simulate", "lim-2036", "--method",
                                    "leapfrog", "--init", "theta1=0.2", "--no-store"])
    assert res.exit_code != 0 and "separable" in res.output
    res = CliRunner().invoke(main, ["--root", str(ROOT), "simulate", "lim-2036", "--method",
                                    "midpoint", "--init", "theta1=0.2", "--t-end", "2",
                                    "--step", "0.01", "--no-store"])
    assert res.exit_code == 0, res.output
    assert "drift of energy_function" in res.output


@pytest.mark.slow
def test_check_run_keeps_simulations_and_simulation_keeps_checks(tmp_path):
    h5 = tmp_path / "m.h5"
    for p in ("problems/lim/2031.yaml", "answers/lim/2031.yaml"):
        (tmp_path / p).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / p, tmp_path / p)
    runner = CliRunner()
    res = runner.invoke(main, ["--root", str(tmp_path), "simulate", "lim-2031", "--t-end", "1",
                               "--store", str(h5), "--name", "first"])
    assert res.exit_code == 0, res.output
    res = runner.invoke(main, ["--root", str(tmp_path), "check", "lim-2031", "--store", str(h5)])
    assert res.exit_code == 0, res.output
    rec = store.read("lim-2031", h5)
    assert rec["simulations"] == ["first"] and rec["checks"] and rec["crosschecks"]
    res = runner.invoke(main, ["--root", str(tmp_path), "simulate", "lim-2031", "--t-end", "1",
                               "--store", str(h5), "--name", "second", "--method", "yoshida4"])
    assert res.exit_code == 0, res.output
    rec = store.read("lim-2031", h5)
    assert rec["simulations"] == ["first", "second"] and rec["checks"]
    with h5py.File(h5) as f:
        assert f["problems/lim-2031/simulations/second"].attrs["method"] == "yoshida4"
    res = runner.invoke(main, ["--root", str(tmp_path), "show", "lim-2031", "--store", str(h5)])
    assert "simulations/second" in res.output and "cross-checks" in res.output


def test_interrupted_simulation_write_keeps_previous_file(tmp_path, monkeypatch):
    h5 = tmp_path / "m.h5"
    store.write_simulation("lim-1", "a", {"t": np.arange(3.0)}, {"method": "RK4"}, path=h5)
    before = h5.read_bytes()

    def broken(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(store_writer.os, "replace", broken)
    with pytest.raises(KeyboardInterrupt):
        store.write_simulation("lim-1", "b", {"t": np.arange(4.0)}, {}, path=h5)
    assert h5.read_bytes() == before
    assert not list(tmp_path.glob("*.tmp"))


V_WELL = """\
id: lim-9302
source: test
title: a mass in a V-shaped well, V = k|x| (SymEngine leaves d|x|/dx unevaluated)
parameters:
  m: {value: 0.5}
  k: {value: 2.0}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: k*abs(x)
"""


def test_a_model_where_symengine_leaves_a_derivative_is_built_by_sympy(tmp_path):
    """build_model's equations and canonical parts are built by SymEngine where it can and
    by SymPy where it leaves a derivative unevaluated (d|x|/dx = sign(x)): the V-shaped well
    compiles, its force is −k·sign(x) both ways, and a symplectic method runs on it."""
    d = tmp_path / "problems" / "lim"
    d.mkdir(parents=True)
    (d / "9302.yaml").write_text(V_WELL)
    p = load_problem(d / "9302.yaml")
    an = Analysis(p)
    sys = system_of(p)
    model = build_model(sys, an.dynamics(), p.values())
    for x0 in (0.3, -0.7):
        assert model.accelerations(0.0, np.array([x0]), np.array([0.1]))[0] == \
            pytest.approx(-2.0 * np.sign(x0) / 0.5, rel=1e-12)
        ML, b, dLdq = model.canonical_parts(0.0, np.array([x0]), np.array([0.1]))
        assert float(np.ravel(ML)[0]) == pytest.approx(0.5) and \
            float(np.ravel(dLdq)[0]) == pytest.approx(-2.0 * np.sign(x0))
    sim = simulate(an, init={"x": "0.5", "xdot": "0"}, t_span=(0, 2), method="leapfrog",
                   step=1e-3)
    assert sim.trajectory.success and sim.trajectory.q.shape[1] > 100
    assert np.max(np.abs(sim.trajectory.q[0])) <= 0.5 + 1e-3  # energy kept: never far out


# ---- issue 33: hostile numbers on the command line end in a message that names them ------
@pytest.mark.parametrize("args, message", [
    (["--method", "RK4", "--step", "1e-300"], "1e+301 steps (at most 1e+10)"),
    (["--method", "RK4", "--t-end", "5e-324"], "too short to divide into steps"),
    (["--param", "m=nan"], "--param m=nan: unknown name 'nan'"),
    (["--param", "m=1e308"], "--param m=1e308: number 1e308 out of range"),
    (["--init", "theta=1e308"], "--init theta=1e308: number 1e308 out of range"),
    (["--init", "thetadot=("], "--init thetadot=(: syntax error"),
])
def test_hostile_simulate_options_are_refused_by_name(args, message):
    """On 0834a76: OverflowError (a C long of 1e301 steps), and --param/--init values blamed
    on problems/lim/2031.yaml:1."""
    from hostile import run

    res = run("--root", ROOT, "simulate", "lim-2031", "--no-store", *args)
    assert res.exit_code == 1, res.output
    assert message in res.output, res.output
    assert "2031.yaml:1" not in res.output and "Error: simulate lim-2031: " not in res.output


@pytest.mark.parametrize("t_end", ["1e-300", "1e-200", "5e-324"])
def test_a_tiny_span_simulates_and_its_drift_rate_is_a_number(t_end):
    """--t-end 1e-300 ended in "LinAlgError: SVD did not converge" (the drift's fit in
    time squared underflowed)."""
    from hostile import run

    res = run("--root", ROOT, "simulate", "lim-2031", "--no-store", "--t-end", t_end)
    assert res.exit_code == 0, res.output
    assert "drift of energy_function" in res.output and "LinAlg" not in res.output


def test_a_repeated_run_reuses_the_compiled_model(tmp_path):
    from systems import OSCILLATOR, load_analysis

    an = load_analysis(tmp_path, OSCILLATOR, "9301")  # m = 1.5, k = 6
    first = simulate(an, init={"x": "0.5"}, t_span=(0, 3), points=31)
    again = simulate(an, init={"x": "0.5"}, t_span=(0, 3), points=31)
    other = simulate(an, init={"x": "0.5"}, t_span=(0, 3), points=31, parameters={"k": "4"})
    assert again.model is first.model and other.model is not first.model
    assert np.array_equal(again.trajectory.y, first.trajectory.y)
    for sim, k in ((first, 6.0), (other, 4.0)):  # each with its own k: x = 0.5 cos(√(k/m) t)
        t = sim.trajectory.t
        assert np.allclose(sim.trajectory.q[0], 0.5 * np.cos(np.sqrt(k / 1.5) * t), atol=1e-6)
