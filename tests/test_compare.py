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


def test_a_restricted_symbol_is_recomputed_without_sympy_at_each_point(monkeypatch):
    """A walk toward a limit recomputes a `restrict:`ed symbol (w = u/b, Kapitza's drive)
    at thousands of points: compiled once, not SymPy's subs and N at each (4 ms each, a
    third of a driven problem's check until issue 41's second pass), and to the same 30
    digits: u/b and sqrt(g/length)·u/b against the closed form at 40 digits; a square root of a
    negative number is no point."""
    import mpmath

    u, b, g, length = sp.symbols("u b g length", positive=True)
    w = sp.Symbol("w", positive=True)
    s = Sampler({u: 4.5, b: 0.08, g: 9.8, length: 0.8}, derived={w: sp.sqrt(g / length) * u / b})
    calls = []
    original = sp.Basic.subs
    monkeypatch.setattr(sp.Basic, "subs", lambda self, *a, **k: calls.append(1)
                        or original(self, *a, **k))
    for bv in ("0.08", "0.00008", "8e-12"):
        pt = s.complete({u: sp.Float("4.5", 30), b: sp.Float(bv, 30), g: sp.Float("9.8", 30),
                         length: sp.Float("0.8", 30)})
        with mpmath.workdps(40):
            want = mpmath.sqrt(mpmath.mpf("9.8") / mpmath.mpf("0.8")) * mpmath.mpf("4.5") \
                / mpmath.mpf(bv)
            assert abs(mpmath.mpf(pt[w]._mpf_) / want - 1) < 1e-29, (bv, pt[w])
        assert isinstance(pt[w], sp.Float) and pt[w]._prec == mpmath.libmp.dps_to_prec(30)
    assert not calls
    bad = Sampler({u: 1.0, g: 1.0}, derived={w: sp.sqrt(g - 2 * u)})
    assert bad.complete({u: sp.Float(1, 30), g: sp.Float(1, 30)}) is None
    negative = Sampler({u: 1.0, g: 1.0}, derived={w: g - 2 * u})  # w declared positive
    assert negative.complete({u: sp.Float(1, 30), g: sp.Float(1, 30)}) is None
    assert negative.complete({u: sp.Float("0.25", 30), g: sp.Float(1, 30)})[w] == \
        sp.Float("0.5", 30)
