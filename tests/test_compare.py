"""Numeric comparison: the sampler and the evaluator behind `vanishes`."""

from __future__ import annotations

import sympy as sp

from mechbook.core.numeval import evaluate
from mechbook.verify.compare import Sampler, all_vanish, vanishes

x, y = sp.symbols("x y", positive=True)
z = sp.Symbol("z", real=True)


def test_sampler_widens_when_the_conditions_exclude_the_defaults():
    s = Sampler({x: 1.0, z: 0.0}, [x > 50, z < -20])
    point = s.draw()
    assert point[x] > 50 and point[z] < -20


def test_identities_vanish_and_near_identities_do_not():
    s = Sampler({x: 0.7, y: 1.3})
    for e in (sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1, sp.exp(x) * sp.exp(y) - sp.exp(x + y),
              (x + y) ** 3 - sp.expand((x + y) ** 3), sp.sqrt(x**2 * y**2) - x * y,
              sp.atan2(y, x) - sp.atan(y / x)):
        assert vanishes(e, s, symbolic=False).ok, e
    for e in (sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1 + sp.Rational(1, 10**8),
              (x + y) ** 3 - sp.expand((x + y) ** 3) + x * sp.Rational(1, 10**7)):
        assert not vanishes(e, s, symbolic=False).ok, e


def test_magnitude_tracks_cancellation_inside_functions():
    """sin(a - b) with a = b identically: the value is rounding, the scale is not."""
    a = (x + y) ** 2
    b = x**2 + 2 * x * y + y**2
    v, m = evaluate(sp.sin(a - b) + 0 * x, {x: sp.Float(0.7, 30), y: sp.Float(1.3, 30)})
    assert abs(v) <= 1e-25 * m


def test_all_vanish_reports_the_first_failure_without_proving_the_rest():
    s = Sampler({x: 0.7})
    v = all_vanish([sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1, x - 2 * x], s)
    assert not v.ok and "residual" in v.detail
