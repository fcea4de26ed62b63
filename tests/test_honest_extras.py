"""Issue 41's smaller items: a symbolic frequency list in the order of the numeric one, a
failing frequency part that names its point, and the engine's own equilibria cross-checked
only inside the coordinates' domains. Reference values are derived in the docstrings."""

from __future__ import annotations

import numpy as np
import sympy as sp
from ruamel.yaml import YAML
from systems import load_analysis

from mechbook.crosscheck.points import admissible, engine_linear_systems
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem

# three uncoupled masses on springs: ω² = k3/m, k1/m, k2/m for x, y, z (defaults 9, 1, 4)
THREE = """\
id: lim-9701
source: test
title: three uncoupled masses on springs
parameters:
  m: {value: 1.0}
  k1: {value: 1.0}
  k2: {value: 4.0}
  k3: {value: 9.0}
coordinates:
  x: {}
  y: {}
  z: {}
kinetic: m*(xdot**2 + ydot**2 + zdot**2)/2
potential: (k3*x**2 + k1*y**2 + k2*z**2)/2
"""

# a bead on a line in a double well V = k(r² − a²)²/4: equilibria r = 0 (unstable) and
# r = ±a (stable, ω² = 2ka²/m); with r declared positive only r = a is a state
WELL = """\
id: lim-9702
source: test
title: bead in a double well, its coordinate declared positive
parameters:
  m: {value: 1.0}
  k: {value: 2.0}
  a: {value: 0.62}
coordinates:
  r: {positive: true}
kinetic: m*rdot**2/2
potential: k*(r**2 - a**2)**2/4
"""


def test_symbolic_frequencies_come_in_the_numeric_order(tmp_path):
    """The secular equation's roots come in SymPy's order; the list is the numeric one's,
    ascending at the system's values: 1, 2, 3."""
    analysis = load_analysis(tmp_path, THREE, "9701")
    sys = analysis.system(None)
    lin = analysis.linear(None, {q: 0 for q in sys.q})
    values = sys.numeric_values()
    symbolic = [float(sp.N(w.subs(values))) for w in lin.frequencies]
    assert symbolic == sorted(symbolic) and np.allclose(symbolic, [1, 2, 3]), symbolic
    assert np.allclose(symbolic, lin.numeric_frequencies(values))


def test_a_failing_frequency_part_names_its_point(tmp_path):
    analysis = load_analysis(tmp_path, THREE, "9701")
    data = {"problem": "lim-9701", "source": "test",
            "parts": [{"part": "w", "cite": "derived", "quantity": "frequencies",
                       "about": {"x": 0, "y": 0, "z": 0},
                       "book": ["sqrt(k1/m)", "sqrt(k2/m)", "sqrt(1.01*k3/m)"]}]}
    path = tmp_path / "key.yaml"
    with path.open("w") as fh:
        YAML().dump(data, fh)
    out = check_problem(analysis, load_answers(path))[0]
    assert out.status == "fail", out.detail
    assert " at {" in out.detail and "k3=" in out.detail, out.detail


def test_engine_equilibria_outside_a_domain_are_not_cross_checked(tmp_path):
    """r = −a is an equilibrium of the formula but not a state of the problem (r > 0)."""
    analysis = load_analysis(tmp_path, WELL, "9702")
    sys = analysis.system(None)
    r = sys.q[0]
    assert not admissible(sys, {r: -0.62}, {}) and admissible(sys, {r: 0.62}, {})
    found = engine_linear_systems(analysis, None, {})
    points = [float(sp.N(lin.point[r])) for lin, _ in found]
    assert points and all(p > 0 for p in points), points
