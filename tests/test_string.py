"""The Galerkin string (`string:`): exact for a uniform string, and the truncation's
accuracy measured for the variable density of Symon 12-19 (the figure quoted in
docs/schema.md and the problem's notes)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from systems import load_analysis as load

from mechbook.engine.analysis import Analysis
from mechbook.errors import SpecError


def string(n: int, density: str) -> str:
    coords = "\n".join(f"  q{k}: {{}}" for k in range(1, n + 1))
    amps = ", ".join(f"q{k}" for k in range(1, n + 1))
    return f"""\
id: lim-9601
source: test
title: a string in {n} modes
parameters:
  l: {{value: 1.2}}
  tau: {{value: 3.0}}
  sigma0: {{value: 0.5}}
  alpha: {{value: 0.15}}
coordinates:
{coords}
string:
  length: l
  tension: tau
  density: {density}
  amplitudes: [{amps}]
"""


def frequencies(an: Analysis) -> np.ndarray:
    lin = an.linear(None, {q: sp.S.Zero for q in an.system().q})
    return np.sort(lin.numeric_frequencies(an.problem.values()))


def test_uniform_string_is_exact(tmp_path):
    an = load(tmp_path, string(5, "sigma0"), "9601")
    w = frequencies(an)
    exact = np.arange(1, 6) * np.pi / 1.2 * np.sqrt(3.0 / 0.5)
    assert w == pytest.approx(exact, rel=1e-13)


@pytest.mark.slow
def test_truncation_accuracy_for_the_density_bump(tmp_path):
    """sigma0 + alpha*sin(pi*x/l) with alpha = 0.3*sigma0: the lowest frequency with 8 modes
    against 16 modes (the problem file of Symon 12-19 uses 8)."""
    dens = "sigma0 + alpha*sin(pi*x/l)"
    w8 = frequencies(load(tmp_path, string(8, dens), "9602"))
    w16 = frequencies(load(tmp_path, string(16, dens), "9603"))
    rel = abs(w8[0] - w16[0]) / w16[0]
    assert rel < 1e-8, rel  # measured: 5.8e-9
    assert abs(w8[1] - w16[1]) / w16[1] < 1e-7  # the second mode, slower: 4.8e-8
    w4 = frequencies(load(tmp_path, string(4, dens), "9604"))
    assert abs(w4[0] - w16[0]) / w16[0] > rel  # and it does converge: fewer modes, worse


def test_string_refuses_a_tension_that_varies(tmp_path):
    bad = string(2, "sigma0").replace("tension: tau", "tension: tau*(1 + x)")
    with pytest.raises(SpecError, match="do not depend on x"):
        load(tmp_path, bad, "9605").system()
