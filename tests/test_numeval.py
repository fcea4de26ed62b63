"""The numeric evaluator's compiled programs (mechbook.core.numeval.Program)."""

from __future__ import annotations

import mpmath
import pytest
import sympy as sp

from mechbook.core import numeval
from mechbook.core.numeval import NotNumeric, evaluate, evaluate_mp, evaluate_resolved

x, y = sp.symbols("x y", positive=True)
z = sp.Symbol("z", real=True)


def _reference(expr: sp.Basic, point: dict, digits: int) -> mpmath.mpc:
    """SymPy's own evaluation at `digits` + 10 digits (an independent route to the value)."""
    d = digits + 10
    v = sp.N(expr.xreplace({k: sp.Float(v, d) for k, v in point.items()}), d)
    re, im = (sp.Float(part, d) for part in v.as_real_imag())
    with mpmath.workdps(d):
        return mpmath.mpc(mpmath.mpf(re._mpf_), mpmath.mpf(im._mpf_))


@pytest.mark.parametrize("expr", [
    x**3 * sp.sin(y) + sp.cos(x * y) ** 2 - sp.Rational(7, 3),
    sp.sqrt(x + y) ** 3 + sp.exp(-x) * sp.log(y) + sp.pi * sp.atan2(y, x),
    (x + y) ** sp.Rational(-1, 2) + sp.Abs(z - 1) + sp.tanh(z) ** 4,
    x**y + sp.I * sp.sin(x),
])
def test_the_program_agrees_with_sympy_to_the_working_precision(expr):
    point = {x: 0.7, y: 1.3, z: -0.4}
    for digits in (15, 30, 60):
        value, size = evaluate(expr, point, digits)
        ref = _reference(expr, point, digits)
        assert abs(value - complex(ref)) <= 1e-13 * max(1.0, abs(complex(ref)))
        assert size >= abs(value) * (1 - 1e-12)
        with mpmath.workdps(digits):
            precise = evaluate_mp(expr, point, digits)
            assert abs(precise - ref) <= mpmath.mpf(10) ** (3 - digits) * max(1, abs(ref))


def test_a_kept_program_follows_the_precision_of_each_call():
    """The constants of a kept program are converted again when the precision changes: a
    program first run at 15 digits must not carry 15-digit constants into a 60-digit run."""
    expr = sp.pi * x - sp.Rational(1, 3)
    evaluate(expr, {x: 1}, 15)
    with mpmath.workdps(60):
        v = evaluate_mp(expr, {x: 1}, 60)
        assert abs(v - (mpmath.pi - mpmath.mpf(1) / 3)) < mpmath.mpf(10) ** -58


def test_the_magnitude_measures_cancellation():
    expr = (x + 1) ** 2 - x**2 - 2 * x - 1  # zero, by cancelling terms of size ~1e12
    value, size = evaluate(expr, {x: 1e6}, 30)
    assert abs(value) <= 1e-15 * size and size > 1e12


@pytest.mark.parametrize(("expr", "point", "size"), [
    (x * y - z, {x: 2, y: 3, z: 5}, 2 * 3 + 5),  # sums add magnitudes, products multiply
    (sp.sin(x), {x: 1}, abs(mpmath.sin(1)) + abs(mpmath.cos(1)) * 1),  # |f| + |f'|·|x|
    (sp.sqrt(x), {x: 4}, 2 + 0.5 * 2 / 4 * 4),  # |v| + |exponent·v/base|·|base|
    (sp.atan2(y, x), {x: 3, y: 4}, abs(mpmath.atan2(4, 3)) + (3 * 4 + 4 * 3) / 25),
])
def test_the_magnitude_of_each_kind_of_node(expr, point, size):
    assert evaluate(expr, point, 30)[1] == pytest.approx(float(size), rel=1e-14)


def test_errors_are_raised_when_the_walk_reaches_them():
    with pytest.raises(NotNumeric, match="no value for y"):
        evaluate(x + y, {x: 1})
    with pytest.raises(ValueError, match="zoo"):
        evaluate(x + sp.zoo, {x: 1})
    with pytest.raises(NotNumeric, match="Piecewise"):
        evaluate(sp.Piecewise((x, x > 1), (0, True)), {x: 2})
    with pytest.raises(ZeroDivisionError):
        evaluate(1 / (x - 1), {x: 1})


@pytest.mark.parametrize("missing_first", [True, False])
def test_of_two_faults_the_first_in_the_walk_is_raised(missing_first):
    """A missing symbol (NotNumeric: not known to be zero) and a singularity (ValueError:
    the zero test draws another point) in one expression: the walk meets the arguments in
    order, as the recursive walk before the programs did."""
    missing = sp.sin(y)
    singular = sp.log(z)  # log(0) = zoo at z = 0
    expr = sp.Add(missing, singular, evaluate=False) if missing_first else \
        sp.Add(singular, missing, evaluate=False)
    first = expr.args[0]
    expected = NotNumeric if first.has(y) else (ValueError, ZeroDivisionError)
    with pytest.raises(expected):
        evaluate(expr, {x: 1, z: 0})
def test_resolved_values_raise_the_precision_until_they_stand_clear():
    big = sp.Integer(10) ** 24
    expr = (x + big) - big - x + sp.Rational(1, 10**25)
    assert abs(evaluate_resolved(expr, {x: sp.Rational(1, 3)}) - mpmath.mpf(10) ** -25) \
        < mpmath.mpf(10) ** -35


def test_the_kept_programs_are_bounded_and_the_recently_used_stay(monkeypatch):
    monkeypatch.setattr(numeval, "PROGRAMS", 8)
    numeval._programs.clear()
    for k in range(20):
        evaluate(x + k, {x: 1})
        evaluate(x + 100, {x: 1})  # used all along: never the least recently used
    assert len(numeval._programs) == 8
    assert x + 100 in numeval._programs and x + 19 in numeval._programs
    assert x + 0 not in numeval._programs
    assert evaluate(x + 19, {x: 1})[0] == 20  # the newest are kept, still right


@pytest.mark.parametrize("expr", [
    x**3 * sp.sin(y) + sp.cos(x * y) ** 2 - sp.Rational(7, 3),
    sp.sqrt(x + y) ** 3 + sp.exp(-x) * sp.log(y) + sp.pi * sp.atan2(y, x),
    sp.elliptic_k(x) + sp.asin(y) * sp.acos(x),
    sp.elliptic_e(x) + sp.sin(y),
])
def test_the_value_alone_is_runs_value_and_refuses_the_same_points(expr):
    """`Program.value` (no magnitudes) gives the very number `run` gives first, and a point
    `run` refuses — E(m)'s slope sampled past m = 1, where it has no real value — it
    refuses too; a point may name symbols the expression does not use."""
    prog = numeval.program(expr)
    refused = 0
    for xv, yv in ((0.7, 0.3), (1 - 1e-29, 0.5), (0.5, 1 - 1e-29), (0.2, 1.0), (1.0, 0.4)):
        pt = {x: mpmath.mpf(xv), y: mpmath.mpf(yv), z: "not a number"}
        for digits in (30, 50):
            with mpmath.workdps(digits):
                try:
                    expected = prog.run(prog.values(pt))[0]
                except (ValueError, ZeroDivisionError) as exc:
                    expected = type(exc)
                    refused += 1
                try:
                    got = prog.value(prog.values(pt))
                except (ValueError, ZeroDivisionError) as exc:
                    got = type(exc)
            assert got == expected, (xv, yv, digits)
    if expr.has(sp.elliptic_e):
        assert refused, "the edge of E's domain refuses points"
