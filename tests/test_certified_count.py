"""Counts certified by real-root isolation (mechbook.engine.certified_count): exact where the
conditions are polynomial, None (a lower bound for the caller) where they are not."""

from __future__ import annotations

import sympy as sp

from mechbook.engine.certified_count import certified_count

x, y, a = sp.symbols("x y a", real=True)


def _count(conds, unknowns, boxes, values=None):
    got = certified_count(conds, unknowns, values or {a: 2.0}, boxes)
    return None if got is None else got[0]


def test_univariate_roots_in_boxes():
    assert _count([x**2 - a], [x], [{x: (0, 5)}]) == 1
    assert _count([x**2 - a], [x], [{x: (-5, 5)}]) == 2
    assert _count([x**2 + a], [x], [{x: (-5, 5)}]) == 0
    assert _count([(x - 1) * (x - 2) * (x - 3)], [x], [{x: (0, 2.5)}]) == 2
    assert _count([(x - 1) * (x - 2) * (x - 3)], [x], [{x: (0, 1.5)}, {x: (2.5, 9)}]) == 2


def test_two_unknowns_shape_position():
    conds = [x**2 + y**2 - a, x - y]
    assert _count(conds, [x, y], [{x: (-5, 5), y: (-5, 5)}]) == 2
    assert _count(conds, [x, y], [{x: (0, 5), y: (0, 5)}]) == 1


def test_factors_that_never_vanish_are_removed():
    cond = [sp.exp(x**2) * (x - a) * 3, sp.exp(-y) * (y + 1)]
    assert _count(cond, [x, y], [{x: (0, 5), y: (-5, 5)}]) == 1


def test_not_polynomial_is_not_certified():
    assert _count([sp.sin(x) - x / 3], [x], [{x: (-5, 5)}]) is None
    assert _count([x**2 - a, x**2 - a], [x, y], [{x: (-5, 5), y: (-5, 5)}]) is None  # a curve


def test_a_root_outside_by_a_hair_is_outside():
    # root at sqrt(2) = 1.41421356..., box edge at 1.4142135 and 1.4142136
    assert _count([x**2 - 2], [x], [{x: (0, 1.4142135)}], {}) == 0
    assert _count([x**2 - 2], [x], [{x: (0, 1.4142136)}], {}) == 1
