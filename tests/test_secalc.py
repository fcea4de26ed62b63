"""SymEngine's results come back to SymPy with the caller's own symbols (mechbook.core.secalc)."""

from __future__ import annotations

import symengine as se
import sympy as sp

from mechbook.core.secalc import derivative, euler_lagrange, to_sympy


def test_a_result_keeps_the_callers_assumptions():
    r, m = sp.Symbol("r", positive=True), sp.Symbol("m", positive=True)
    out = derivative(sp.sqrt(r**2) * m * sp.cos(r), r)
    assert out.free_symbols == {r, m}
    assert sp.simplify(out - m * (sp.cos(r) - r * sp.sin(r))) == 0


def test_two_problems_with_one_name_and_other_assumptions_stay_apart():
    """The same SymEngine product with r positive (one problem: a radius) and then with r
    real (the next problem in the same worker: a coordinate): SymPy's cache keys the
    conversion by SymEngine's arguments, which compare by name; each result must come
    back with its own r (it came back with the first problem's r, and symon-09-05's
    equations then held two r's and failed after lim-2030)."""
    th, m = sp.Symbol("theta", real=True), sp.Symbol("m", positive=True)
    first = sp.Symbol("r", positive=True)
    second = sp.Symbol("r", real=True)
    for r in (first, second, first):
        product = se.sympify(m * r**2 * sp.cos(th) ** 2)
        out = to_sympy(product, {r, m, th})
        assert out.free_symbols == {r, m, th}, r.assumptions0
    t = sp.Symbol("t", real=True)
    for r in (first, second):
        rd = sp.Symbol("rdot", real=True)
        [eq] = euler_lagrange(m * rd**2 / 2 - m * r**2, [r], [rd], [(r, rd)], t, [sp.S.Zero])
        assert eq.free_symbols == {r, m}, r.assumptions0


def test_a_dummy_comes_back_as_itself():
    d, x = sp.Dummy("d"), sp.Symbol("x", real=True)
    out = derivative(d * x**2, x)
    assert out == 2 * d * x and d in out.free_symbols
