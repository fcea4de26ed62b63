"""mechbook.core.rational: SymPy's cancel with SymEngine's expansion, and its size limit."""

from __future__ import annotations

import pytest
import sympy as sp

from mechbook.core.rational import TooLarge, cancel, vanishes_identically

x, y, a = sp.symbols("x y a", positive=True)


@pytest.mark.parametrize("expr", [
    (x**2 - y**2) / (x - y),
    (x + y) ** 3 / (x**2 + 2 * x * y + y**2) + a / (x * (1 + a)),
    sp.sin(x) ** 2 / (sp.sin(x) + sp.sin(x) * sp.cos(y)),
])
def test_cancel_is_sympys_cancel(expr):
    assert sp.simplify(cancel(expr) - sp.cancel(expr)) == 0
    assert cancel(expr) == sp.cancel(expr)


def test_a_cancel_that_outgrows_its_limit_stops_before_the_costly_part():
    grows = (x + y + a) ** 8 / (x - y) + 1 / (x + a)  # a short product, a long expansion
    with pytest.raises(TooLarge):
        cancel(grows, max_growth=8)
    assert sp.simplify(cancel(grows) - grows) == 0  # without a limit: cancelled
    small = (x**2 - y**2) / (x - y)  # shrinks: the limit does not stop it
    assert cancel(small, max_growth=8) == x + y


def test_vanishes_identically():
    assert vanishes_identically((x + y) ** 2 - x**2 - 2 * x * y - y**2)
    assert not vanishes_identically((x + y) ** 2 - x**2 - y**2)
