"""normal_coordinates' frequencies, a zero one included, decided at 50 digits.

Three beads on a ring of radius r, masses m, M, m, joined by three springs of stiffness k
(angles θ1, θ2, θ3): T = r²(m θ̇1² + M θ̇2² + m θ̇3²)/2, V = k r²((θ2 − θ1)² + (θ3 − θ2)² +
(θ1 − θ3)²)/2. Derived here: K = k r²·[[2, −1, −1], [−1, 2, −1], [−1, −1, 2]],
M = r²·diag(m, M, m). The rigid rotation u = (1, 1, 1) has Ku = 0, so its normal
coordinate is c = Mu ∝ m θ1 + M θ2 + m θ3 with ω = 0. u = (1, 0, −1): Ku = 3k r² u, so
θ1 − θ3 (c = r²m(θ1 − θ3)) has ω² = 3k/m. The third, u = (1, −2m/M, 1): Ku = k r²(1 +
2m/M)(1, −2, 1) and Mu = r²m(1, −2, 1), so ω² = k(2m + M)/(mM), and its form is
c = Mu ∝ θ1 − 2θ2 + θ3.

The stiff springs (k = 400) make the zero mode's double-precision Rayleigh quotient a
rounding of ~1e-16·k/m, whose square root, ~1e-7 when it comes out positive, is past the
comparison's 1e-8: that is how lim-2047's true ω = 0 failed on an AVX-512 machine. The
frequency is now taken from the quotient at 50 digits.
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
import sympy as sp
from ruamel.yaml import YAML
from systems import load_analysis

from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

RING = """\
id: lim-9711
source: test
title: three beads on a ring joined by stiff springs
parameters:
  m: {value: 1.0}
  M: {value: 3.0}
  k: {value: 400.0}
  r: {value: 1.3}
coordinates:
  theta1: {}
  theta2: {}
  theta3: {}
kinetic: r**2*(m*theta1dot**2 + M*theta2dot**2 + m*theta3dot**2)/2
potential: k*r**2*((theta2 - theta1)**2 + (theta3 - theta2)**2 + (theta1 - theta3)**2)/2
"""

RIGHT = [("m*theta1 + M*theta2 + m*theta3", "0"),
         ("theta1 - theta3", "sqrt(3*k/m)"),
         ("theta1 - 2*theta2 + theta3", "sqrt(k*(2*m + M)/(m*M))")]


def _check(tmp_path, forms, parts: int = 1):
    """Each part is drawn at its own 5 points."""
    analysis = load_analysis(tmp_path, RING, "9711")
    data = {"problem": "lim-9711", "source": "test",
            "parts": [{"part": f"n{j}", "cite": "derived", "quantity": "normal_coordinates",
                       "about": {"theta1": 0, "theta2": 0, "theta3": 0},
                       "book": [{"coordinate": c, "frequency": w} for c, w in forms]}
                      for j in range(parts)]}
    path = tmp_path / "key.yaml"
    with path.open("w") as fh:
        YAML().dump(data, fh)
    return check_problem(analysis, load_answers(path))


def test_a_zero_frequency_of_a_stiff_system_passes(tmp_path):
    """Eight parts, 40 points: in double precision the rows of K·u cancel exactly at some
    points and not at others (u = M⁻¹c rounds apart in its entries); 50 digits at all."""
    outs = _check(tmp_path, RIGHT, parts=8)
    assert [o.status for o in outs] == ["pass"] * 8, [o.detail for o in outs]


@pytest.mark.parametrize("i, wrong", [
    (0, "1e-6"),                                   # the rigid rotation is not at rest
    (1, "sqrt(3*k/m)*1.01"),
    (1, "sqrt(3*k/m)*(1 + 1e-6)"),
    (2, "sqrt(k*(2*m + M)/(m*M))*(1 - 1e-6)"),
    (2, "sqrt(3*k/m)"),                            # the other mode's frequency
])
def test_a_wrong_frequency_fails(tmp_path, i, wrong):
    forms = list(RIGHT)
    forms[i] = (forms[i][0], wrong)
    out = _check(tmp_path, forms)[0]
    assert out.status == "fail", out.detail
    assert "frequency" in out.detail, out.detail


def test_the_zero_modes_frequency_is_free_of_rounding(tmp_path):
    """At 60 points of the ring, the rigid rotation's ω from the 50-digit quotient is below
    1e-20; the same quotient in double precision has a root past the comparison's 1e-8 at
    some of them (where its rounding comes out positive), as lim-2047's did."""
    analysis = load_analysis(tmp_path, RING, "9711")
    system = analysis.system(None)
    lin = analysis.linear(None, {q: 0 for q in system.q})
    s = {x.name: x for x in system.numeric_values()}
    form = sp.Matrix([s["m"], s["M"], s["m"]])
    rng = random.Random(2047)
    worst_double = 0.0
    for _ in range(60):
        pt = {s["m"]: rng.uniform(0.5, 2), s["M"]: rng.uniform(0.5, 4),
              s["k"]: rng.uniform(100, 1000), s["r"]: rng.uniform(0.5, 2)}
        M, _, K = lin.matrices(pt)
        u = np.linalg.solve(M, np.array([float(x.subs(pt)) for x in form]))
        worst_double = max(worst_double, math.sqrt(max(float(u @ K @ u / (u @ M @ u)), 0)))
        assert lin.mode_frequency(form, pt) < 1e-20
    assert worst_double > 1e-8, worst_double
