"""Issue 44, item 3: velocity constraints that are not linear in the velocities are refused
at their line by `validate` (they ended in a raw NonInvertibleMatrixError at check time),
and a linear one whose coefficients are tiny is accepted and checked."""

from __future__ import annotations

import shutil

import pytest
from constrained_systems import SLEIGH, write_tree
from hostile import ROOT, check, run

BLADE = '"-xdot*sin(theta) + ydot*cos(theta)"'

# a mass at (x, z) on the rail z = l, and a coordinate y without inertia that follows x by
# the velocity constraint c·(ẏ − ẋ) = 0, c = 1e-12: L = m(ẋ² + ż²)/2 − k x²/2 − k y²/2 and
# the multiplier force Aᵀλ, A = c(−1, 1, 0), give 0 = −k y + cλ and m ẍ = −k x − cλ, so
# m ẍ + k (x + y) = 0 whatever c ≠ 0; the freedoms are 3 − 1 = 2 of the configuration and
# 2 − 1 = 1 of the velocity.
FOLLOWER = """\
id: lim-NUM
source: a test
title: a mass whose partner coordinate follows it by a velocity constraint
parameters:
  m: {value: 1.5}
  k: {value: 2.0}
  l: {value: 1.0}
coordinates:
  x: {}
  y: {}
  z: {}
particles:
  a:
    mass: m
    position: [x, z]
potential: "k*x**2/2 + k*y**2/2"
constraints:
  - {name: rail, expr: "z - l"}
velocity_constraints:
  - {name: follow, expr: "SCALE*(ydot - xdot)"}
"""
FOLLOWER_KEY = """\
problem: lim-NUM
source: derived in tests/test_hostile_constraints.py
parts:
  - part: a
    cite: freedoms
    quantity: mode_count
    book: {configuration: 2, velocity: 1}
  - part: b
    cite: the equation of motion of x
    quantity: eom
    book: ["m*xddot + k*(x + y) = 0"]
"""


@pytest.mark.parametrize("expr", ["Abs(xdot)", "sign(xdot)*xdot", "sqrt(xdot**2)",
                                  "xdot*Abs(ydot) - ydot", "cos(xdot) - 1",
                                  "exp(xdot) - 1", "xdot**2 - ydot", "1/xdot",
                                  "(xdot**2)**(1/2)*sin(theta)"])
def test_a_constraint_not_linear_in_the_velocities_is_refused_at_its_line(tmp_path, expr):
    ppath, _ = write_tree(tmp_path, "9611", SLEIGH.replace(BLADE, f'"{expr}"'),
                          "problem: lim-NUM\nsource: x\nparts: []\n")
    shutil.copy(ROOT / "books.yaml", tmp_path / "books.yaml")
    line = 1 + SLEIGH.splitlines().index(f"  - {{name: blade, expr: {BLADE}}}")
    res = run("--root", tmp_path, "validate", ppath)
    assert res.exit_code == 1, res.output
    assert f"9611.yaml:{line}: velocity_constraints/0/expr" in res.output, res.output
    assert "not linear in the velocities" in res.output
    assert "Traceback" not in res.output and "NonInvertible" not in res.output


@pytest.mark.parametrize("expr", ["-xdot*sin(theta) + ydot*cos(theta)",
                                  "xdot*(sin(theta)**2 + cos(theta)**2) - ydot",
                                  "(xdot + ydot)**2 - (xdot - ydot)**2 - 4*xdot*ydot + xdot"])
def test_a_linear_constraint_in_any_spelling_is_accepted(tmp_path, expr):
    ppath, _ = write_tree(tmp_path, "9612", SLEIGH.replace(BLADE, f'"{expr}"'),
                          "problem: lim-NUM\nsource: x\nparts: []\n")
    shutil.copy(ROOT / "books.yaml", tmp_path / "books.yaml")
    res = run("--root", tmp_path, "validate", ppath)
    assert res.exit_code == 0, res.output


@pytest.mark.parametrize("scale", ["1e-12", "1", "1e12"])
def test_a_tiny_coefficient_is_no_degeneracy(tmp_path, scale):
    write_tree(tmp_path, "9613", FOLLOWER.replace("SCALE", scale), FOLLOWER_KEY)
    shutil.copy(ROOT / "books.yaml", tmp_path / "books.yaml")
    res = run("--root", tmp_path, "validate", tmp_path / "problems" / "lim" / "9613.yaml")
    assert res.exit_code == 0, res.output
    res = check(tmp_path, "lim-9613", "--no-store", "--format", "json")
    assert res.exit_code == 0, res.output
    assert res.output.count('"status": "pass"') >= 2, res.output
