"""A residual below 1e-27 of its cancellation scale is not necessarily rounding.

The scale `vanishes` judges a residual against is a bound on what cancelled on the way;
where a denominator cancels it can stand 1e10 above the terms themselves. A fixed floor of
1e-27 of it then took a real residual for rounding: symon-11-08's polhode with an exponent
moved to 2·(1 + 1e-19) (residual ~1e-20 against scales of 4e6 to 5e10) passed or failed by
the points drawn, and the points followed the process's hash seed. These tests build the
same situation from a closed form: f = ((x + y)² − y² − x²)/(2xy) is exactly 1, but with
y ~ 1e10 its scale is ~y/x, so f·(x^(2(1+δ)) − x²) has the value 2δ·ln(x)·x² (+O(δ²)) at
~1e-30 of its scale.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import sympy as sp

from mechbook.core.numeval import evaluate
from mechbook.verify.compare import AMBIGUOUS, Sampler, vanishes

ROOT = Path(__file__).resolve().parents[1]
x, y = sp.symbols("x y", positive=True)
z = sp.Symbol("z", positive=True)
DELTA = sp.Rational(1, 10**19)
ONE = ((x + y) ** 2 - y**2 - x**2) / (2 * x * y)  # 1, with a scale of ~y/x
BASE = {x: 1.7, y: 1e10}


def test_the_closed_form_puts_a_real_residual_under_the_old_floor():
    """The premise, from the closed form: at the default point the mutant's residual is
    2δ·ln(1.7)·1.7² = 3.07e-19, and it lies below 1e-27 of the scale."""
    e = ONE * (x ** (2 * (1 + DELTA)) - x**2)
    v, m = evaluate(e, {x: sp.Float(1.7, 30), y: sp.Float(1e10, 30)})
    expected = 2 * 1e-19 * float(sp.log(sp.Float(1.7))) * 1.7**2
    assert abs(abs(v) - expected) < 1e-3 * expected
    assert abs(v) < AMBIGUOUS * m


def test_an_exponent_moved_by_1e_19_fails_under_a_large_cancellation_scale():
    e = ONE * (x ** (2 * (1 + DELTA)) - x**2)
    got = vanishes(e, Sampler(BASE), symbolic=False)
    assert not got.ok, got
    assert "60 digits" in got.method and "not rounding" in got.detail, got


def test_a_coefficient_moved_by_1e_19_fails_likewise():
    """(1 + δ)(x + 1)² − (x² + 2x + 1) = δ(x + 1)², ~1e-29 of the scale here."""
    e = ONE * ((1 + DELTA) * (x + 1) ** 2 - (x**2 + 2 * x + 1))
    v, m = evaluate(e, {x: sp.Float(1.7, 30), y: sp.Float(1e10, 30)})
    assert abs(abs(v) - 1e-19 * 2.7**2) < 1e-22 and abs(v) < AMBIGUOUS * m
    assert not vanishes(e, Sampler(BASE), symbolic=False).ok


def test_a_true_identity_under_the_same_scale_still_passes_and_says_what_was_decided():
    e = ONE * (x * (x + 1) - x**2 - x)
    got = vanishes(e, Sampler(BASE), symbolic=False)
    assert got.ok, got
    assert "residual ≤ 1e-20 of its scale" in got.power
    assert "none above 1e-50 of it at 60 digits: exact inputs" in got.power, got.power


def test_a_point_computed_at_30_digits_keeps_the_floor():
    """z = √x is a derived symbol, rounded at 30 digits: z² − x is then ~1e-30·x at the
    point, a true residual that 60 digits would find and no precision removes. Such a
    point keeps the 1e-27 floor, and its power line says so."""
    s = Sampler(BASE, derived={z: sp.sqrt(x)})
    e = ONE * (z**2 - x)
    got = vanishes(e, s, symbolic=False)
    assert got.ok, got
    assert "undecided: inputs rounded" in got.power, got.power


def test_a_number_of_30_digits_in_the_expression_keeps_the_floor():
    """0.1 at 30 digits is 1/10 only to ~1e-31: a residual its rounding leaves, not the
    expression's."""
    e = ONE * (sp.exp(x * sp.Float("0.1", 30)) - sp.exp(x / 10))
    got = vanishes(e, Sampler(BASE), symbolic=False)
    assert got.ok, got
    assert "undecided: inputs rounded" in got.power, got.power


DRAW = """
import sympy as sp
from mechbook.verify.compare import Sampler
names = sp.symbols("a b c d e f g h", real=True)
s = Sampler({names[0]: 1.0})
print(sorted((str(k), float(v)) for k, v in s.draw(set(names)).items()))
"""


def test_the_points_drawn_do_not_depend_on_the_hash_seed():
    """A set of variables is drawn in one order, whatever the process's hash seed."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    outs = {subprocess.run([sys.executable, "-c", DRAW], capture_output=True, text=True,
                           env={**env, "PYTHONHASHSEED": str(seed)}, check=True,
                           timeout=120).stdout
            for seed in (0, 1, 2, 3)}
    assert len(outs) == 1, outs


def test_a_number_written_to_its_digits_keeps_the_floor():
    """A root the key writes to 36 digits is true to those only: 1.875104068711961166445308
    24107821416 stands for the root of 1 + cos(z)cosh(z) (classic-cantilever-beam), whose
    edge condition then leaves ~1e-33 of its scale. Such a key keeps the floor; an exact
    key's ratio of integers (the power bench's 1 + δ) does not."""
    from mechbook.model.expr import decimal_digits

    assert decimal_digits("1.87510406871196116644530824107821416/L") == 36
    assert decimal_digits("0.5*m*v**2 + 9.81*m*h") == 3
    assert decimal_digits("I3**(2*(10000000000000000001/10000000000000000000))") == 0
    assert decimal_digits("x1**2 = 2.50e3") == 3
    assert decimal_digits(1.8751040687119612) == 17  # a YAML float: its repr
    root = sp.Rational("1.87510406871196116644530824107821416")  # as the parser reads it
    e = ONE * (1 + sp.cos(root) * sp.cosh(root))  # 4e-31, 8e-43 of the scale
    assert not vanishes(e, Sampler(BASE), symbolic=False).ok  # exact: the root is not one
    got = vanishes(e, Sampler(BASE, approximate=True), symbolic=False)
    assert got.ok and "undecided: inputs rounded" in got.power, got
