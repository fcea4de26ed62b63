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
