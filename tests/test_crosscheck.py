"""Cross-checks: frequencies measured from nonlinear simulations, Lagrange against Newton.
Each check must be able to fail: tampered engines are caught."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from click.testing import CliRunner

import mechbook.crosscheck as crosscheck_mod
from mechbook.app.cli import main
from mechbook.crosscheck import crosscheck_problem
from mechbook.crosscheck.frequencies import REL_TOL, frequency_crosscheck
from mechbook.crosscheck.newton import newton_crosscheck
from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.records import CrossCheck
from mechbook.verify.answers import load_answers

ROOT = Path(__file__).resolve().parents[1]

OSCILLATOR = """\
id: lim-9201
source: test
title: mass on a spring
parameters:
  m: {value: 1.7}
  k: {value: 5.3}
coordinates:
  x: {}
particles:
  mass: {mass: m, position: [x]}
springs:
  - {k: k, between: [mass, [0]]}
"""

DRIVEN = """\
id: lim-9202
source: test
title: pendulum with a prescribed vibrating support
parameters:
  m: {value: 1.0}
  l: {value: 1.0}
  g: {}
  a: {value: 0.1}
  w: {value: 7.0}
coordinates:
  theta: {}
particles:
  bob: {mass: m, position: [l*sin(theta), a*cos(w*t) - l*cos(theta)]}
