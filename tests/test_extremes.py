"""Normal frequencies stay accurate at extreme parameter ratios (against 50-digit closed forms)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from mechbook.engine.analysis import Analysis
from mechbook.model.catalog import problem_path
from mechbook.model.problem import load_problem

ROOT = Path(__file__).resolve().parents[1]


def _reference(freqs, values) -> np.ndarray:
    exact = {k: sp.Rational(v) for k, v in values.items()}
    return np.sort([float(sp.re(sp.N(f.subs(exact), 50))) for f in freqs])


@pytest.mark.parametrize("pid, name, factor", [
    ("lim-2037", "omega0", 1e-8),   # magnetron frequency ~1e-16 next to the cyclotron one
    ("lim-2036", "m1", 1e-8),       # nearly singular mass matrix
    ("lim-2036", "l2", 1e8),
    ("lim-2028", "m", 1e8),
    ("lim-2033", "k", 1e8),
])
def test_frequencies_at_extreme_ratios(pid, name, factor):
    problem = load_problem(problem_path(pid, ROOT))
    analysis = Analysis(problem)
    lin = analysis.linear(None, analysis.default_point())
    values = dict(problem.values())
    sym = problem.parameters[name].symbol
    values[sym] = values[sym] * factor
    ref = _reference(list(lin.frequencies), values)
    got = np.sort(lin.numeric_frequencies(values))
    nonzero = ref > 0
    assert np.all(np.abs(got[nonzero] - ref[nonzero]) <= 1e-10 * ref[nonzero])
    assert np.all(got[~nonzero] == 0)


# A chain: a wall, a soft spring k1, mass m1, a stiff spring k2, mass m2. det(K − w·M) = 0
# with M = diag(m1, m2), K = [[k1 + k2, −k2], [−k2, k2]] gives
# m1·m2·w² − (m1·k2 + m2·(k1 + k2))·w + k1·k2 = 0, so w₋·w₊ = k1·k2/(m1·m2) and
# w₊ + w₋ = (m1·k2 + m2·(k1 + k2))/(m1·m2): w₋ = k1·k2/(m1·m2·w₊), free of cancellation.
CHAIN = """\
id: lim-9801
source: test
title: two masses on a soft and a stiff spring
parameters:
  m1: {value: 2.0}
  m2: {value: 0.5}
  k1: {value: 1.0}
  k2: {value: 3.0}
coordinates:
  x1: {}
  x2: {}
particles:
  a: {mass: m1, position: [x1]}
  b: {mass: m2, position: [x2]}
potential: k1*x1**2/2 + k2*(x2 - x1)**2/2
"""


def _chain_frequencies(m1, m2, k1, k2) -> list[float]:
    import mpmath

    with mpmath.workdps(50):
        m1, m2, k1, k2 = (mpmath.mpf(v) for v in (m1, m2, k1, k2))
        s = (m1 * k2 + m2 * (k1 + k2)) / (m1 * m2)
        wp = (s + mpmath.sqrt(s**2 - 4 * k1 * k2 / (m1 * m2))) / 2
        wm = k1 * k2 / (m1 * m2 * wp)
        return [float(mpmath.sqrt(wm)), float(mpmath.sqrt(wp))]


@pytest.mark.parametrize("k1", [1e-8, 1e-12, 3e-16])
def test_a_soft_spring_beside_a_stiff_one_is_no_zero_mode(tmp_path, k1):
    """The zero decision is the arithmetic's, not a threshold: ω₋/ω₊ down to 1e-8 (ω²
    ratio 1e-16, where double precision cannot see it) comes out to 1e-10; ZERO_TOL had
    set every one of these to 0 (lim-2042 spring at A × 1e-8 was the book's case)."""
    from systems import load_analysis

    an = load_analysis(tmp_path, CHAIN, "9801")
    lin = an.linear(None, {an.system().q[0]: 0, an.system().q[1]: 0})
    values = {s: (k1 if s.name == "k1" else v) for s, v in an.system().numeric_values().items()}
    got = lin.numeric_frequencies(values)
    want = _chain_frequencies(2.0, 0.5, k1, 3.0)
    assert got[0] > 0
    assert got == pytest.approx(want, rel=1e-10)
    assert lin.numeric_stability(values) == "stable"  # not "marginal"
    values_zero = dict(values)
    values_zero.update({s: 0.0 for s in values if s.name == "k1"})
    zero = lin.numeric_frequencies(values_zero)
    assert zero[0] == 0.0 and zero[1] == pytest.approx(_chain_frequencies(2.0, 0.5, 0, 3)[1],
                                                       rel=1e-12)
    assert lin.numeric_stability(values_zero) == "marginal"
    values_neg = dict(values)
    values_neg.update({s: -k1 for s in values if s.name == "k1"})
    assert lin.numeric_stability(values_neg) == "unstable"
    assert np.isnan(lin.numeric_frequencies(values_neg)[0])


def test_no_unit_of_omega_squared_is_special():
    """classify_matrices judges ω² against the largest, not against 1: a slow system
    (ω² ~ 1e-12 in these units) is stable, and a tiny negative one unstable."""
    from mechbook.engine.linear import classify_matrices

    M, C = np.eye(2), np.zeros((2, 2))
    assert classify_matrices(M, C, np.diag([1e-12, 3e-12])) == "stable"
    assert classify_matrices(M, C, np.diag([-1e-12, 3e-12])) == "unstable"
    assert classify_matrices(M, C, np.diag([0.0, 3e-12])) == "marginal"


def test_a_singular_mass_matrix_is_said_so():
    """symon-12-25 about its default point θ = 0: z-x-z Euler angles are singular there
    (φ and ψ turn about the same axis), M has no inverse; the bench had read its error as
    an infinite relative error at M × 1e-8."""
    from mechbook.errors import MechbookError

    problem = load_problem(problem_path("symon-12-25", ROOT))
    analysis = Analysis(problem)
    lin = analysis.linear(None, analysis.default_point())
    with pytest.raises(MechbookError, match="not positive definite"):
        lin.numeric_frequencies(problem.values())
