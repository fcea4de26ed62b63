"""A flat (non-Morse) equilibrium is one equilibrium (mechbook.engine.flat_roots, used by
engine.screen and Equilibria.numeric), and two true equilibria, however close, stay two.

For V = c·x⁴ Newton's method converges linearly on the force −4c·x³ and stopped at
x = ±1.6e-5, ±1.8e-5 beside 0 (residuals below 1e-13): the modes cross-check called each
"not an equilibrium" and `check` exited 1 while every part passed."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from click.testing import CliRunner
from systems import load_analysis

from mechbook.app.cli import main
from mechbook.engine.certified_count import certified_count
from mechbook.engine.flat_roots import one_root, polish, unresolved
from mechbook.engine.screen import screen

ROOT = Path(__file__).resolve().parents[1]


def well(potential: str, coords: tuple[str, ...] = ("x",), d: float = 1.0) -> str:
    lines = "\n".join(f"  {c}: {{}}" for c in coords)
    return f"""\
id: lim-9601
source: test
title: a particle in a polynomial well
parameters:
  m: {{value: 1.0}}
  c: {{value: 2.0}}
  d: {{value: {d}}}
coordinates:
{lines}
particles:
  p: {{mass: m, position: [{', '.join(coords)}]}}
potential: {potential}
"""


def screened(tmp_path, text, periodic: bool = False) -> list[np.ndarray]:
    an = load_analysis(tmp_path, text, "9601")
    found = screen(an.equilibria(), an.system().numeric_values()).found
    if not periodic:  # the engine's other search (which keeps points a turn apart) agrees
        assert len(an.equilibria().numeric(an.system().numeric_values())) == len(found)
    return sorted((f.point for f in found), key=lambda p: tuple(p))


@pytest.mark.parametrize("potential, coords", [
    ("c*x**4", ("x",)),
    ("c*x**4 + y**2", ("x", "y")),      # flat along x only
    ("c*(x**2 + y**2)**2", ("x", "y")),  # flat in every direction (41 points before)
    ("c*x**6 + c*y**4", ("x", "y")),
])
def test_a_flat_minimum_is_one_equilibrium(tmp_path, potential, coords):
    points = screened(tmp_path, well(potential, coords))
    assert len(points) == 1
    assert np.max(np.abs(points[0])) < 1e-12


def test_a_flat_minimum_with_cancellation_is_one(tmp_path):
    """V = c(1 − cos x)²: the force 2c(1 − cos x) sin x is computed with cancellation,
    so near 0 it is noise below ~3e-8; one equilibrium there (and the maximum at ±π,
    which the screen counts once: a full turn apart)."""
    points = screened(tmp_path, well("c*(1 - cos(x))**2"), periodic=True)
    assert len(points) == 2
    assert abs(points[1][0]) < 1e-7 and abs(abs(points[0][0]) - np.pi) < 1e-12


@pytest.mark.parametrize("d", [1e-3, 1e-5])
def test_a_true_pair_of_close_equilibria_stays_two(tmp_path, d):
    """V = c(x² − d²)²: minima at ±d and a maximum at 0 between them, however small d.
    (Before, d = 1e-5 gave ±1.8e-5, ±2.0e-5 and 0: four ghosts and no true minimum.)"""
    points = screened(tmp_path, well("c*(x**2 - d**2)**2", d=d))
    xs = [p[0] for p in points]
    assert len(xs) == 3
    assert xs[0] == pytest.approx(-d, rel=1e-10) and xs[2] == pytest.approx(d, rel=1e-10)
    assert abs(xs[1]) < 1e-12 * d


def test_polish_and_what_the_arithmetic_resolves():
    x = sp.Symbol("x")
    cond = [8 * x**3]  # the force of V = 2x⁴, a triple root at 0
    def fj(v):
        return np.array([8 * v[0] ** 3]), np.array([[24 * v[0] ** 2]])

    assert abs(polish(fj, np.array([1.8e-5]))[0]) < 1e-20  # linear convergence sped up
    # no root near: exp(-x) only fades; the polish stops and keeps the start
    fade = polish(lambda v: (np.exp(-v), -np.exp(-v)[None, :]), np.array([30.0]))
    assert fade[0] == 30.0
    assert unresolved(cond, {x: sp.Float(1.8e-5, 30)}) is False  # a ghost: force resolved
    assert unresolved(cond, {x: sp.Float(0, 30)}) is True
    # cancellation: 1 - cos(x) at 1e-9 is below double precision's rounding of its terms
    noisy = [(1 - sp.cos(x)) * sp.sin(x)]
    assert one_root(noisy, [x], {}, np.array([-1e-9]), np.array([1e-9]))
    assert not one_root(noisy, [x], {}, np.array([-1e-3]), np.array([1e-3]))


def test_the_count_of_a_close_pair_is_certified():
    """Real-root isolation at a rational point: x³ − x/10⁶ has 3 roots in (−1, 1). The
    interval refinement once counted the root at 0 (a neighbour's, on a shared end) and
    gave up on 10⁻³."""
    x, c, d = sp.symbols("x c d")
    cond = [4 * c * x**3 - 4 * c * d**2 * x]
    got = certified_count(cond, [x], {c: 2.0, d: 0.001}, [{x: (-1, 1)}])
    assert got is not None and got[0] == 3
    assert certified_count(cond, [x], {c: 2.0, d: 0.001}, [{x: (0.0005, 1)}])[0] == 1


def _tree(tmp_path: Path, parts: list[dict], problem: str | None = None) -> Path:
    (tmp_path / "problems" / "lim").mkdir(parents=True)
    (tmp_path / "answers" / "lim").mkdir(parents=True)
    shutil.copy(ROOT / "books.yaml", tmp_path / "books.yaml")
    (tmp_path / "problems" / "lim" / "9601.yaml").write_text(problem or well("c*x**4"))
    (tmp_path / "answers" / "lim" / "9601.yaml").write_text(json.dumps(
        {"problem": "lim-9601", "source": "test", "parts": parts}))
    return tmp_path


def test_a_quartic_well_checks_with_exit_0(tmp_path):
    count = {"part": "n", "cite": "t", "quantity": "equilibrium_count",
             "search": {"x": [-1, 1]}, "book": 1}
    lagrangian = {"part": "a", "cite": "t", "quantity": "lagrangian",
                  "book": "m*xdot**2/2 - c*x**4"}
    tree = _tree(tmp_path / "good", [lagrangian, count])
    result = CliRunner().invoke(main, ["--root", str(tree), "check", "lim-9601",
                                       "--no-store", "--serial", "--format", "json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    problem = doc["problems"][0]
    assert [p["status"] for p in problem["parts"]] == ["pass", "pass"]
    assert "exactly 1" in problem["parts"][1]["power"]
    assert doc["summary"]["crosschecks"]["fail"] == 0
    wrong = _tree(tmp_path / "wrong", [lagrangian, dict(count, book=2)])
    result = CliRunner().invoke(main, ["--root", str(wrong), "check", "lim-9601",
                                       "--no-store", "--serial"])
    assert result.exit_code == 1


def test_a_close_pair_checks_and_each_minimum_is_simulated(tmp_path):
    """The modes cross-check swings each minimum of V = c(x² − d²)², d = 1e-3: a swing of
    1e-3 leaves the well (no oscillation to measure: an error before), so the amplitude
    shrinks until the motion stays in it; ω² = V''(±d)/m = 8c·d²."""
    count = {"part": "n", "cite": "t", "quantity": "equilibrium_count",
             "search": {"x": [-1, 1]}, "book": 3}
    tree = _tree(tmp_path, [count], well("c*(x**2 - d**2)**2", d=1e-3))
    result = CliRunner().invoke(main, ["--root", str(tree), "check", "lim-9601",
                                       "--no-store", "--serial", "--format", "json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["problems"][0]["parts"][0]["status"] == "pass"
    assert doc["summary"]["crosschecks"]["fail"] == doc["summary"]["crosschecks"]["error"] == 0
    assert doc["summary"]["crosschecks"]["pass"] >= 3  # Newton's law and both minima