gravity: {}
"""


def load(tmp_path: Path, text: str, num: str) -> Analysis:
    d = tmp_path / "problems" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    (d / f"{num}.yaml").write_text(text)
    return Analysis(load_problem(d / f"{num}.yaml"))


def real(pid: str) -> tuple[Analysis, object]:
    book, num = pid.split("-", 1)
    an = Analysis(load_problem(ROOT / "problems" / book / f"{num}.yaml"))
    return an, load_answers(ROOT / "answers" / book / f"{num}.yaml")


def test_harmonic_oscillator_frequency_to_1e8(tmp_path):
    an = load(tmp_path, OSCILLATOR, "9201")
    lin = an.linear(None, {an.system().q[0]: sp.S.Zero})
    x = frequency_crosscheck(an, lin, an.problem.values(), "osc")
    assert x.status == "pass", x.detail
    (mode,) = x.modes
    exact = np.sqrt(5.3 / 1.7)
    assert abs(mode["measured"] - exact) / exact < 1e-8
    assert x.error < 1e-8


def test_pendulum_nonlinear_shift_controlled():
    """A pendulum's frequency falls with amplitude as ω(1 − A²/16): the amplitude is chosen
    small enough that the measured frequency agrees to far better than REL_TOL."""
    an, key = real("lim-2035")
    checks = crosscheck_problem(an, key)
    (modes,) = [c for c in checks if c.kind == "frequencies"]
    assert modes.status == "pass"
    for m in modes.modes:
        assert m["relative_error"] < REL_TOL and m["shift"] < 1e-5
        assert m["extrapolated_error"] < 1e-8
    assert set(modes.parts) == {"modes", "point"}


def test_tampered_linear_system_fails(tmp_path):
    an = load(tmp_path, OSCILLATOR, "9201")
    lin = an.linear(None, {an.system().q[0]: sp.S.Zero})
    wrong = dataclasses.replace(lin, K=lin.K * sp.Rational(1001, 1000))
    x = frequency_crosscheck(an, wrong, an.problem.values(), "osc")
    assert x.status == "fail" and x.error > REL_TOL


def test_point_that_is_not_an_equilibrium_fails(tmp_path):
    an = load(tmp_path, OSCILLATOR, "9201")
    lin = an.linear(None, {an.system().q[0]: sp.S.Zero})
    moved = dataclasses.replace(lin, point={an.system().q[0]: sp.Rational(1, 10)})
    x = frequency_crosscheck(an, moved, an.problem.values(), "osc")
    assert x.status == "fail" and "not an equilibrium" in x.detail


@pytest.mark.parametrize("pid", ["lim-2037", "lim-2040", "lim-2038", "symon-09-20"])
def test_gyroscopic_steady_and_zero_modes(pid):
    """Gyroscopic (magnetic) terms, a steady motion by Routh reduction, and a free
    translation (zero mode, which must stay put) are all handled."""
    an, key = real(pid)
    checks = [c for c in crosscheck_problem(an, key) if c.kind == "frequencies"]
    assert checks and all(c.status == "pass" for c in checks), [c.detail for c in checks]
    if pid == "lim-2038":
        assert any(m["kind"] == "zero" and m["status"] == "pass" for m in checks[0].modes)


def test_non_autonomous_is_not_applicable(tmp_path):
    an = load(tmp_path, DRIVEN, "9202")
    an.problem.parameters["a"].small = False
    lin = an.linear(None, {an.system().q[0]: sp.S.Zero})
    x = frequency_crosscheck(an, lin, an.problem.values(), "driven")
    assert x.status == "n.a." and "autonomous" in x.detail


def test_newton_passes_and_catches_a_wrong_lagrangian(tmp_path):
    an, _ = real("lim-2039")  # rigid body with Euler terms, springs by length
    assert newton_crosscheck(an).status == "pass"
    an, _ = real("lim-2042")  # planar body, particle, extra potential
    assert newton_crosscheck(an, "spring").status == "pass"
    an = load(tmp_path, OSCILLATOR, "9201")
    sys = an.system()
    sys.lagrangian = sys.lagrangian.subs(sp.Symbol("k", positive=True, real=True), 2)
    x = newton_crosscheck(an)
    assert x.status == "fail" and x.error > 1e-3


@pytest.mark.parametrize(("pid", "name"), [("lim-2039", None), ("lim-2042", "spring"),
                                          ("symon-text-11-5-heavy-top", "euler"),
                                          ("symon-11-15", "sliding")])
def test_newton_residual_is_the_same_in_symengine_and_sympy(pid, name):
    """The Newton side is assembled by SymEngine where it can, by SymPy otherwise (an
    unknown function): the two algebras give the same residual at random states."""
    import symengine as se

    from mechbook.crosscheck.newton import newton_residual

    an, _ = real(pid)
    sys = an.system(name)
    fast, slow = newton_residual(sys), newton_residual(sys, symengine=False)
    assert all(isinstance(e, se.Basic) for e in fast)
    assert all(isinstance(e, sp.Basic) for e in slow)
    rng = np.random.default_rng(5)
    symbols = sorted(set().union(*(e.free_symbols for e in slow)), key=str)
    for _ in range(3):
        point = {s: float(rng.uniform(0.2, 0.9)) for s in symbols}
        by_name = {str(s): v for s, v in point.items()}
        for a, b in zip(fast, slow, strict=True):
            va = float(a.subs({se.Symbol(k): v for k, v in by_name.items()}))
            vb = float(b.xreplace(point))
            assert abs(va - vb) <= 1e-12 * max(1.0, abs(vb)), (pid, a, b)


def test_newton_not_applicable_without_positions():
    an, _ = real("lim-2032")
    assert newton_crosscheck(an, "free").status == "n.a."


def test_crosscheck_roundtrip_dict():
    x = CrossCheck("n", "newton", "main", "pass", 1e-16, "d", ["a"], 0.1, [{"mode": 0}])
    assert CrossCheck.from_dict(x.as_dict()) == x
    assert x.cell() == "pass 1e-16" and not x.failed


@pytest.mark.slow
def test_check_table_has_the_column_and_a_crosscheck_fail_exits_1(monkeypatch):
    runner = CliRunner()
    res = runner.invoke(main, ["--root", str(ROOT), "check", "lim-2031", "--no-store"])
    assert res.exit_code == 0, res.output
    header = next(x for x in res.output.splitlines() if x.startswith("problem "))
    assert "cross-check" in header
    line = next(x for x in res.output.splitlines() if "c-frequency" in x)
    assert line.split()[4] == "pass" and float(line.split()[5]) < REL_TOL

    def failing(analysis, key, stage=None):
        return [CrossCheck("newton:main", "newton", "main", "fail", 0.5, "tampered",
                           ["a-eom"])]

    monkeypatch.setattr(crosscheck_mod, "crosscheck_problem", failing)
    res = runner.invoke(main, ["--root", str(ROOT), "check", "lim-2031", "--no-store",
                               "--serial"])
    assert res.exit_code == 1
    assert "fail 5e-01" in res.output and "failed cross-checks" in res.output


def test_conserved_by_simulation_passes_a_true_integral_and_fails_a_false_one(tmp_path):
    """The book's first integral is evaluated along an integrated trajectory: the angular
    momentum about the axis stays put, a wrong power of r does not."""
    from mechbook.verify.answers import load_answers

    src = Path(__file__).resolve().parents[1]
    analysis = Analysis(load_problem(src / "problems" / "lim" / "2040.yaml"))
    text = (src / "answers" / "lim" / "2040.yaml").read_text()
    results = {}
    for label, book in (("right", "m*r**2*thetadot"), ("wrong", "m*r*thetadot")):
        f = tmp_path / f"{label}.yaml"
        f.write_text(text.replace('book: "m*r**2*thetadot"', f'book: "{book}"'))
        xs = crosscheck_problem(analysis, load_answers(f))
        results[label] = next(x for x in xs if x.name == "conserved:b-momentum")
    assert results["right"].status == "pass", results["right"].detail
    assert results["wrong"].status == "fail"


@pytest.mark.slow
def test_independent_kinematics_agree_with_the_engine_and_catch_a_wrong_one():
    """The Newton check's own kinematics (ω from Rᵀ·dR/dt, inertia by integration over the
    shape) agree with the engine's closed forms for every standard shape — and would
    expose a wrong entry in the engine's table."""
    from mechbook.crosscheck.kinematics import body_angular_velocity, inertia_of_shape
    from mechbook.model.bodies import SHAPES, euler_body_rates, shape_inertia

    phi, theta, psi = sp.symbols("phi theta psi", real=True)
    rates = dict(zip((phi, theta, psi), sp.symbols("phid thetad psid", real=True),
                     strict=True))

    def dt(e):
        return sum((sp.diff(e, q) * v for q, v in rates.items()), sp.S.Zero)

    ours = body_angular_velocity([phi, theta, psi], dt)
    theirs = euler_body_rates([phi, theta, psi], dt)
    rng = np.random.default_rng(3)
    for _ in range(5):
        pt = {s: rng.uniform(-2, 2) for s in [phi, theta, psi, *rates.values()]}
        assert np.allclose([float(x.subs(pt)) for x in ours],
                           [float(x.subs(pt)) for x in theirs], rtol=1e-12, atol=1e-12)
    m, r, length, a, b, c = sp.symbols("m r L a b c", positive=True)
    dims = {"point": {}, "rod": {"length": length}, "ring": {"radius": r},
            "disk": {"radius": r}, "solid_cylinder": {"radius": r, "length": length},
            "solid_sphere": {"radius": r}, "spherical_shell": {"radius": r},
            "rectangular_plate": {"sides": [a, b]}, "block": {"sides": [a, b, c]},
            "cone": {"radius": r, "height": length}, "solid_ellipsoid": {"semi_axes": [a, b, c]}}
    assert set(dims) == set(SHAPES)
    for shape, d in dims.items():
        diff = sp.simplify(inertia_of_shape(shape, m, d) - shape_inertia(shape, m, d))
        assert diff == sp.zeros(3, 3), shape
    wrong = shape_inertia("solid_sphere", m, dims["solid_sphere"]) * sp.Rational(5, 4)
    assert sp.simplify(inertia_of_shape("solid_sphere", m, dims["solid_sphere"]) - wrong) \
        != sp.zeros(3, 3)


