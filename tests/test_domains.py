"""Coordinate domains (`positive`, `nonnegative`, `range`) in the generic engine: the
equilibria listed, the numeric search, random states and simulations respect them; points
that do not exist at the default values are not listed; an unstable point shows its growth
rate, not NaN."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from click.testing import CliRunner

from mechbook.app.cli import main
from mechbook.engine.analysis import Analysis
from mechbook.engine.existence import existing
from mechbook.errors import MechbookError
from mechbook.model.problem import load_problem

ROOT = Path(__file__).resolve().parents[1]

SPRING_PENDULUM = """\
id: lim-2098
source: a test problem
title: a spring pendulum
parameters:
  m: {{value: 0.5}}
  k: {{value: {k}}}
  l0: {{value: 1.0}}
  g: {{}}
coordinates:
  r: {{doc: length of the spring{domain}}}
  theta: {{doc: angle from the downward vertical}}
particles:
  bob: {{mass: m, position: [r*sin(theta), -r*cos(theta)]}}
gravity: {{}}
springs:
  - {{k: k, length: r, natural_length: l0}}
"""


def _tree(tmp: Path, k: float = 20.0, domain: str = ", positive: true") -> Path:
    shutil.copy(ROOT / "books.yaml", tmp / "books.yaml")
    path = tmp / "problems" / "lim" / "2098.yaml"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(SPRING_PENDULUM.format(k=k, domain=domain), "utf-8")
    return path


def test_a_spring_pendulum_lists_only_r_positive_equilibria(tmp_path):
    analysis = Analysis(load_problem(_tree(tmp_path)))
    r = analysis.system().q[0]
    assert r.is_positive
    points = analysis.equilibria().symbolic
    assert len(points) == 2 and all(p[r] != 0 for p in points)
    values = analysis.problem.values()
    assert all(float(p[r].subs(values)) > 0 for p in points)
    # without the domain, SymPy also returns the polar origin r = 0 with
    # theta = acos(-k*l0/(g*m)), complex at the default values: not listed, and said why
    plain = Analysis(load_problem(_tree(tmp_path, domain="")))
    raw = plain.equilibria().symbolic
    assert any(p[plain.system().q[0]] == 0 for p in raw)
    kept, gone = existing(raw, plain.system(), plain.problem.values())
    assert len(kept) == 2 and len(gone) == 2
    assert all("not real at the default values" in why for why in gone)


def test_solve_lists_the_equilibria_that_exist_and_says_which_it_left_out(tmp_path):
    _tree(tmp_path, k=2.0)  # l0 - m*g/k < 0: the hanging-upside-down point has r < 0
    result = CliRunner().invoke(main, ["--root", str(tmp_path), "solve", "lim-2098",
                                       "--no-simplify"])
    assert result.exit_code == 0, result.output
    listed = result.output.split("equilibria:\n", 1)[1].splitlines()[0]
    assert "theta: 0" in listed and "pi" not in listed
    assert "r = -g*m/k + l0 is outside r > 0" in result.output
    assert "nan" not in result.output.lower()


def test_an_unstable_point_shows_its_growth_rate(tmp_path):
    _tree(tmp_path)
    result = CliRunner().invoke(main, ["--root", str(tmp_path), "solve", "lim-2098",
                                       "--no-simplify"])
    assert result.exit_code == 0, result.output
    # about theta = pi the swing mode grows like e^(λt), λ = sqrt(g/r - k/m)... at the
    # defaults sqrt(-K22/M22) with K22 = -m*g*r*, M22 = m*r*²
    m, k, l0, g = 0.5, 20.0, 1.0, 9.81
    rstar = l0 - m * g / k
    rate = np.sqrt(g / rstar)
    found = re.search(r"grows like e\^\(([0-9.e+-]+) t\)", result.output)
    assert found, result.output
    assert float(found.group(1)) == pytest.approx(rate, rel=1e-9)
    assert "[nan" not in result.output and "nan]" not in result.output


def test_the_numeric_search_looks_only_inside_the_domain(tmp_path):
    analysis = Analysis(load_problem(_tree(tmp_path)))
    found = analysis.equilibria().numeric(analysis.problem.values(),
                                          {analysis.system().q[0]: (-2.0, 2.0)})
    assert found and all(x[0] > 0 for x in found)


def test_random_states_are_drawn_inside_the_domain(tmp_path):
    from mechbook.verify.compare import Sampler

    analysis = Analysis(load_problem(_tree(tmp_path)))
    r, theta = analysis.system().q
    sampler = Sampler(analysis.problem.values())
    draws = [sampler.draw([r, theta]) for _ in range(200)]
    assert all(float(d[r]) > 0 for d in draws)
    assert any(float(d[theta]) < 0 for d in draws)  # an undeclared one keeps both signs


def test_a_simulation_stops_where_a_coordinate_leaves_its_domain(tmp_path):
    from mechbook.numerics.simulate import simulate

    analysis = Analysis(load_problem(_tree(tmp_path)))
    run = simulate(analysis, init={"r": "0.3", "rdot": "-8", "theta": "0"}, t_span=(0, 5),
                   points=501)
    assert run.trajectory.t[-1] < 1.0
    assert np.all(run.trajectory.q[0] > 0)
    assert any("left the domain r > 0" in n for n in run.notes), run.notes
    with pytest.raises(MechbookError, match="outside the coordinate's domain r > 0"):
        simulate(analysis, init={"r": "-0.5"}, t_span=(0, 1))


def test_a_range_and_its_text(tmp_path):
    path = _tree(tmp_path, domain=", range: [0, 3*l0]")
    analysis = Analysis(load_problem(path))
    sys = analysis.system()
    dom = sys.domains[sys.q[0]]
    assert dom.text == "0 <= r <= 3*l0"
    values = analysis.problem.values()
    assert dom.contains(2.9, values) and not dom.contains(3.1, values)
    assert not dom.contains(-0.1, values)
    assert sys.q[0].is_real and sys.q[0].is_positive is None


def test_a_bad_range_bound_names_its_line(tmp_path):
    path = _tree(tmp_path, domain=", range: [0, 3*ll0]")
    with pytest.raises(MechbookError) as info:
        Analysis(load_problem(path)).system()
    assert "2098.yaml:10" in str(info.value) and "did you mean 'l0'" in str(info.value)


def test_the_domain_is_kept_by_the_symbol_so_answers_share_it(tmp_path):
    analysis = Analysis(load_problem(_tree(tmp_path)))
    r = analysis.system().names["r"]
    assert r is analysis.system().q[0] and r.is_positive
    assert sp.sqrt(r**2) == r
