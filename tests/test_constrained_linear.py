"""Small oscillations on a constraint manifold (mechbook.engine.constrained), against closed
forms, through the checker.

- Two particles of mass m at x and y tied by x − y = 0, potential k x²/2: one degree of
  freedom of mass 2m and stiffness k, ω = √(k/2m). The unconstrained system's [0, √(k/m)]
  must fail.
- A pendulum written in Cartesian x, y with x² + y² = l²: at the bottom ω = √(g/l), stable;
  at the top unstable. All of the stiffness comes from the constraint force turning with
  the circle (the multiplier times the constraint's curvature).
- A constraint that moves with time is refused (unsupported),
  never computed as if it were absent.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from ruamel.yaml import YAML
from systems import load_analysis

from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

TIED = """\
id: lim-9101
source: test
title: two particles tied together
parameters:
  m: {value: 1.3}
  k: {value: 2.1}
coordinates:
  x: {}
  y: {}
particles:
  a: {mass: m, position: [x]}
  b: {mass: m, position: [y]}
potential: k*x**2/2
constraints:
  - {name: c, expr: x - y}
"""

CARTESIAN = """\
id: lim-9102
source: test
title: a pendulum in Cartesian coordinates
parameters:
  m: {value: 0.7}
  l: {value: 1.9}
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

MOVING = """\
id: lim-9103
source: test
title: a bead on a wire pulled along at a constant speed
parameters:
  m: {value: 1.0}
  k: {value: 2.0}
  v: {value: 0.5}
coordinates:
  x: {}
  y: {}
particles:
  a: {mass: m, position: [x]}
  b: {mass: m, position: [y]}
potential: k*x**2/2 + k*y**2/2
constraints:
  - {name: c, expr: x - y - v*t}
"""


def _check(tmp_path: Path, text: str, num: str, parts: list[dict]) -> list:
    analysis = load_analysis(tmp_path, text, num)
    doc = {"problem": f"lim-{num}", "source": "test", "parts": [
        {"part": f"p{i}", "cite": "test", **p} for i, p in enumerate(parts)]}
    path = tmp_path / f"key-{num}.yaml"
    with path.open("w") as f:
        YAML().dump(doc, f)
    return check_problem(analysis, load_answers(path))


@pytest.mark.parametrize("book, status", [
    (["sqrt(k/(2*m))"], "pass"),
    (["sqrt(k/m)"], "fail"),  # the unconstrained system's nonzero frequency
    (["0", "sqrt(k/m)"], "fail"),  # the unconstrained system's pair
    (["(1 + 1/10**6)*sqrt(k/(2*m))"], "fail"),
])
def test_tied_particles_frequency(tmp_path, book, status):
    out = _check(tmp_path, TIED, "9101", [{"quantity": "frequencies", "about": {"x": 0, "y": 0},
                                           "book": book}])[0]
    assert out.status == status, out.detail


def test_tied_particles_mode_shape_moves_both(tmp_path):
    parts = [
        {"quantity": "normal_modes", "about": {"x": 0, "y": 0},
         "book": [{"frequency": "sqrt(k/(2*m))", "shape": {"x": 1, "y": 1}}]},
        {"quantity": "normal_modes", "about": {"x": 0, "y": 0},
         "book": [{"frequency": "sqrt(k/(2*m))", "shape": {"x": 1, "y": -1}}]},
    ]
    good, bad = _check(tmp_path, TIED, "9101", parts)
    assert good.status == "pass", good.detail
    assert bad.status == "fail" and "constraints make it" in bad.detail, bad.detail


def test_tied_particles_equilibrium_and_stability(tmp_path):
    parts = [
        {"quantity": "equilibrium", "book": {"at": {"x": 0, "y": 0}}},
        {"quantity": "equilibrium", "book": {"at": {"x": "1/10", "y": "1/10"}}},  # a force left
        {"quantity": "stability", "about": {"x": 0, "y": 0}, "book": "stable"},
    ]
    eq, off, stab = _check(tmp_path, TIED, "9101", parts)
    assert eq.status == "pass", eq.detail
    assert off.status == "fail", off.detail
    assert stab.status == "pass", stab.detail