def test_a_double_exponent_with_one_mode_is_not_measured():
    """A Jordan block (critically damped oscillator: p = -1 twice, one eigenvector) is
    recognised, and a double root with two modes (two equal oscillators) is not."""
    import numpy as np
    import scipy.linalg

    from mechbook.crosscheck.modal import defective

    critical = np.array([[0.0, 1.0], [-1.0, -2.0]])
    lam, V = scipy.linalg.eig(critical)
    assert defective(lam, V, 0, float(np.max(np.abs(lam))))
    pair = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.eye(2), np.zeros((2, 2))]])
    lam, V = scipy.linalg.eig(pair)
    assert not any(defective(lam, V, j, 1.0) for j in range(4))


def test_box_integrals_term_by_term_equal_sympys_multiple_integral():
    """core.integrals.box_integral (the inertia shapes', a string's mass integrals):
    products of one-variable factors integrated factor by factor; a term mixing the
    variables, or limits depending on another variable, go to SymPy's multiple integral.
    The same values either way."""
    from mechbook.core.integrals import box_integral as _box_integral

    u, v, w, a = sp.symbols("u v w a", positive=True)
    box = ((u, 0, a), (v, 0, sp.pi), (w, 0, 2 * sp.pi))
    for e, separable in ((u**2 * sp.sin(v) ** 3 * sp.cos(w) ** 2 + a * u * sp.sin(v), True),
                         (u * sp.sin(v + w) ** 2 + u**3, False),  # a term mixing v and w
                         ((u + v) ** 2 * sp.cos(w) ** 2, True)):
        known: dict = {}
        assert sp.simplify(_box_integral(e, box, known) - sp.integrate(sp.expand(e), *box)) \
            == 0
        if separable:  # done factor by factor: each one-variable integral kept
            assert {key[1] for key in known} == {u, v, w}
    tri = ((u, 0, v), (v, 0, a))  # a limit depending on the other variable
    assert sp.simplify(_box_integral(u * v, tri, {}) - a**4 / 8) == 0


