"""A named first integral of a constrained system is compared with the engine's on the
constraint manifold (issue 41): off it the two differ, and the comparison must not look
there. Every key here is derived in the docstring of its test."""

from __future__ import annotations

import pytest
from constrained_systems import check, key

# A uniform disk (mass m, radius R) rolling on a line: x its centre, phi its turn. T is the
# centre's m ẋ²/2 and the spin's (mR²/2) φ̇²/2; with no potential.
DISK = """\
id: lim-NUM
source: a disk rolling on a line
title: uniform disk rolling without slipping on a line
parameters:
  m: {value: 1.3}
  R: {value: 0.4}
coordinates:
  x: {}
  phi: {}
kinetic: m*xdot**2/2 + m*R**2*phidot**2/4
potential: "0"
"""
ROLLS = """\
velocity_constraints:
  - {name: roll, expr: "xdot - R*phidot"}
"""
HOLDS = """\
constraints:
  - {name: roll, expr: "x - R*phi"}
"""

# A Chaplygin sleigh: a body of mass m and moment J about its centre of mass G, which sits
# a distance a ahead of the blade's contact point (x, y) along the blade's direction θ; the
# blade forbids motion of the contact point across it (−ẋ sin θ + ẏ cos θ = 0).
# G moves with (ẋ − aθ̇ sin θ, ẏ + aθ̇ cos θ).
SLEIGH = """\
id: lim-NUM
source: a Chaplygin sleigh
title: Chaplygin sleigh, its centre of mass a ahead of the blade
parameters:
  m: {value: 2.0}
  J: {value: 0.7}
  a: {value: 0.3}
coordinates:
  x: {}
  y: {}
  theta: {}
kinetic: >-
  m*((xdot - a*thetadot*sin(theta))**2 + (ydot + a*thetadot*cos(theta))**2)/2
  + J*thetadot**2/2
potential: "0"
velocity_constraints:
  - {name: blade, expr: "-xdot*sin(theta) + ydot*cos(theta)"}
"""


def _energy(tmp_path, num, problem, book):
    parts = ("  - part: E\n    quantity: conserved\n    cite: derived\n"
             f"    book: \"E = {book}\"\n")
    return check(tmp_path, num, problem, key(parts))["E"]


@pytest.mark.parametrize("constraint", [ROLLS, HOLDS], ids=["velocity", "holonomic"])
def test_rolling_disk_energy_on_the_manifold(tmp_path, constraint):
    """On the manifold φ̇ = ẋ/R, so E = T = mẋ²/2 + mR²(ẋ/R)²/4 = 3mẋ²/4 (off it, where
    φ̇ ≠ ẋ/R, the engine's energy function is not this). A factor wrong by 1e-6, and the
    centre's energy alone (mẋ²/2, the spin forgotten), must fail."""
    problem = DISK + constraint
    out = _energy(tmp_path, "9501", problem, "3*m*xdot**2/4")
    assert out.status == "pass", out.detail
    for wrong in ("3*m*xdot**2/4*(1 + 1/10**6)", "m*xdot**2/2", "3*m*xdot**2/4 + m*x**2"):
        out = _energy(tmp_path, "9501", problem, wrong)
        assert out.status == "fail", (wrong, out.detail)
        assert "at {" in out.detail, out.detail  # names the point


def test_sleigh_energy_on_the_manifold(tmp_path):
    """T = m|v_G|²/2 + Jω²/2 with v_G = (ẋ − aω sin θ, ẏ + aω cos θ), ω = θ̇:
    |v_G|² = ẋ² + ẏ² + 2aω w + a²ω², w = −ẋ sin θ + ẏ cos θ the velocity across the blade.
    The blade makes w = 0 and ẋ² + ẏ² = u², u = ẋ cos θ + ẏ sin θ, so on the manifold
    E = T = (m u² + (J + m a²) ω²)/2. Off it the engine's energy function has m(w² + 2aωw)/2
    more, whose gradient does not vanish where w = 0 (its ∂/∂w is maω)."""
    u = "(xdot*cos(theta) + ydot*sin(theta))"
    out = _energy(tmp_path, "9502", SLEIGH, f"(m*{u}**2 + (J + m*a**2)*thetadot**2)/2")
    assert out.status == "pass", out.detail
    out = _energy(tmp_path, "9502", SLEIGH,
                  f"(m*{u}**2 + (J + m*a**2)*thetadot**2*(1 + 1/10**6))/2")
    assert out.status == "fail", out.detail
    out = _energy(tmp_path, "9502", SLEIGH, f"(m*{u}**2 + J*thetadot**2)/2")
    assert out.status == "fail", out.detail  # the moment about G, not about the blade
