"""Relations decided at their boundary say only what was evaluated (issue 32): `fail` where
a point contradicted the book; where the engine gave no verdict anywhere, `unsupported`
with its reason; where nothing straddled the boundary, an error saying so. Never a fail
that blames the book for what was not compared."""

from __future__ import annotations

import pytest
import sympy as sp

from mechbook.errors import MechbookError, UndecidedError, UnsupportedError
from mechbook.verify import boundary
from mechbook.verify.compare import Sampler

k = sp.Symbol("k", positive=True)
c = sp.Symbol("c", positive=True)


def _sampler() -> Sampler:
    return Sampler({k: sp.Float(2.0, 30), c: sp.Float(1.0, 30)})


def _stable_above(pt: dict, near: bool) -> bool:
    return bool(pt[k] > pt[c])  # the engine's boundary: k = c


def test_the_right_boundary_passes_and_a_moved_one_fails():
    right = boundary.verdict(boundary.compare(k > c, _stable_above, _sampler()))
    assert right.ok and "boundary at" in right.power
    moved = boundary.compare(k > c * (1 + sp.Rational(1, 10**6)), _stable_above, _sampler())
    assert not moved.ok and moved.outcome == "fail"
    assert not boundary.verdict(moved).ok  # a fail: a point contradicted the book


def test_no_verdict_anywhere_is_unsupported_with_the_engines_reason():
    def never(pt, near):
        raise UnsupportedError("time-dependent coefficients")

    got = boundary.compare(k > c, never, _sampler())
    assert not got.ok and got.outcome == "unsupported"
    with pytest.raises(UnsupportedError) as exc:
        boundary.verdict(got)
    assert "time-dependent coefficients" in exc.value.capability
    assert "nothing was compared" in exc.value.capability


def test_marginal_everywhere_is_unsupported():
    got = boundary.compare(k > c, lambda pt, near: None, _sampler())
    with pytest.raises(UnsupportedError) as exc:
        boundary.verdict(got)
    assert "marginal" in exc.value.capability


def test_an_engine_error_everywhere_is_an_error_not_a_fail():
    def broken(pt, near):
        raise MechbookError("the matrix is singular here")

    got = boundary.compare(k > c, broken, _sampler())
    with pytest.raises(UndecidedError) as exc:
        boundary.verdict(got)
    assert "singular" in str(exc.value)


def test_nothing_straddling_the_boundary_is_undecided():
    """The engine and the book agree everywhere and the book's relation holds at every
    point drawn: nothing contradicts it, and nothing tests its boundary either."""
    got = boundary.compare(k > -c, lambda pt, near: True, _sampler())
    assert not got.ok and got.outcome == "undecided"
    with pytest.raises(UndecidedError) as exc:
        boundary.verdict(got)
    assert "cannot discriminate" in str(exc.value) and "all agreeing" in str(exc.value)


def test_a_disagreement_on_the_grid_is_still_a_fail():
    got = boundary.compare(k > -c, lambda pt, near: False, _sampler())
    assert not got.ok and got.outcome == "fail" and "the engine finds false" in got.detail


def test_a_ray_point_is_sympy_float_bit_for_bit():
    """A ray's points are built by `float_at_digits`, which must be SymPy's own
    `Float(x, 30)` to the last bit: x = k/7·e^u at three working precisions (k and u from
    a fixed grid, u over ±30), 1/3, and the special values."""
    import mpmath

    for dps in (15, 35, 50):
        with mpmath.workdps(dps):
            for k in range(-20, 21, 3):
                for u in range(-30, 31, 7):
                    x = mpmath.mpf(k) / 7 * mpmath.exp(mpmath.mpf(u) / 3)
                    a, b = sp.Float(x, 30), boundary.float_at_digits(x)
                    assert type(a) is type(b) and a == b, (dps, k, u)
                    if isinstance(a, sp.Float):
                        assert a._mpf_ == b._mpf_ and a._prec == b._prec, (dps, k, u)
            third = mpmath.mpf(1) / 3
            assert boundary.float_at_digits(third)._mpf_ == sp.Float(third, 30)._mpf_
    assert boundary.float_at_digits(mpmath.mpf(0)) == sp.Float(mpmath.mpf(0), 30)
    assert boundary.float_at_digits(mpmath.inf) == sp.oo
    assert boundary.float_at_digits(-mpmath.inf) == -sp.oo
    assert boundary.float_at_digits(mpmath.nan) is sp.nan


def test_a_crossing_is_the_atoms_root_by_either_bisection():
    """`_crossing` along a ray k = 2e^{t d_k}, c = e^{t d_c}: the book's k > c changes
    truth at t* = ln(1/2)/(d_k − d_c) (by hand), found to 30 digits from the 1e-6 bracket;
    where two atoms change sign within that bracket ((k > c) & (k > c(1 + 1e-9))) the
    bisection goes on and the crossing is the later root, t* + ln(1 + 1e-9)/(d_k − d_c)."""
    import mpmath
    import numpy as np

    d = np.array([0.6, -0.8])  # (c, k): the symbols in name order
    ray = boundary.Ray(_sampler(), _sampler().default(), d, [c, k])
    with mpmath.workdps(40):
        want = mpmath.log(mpmath.mpf(1) / 2) / (mpmath.mpf(-0.8) - mpmath.mpf(0.6))
        later = want + mpmath.log(1 + mpmath.mpf(10) ** -9) / (mpmath.mpf(-0.8) -
                                                                mpmath.mpf(0.6))
    for cond, root in ((k > c, want), (sp.And(k > c, k > c * (1 + sp.Rational(1, 10**9))),
                                        later)):
        judge = boundary._Judge(cond, lambda pt, near: True, ray, boundary._Silence())
        ts = np.linspace(-boundary.SPAN, boundary.SPAN, boundary.GRID)
        cell = int(np.searchsorted(ts, float(root))) - 1
        got = boundary._crossing(boundary.atoms_of(cond), judge, float(ts[cell]),
                                 float(ts[cell + 1]), judge.book(float(ts[cell])))
        assert got is not None and abs(got[0] - root) < 1e-25, (cond, got, root)


def test_a_boundary_moved_below_the_bracket_still_fails():
    """The Boolean bisection stops at 1e-6, but the crossing is the root to 30 digits: a
    boundary moved by a relative 3e-8 (30 times below the bracket, 3 times above EPS) fails."""
    moved = boundary.compare(k > c * (1 + sp.Rational(3, 10**8)), _stable_above, _sampler())
    assert not moved.ok and moved.outcome == "fail"