def test_each_crosscheck_name_is_one_entry_of_the_table(monkeypatch):
    """crosscheck.problem.CROSSCHECKS is the one table of the cross-checks a part's
    registration may name (issue 35, item 4): each entry runs its check, or names the
    check whose measurement it changes; two names of one check run it once; and a new
    entry is all a new check needs to run for the parts that name it, in table order."""
    import re

    from mechbook.crosscheck import problem as problem_mod
    from mechbook.crosscheck.problem import CROSSCHECKS, PartCheck, each_part

    for name, entry in CROSSCHECKS.items():
        if entry.run is None:
            other = re.match(r"with `(\w+)`: ", entry.doc)
            assert other and CROSSCHECKS[other.group(1)].run is not None, name
    assert CROSSCHECKS["first_integrals"].run is CROSSCHECKS["energy_integral"].run

    calls = []

    def probe(analysis, part, models):
        calls.append(part.name)
        return CrossCheck(f"probe:{part.name}", "probe", "main", parts=[part.name])

    run_probe = each_part(probe, "probe")
    table = {"probe": PartCheck("a probe", run_probe),
             "again": PartCheck("Newton's, by another name", CROSSCHECKS["newton"].run),
             "probe_too": PartCheck("the probe by another name", run_probe)}
    monkeypatch.setattr(problem_mod, "CROSSCHECKS", table)
    monkeypatch.setattr(problem_mod, "crosschecks_of", lambda q: ("probe_too", "again"))
    an, key = real("lim-2031")
    stages = []
    out = crosscheck_problem(an, key, stages.append)
    parts = [p.name for p in key.parts if "unsupported" not in p.data]
    assert calls == parts  # each part once, though it names the probe twice
    assert [x.name for x in out if x.kind == "probe"] == [f"probe:{p}" for p in parts]
    assert f"cross-check probe:{parts[0]}" in stages
    (newton,) = [x for x in out if x.kind == "newton"]
    assert newton.parts == parts  # the Newton entry, under another name, ran too