@pytest.mark.parametrize("about, book, status", [
    ({"x": 0, "y": "-l"}, ["sqrt(g/l)"], "pass"),
    ({"x": 0, "y": "-l"}, ["sqrt(2*g/l)"], "fail"),
    ({"x": 0, "y": "-l"}, ["0", "sqrt(g/l)"], "fail"),
])
def test_cartesian_pendulum_frequency(tmp_path, about, book, status):
    out = _check(tmp_path, CARTESIAN, "9102", [{"quantity": "frequencies", "about": about,
                                                "book": book}])[0]
    assert out.status == status, out.detail


def test_cartesian_pendulum_stability_bottom_and_top(tmp_path):
    parts = [
        {"quantity": "stability", "about": {"x": 0, "y": "-l"}, "book": "stable"},
        {"quantity": "stability", "about": {"x": 0, "y": "l"}, "book": "unstable"},
        {"quantity": "stability", "about": {"x": 0, "y": "l"}, "book": "stable"},
        {"quantity": "equilibrium", "book": {"at": {"x": "l", "y": 0}}},  # off: a force along
        {"quantity": "equilibrium", "book": {"at": {"x": 0, "y": "2*l"}}},  # off the circle
    ]
    bottom, top, top_wrong, side, off = _check(tmp_path, CARTESIAN, "9102", parts)
    assert bottom.status == "pass", bottom.detail
    assert top.status == "pass", top.detail
    assert top_wrong.status == "fail"
    assert side.status == "fail", side.detail
    assert off.status == "fail", off.detail


def test_cartesian_pendulum_engine_values(tmp_path):
    analysis = load_analysis(tmp_path, CARTESIAN, "9102")
    eq = analysis.equilibria()
    points = eq.symbolic
    assert len(points) == 2
    values = analysis.problem.values()
    g, l = values[next(s for s in values if s.name == "g")], 1.9  # noqa: E741
    bottom = next(p for p in points if p[analysis.system().q[1]].could_extract_minus_sign())
    lin = analysis.linear(None, bottom)
    w = lin.numeric_frequencies(values)
    assert [str(q) for q in lin.q] == ["x"]
    assert np.allclose(w, [math.sqrt(g / l)], rtol=1e-12)
    found = eq.numeric(values)
    assert sorted(round(float(p[1]), 9) for p in found) == [-1.9, 1.9]


def test_a_moving_constraint_is_unsupported_not_ignored(tmp_path):
    out = _check(tmp_path, MOVING, "9103", [{"quantity": "frequencies",
                                             "about": {"x": 0, "y": 0},
                                             "book": ["sqrt(2*k/(2*m))"]}])[0]
    assert out.status == "unsupported", (out.status, out.detail)
    assert "moving" in out.detail


@pytest.mark.parametrize("text, num, about, book", [
    (TIED, "9101", {"x": 0, "y": 0}, ["sqrt(k/(2*m))"]),
    (CARTESIAN, "9102", {"x": 0, "y": "-l"}, ["sqrt(g/l)"]),
])
def test_frequency_crosscheck_simulates_on_the_manifold(tmp_path, text, num, about, book):
    """The cross-check starts the full nonlinear system (with its multipliers) on the
    constraints, displaced along the mode, and measures the engine's frequency."""
    from mechbook.crosscheck import crosscheck_problem

    analysis = load_analysis(tmp_path, text, num)
    doc = {"problem": f"lim-{num}", "source": "test", "parts": [
        {"part": "a", "cite": "test", "quantity": "frequencies", "about": about, "book": book}]}
    path = tmp_path / "key.yaml"
    with path.open("w") as f:
        YAML().dump(doc, f)
    checks = [c for c in crosscheck_problem(analysis, load_answers(path))
              if c.kind == "frequencies"]
    assert checks and all(c.status == "pass" for c in checks), checks
    assert all(m["relative_error"] < 1e-7 for c in checks for m in c.modes)
