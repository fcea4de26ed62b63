"""A compiled function's call (core.compile.compile_exprs): one float64 point through the
machine code's own entry, anything else through Lambdify, the same values either way."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from mechbook.core.compile import compile_exprs

x, y = sp.symbols("x y", real=True)
EXPRS = [sp.sin(x) * y + x**2, x * y - sp.cos(y), sp.sqrt(x - 1)]


def closed(a: float, b: float) -> list[float]:
    return [math.sin(a) * b + a * a, a * b - math.cos(b),
            math.sqrt(a - 1) if a >= 1 else math.nan]


@pytest.mark.parametrize("backend", ["llvm", "symengine"])
def test_every_kind_of_argument_gives_the_closed_form(backend):
    f, used = compile_exprs([x, y], EXPRS, backend)
    assert used == backend
    point = np.array([0.3, 0.4])
    strided = np.array([0.3, 9.0, 0.4])[::2]
    for arg in (point, [0.3, 0.4], strided):
        got = f(arg)
        assert got.shape == (3,) and got.dtype == np.float64
        assert np.allclose(got, closed(0.3, 0.4), rtol=1e-15, atol=0, equal_nan=True)
    assert np.allclose(f(np.array([2.0, -1.5])), closed(2.0, -1.5), rtol=1e-15, atol=0)
    assert np.allclose(f(np.array([2, -1])), closed(2.0, -1.0), rtol=1e-15, atol=0)
    batch = f(np.array([[0.3, 0.4], [2.0, -1.5]]))  # a batch flattened, as before
    assert np.allclose(batch, closed(0.3, 0.4) + closed(2.0, -1.5), rtol=1e-15, atol=0,
                       equal_nan=True)


def test_each_call_returns_its_own_array():
    f, _ = compile_exprs([x, y], EXPRS)
    first = f(np.array([0.3, 0.4]))
    second = f(np.array([2.0, -1.5]))
    assert first is not second
    assert np.allclose(first, closed(0.3, 0.4), rtol=1e-15, atol=0, equal_nan=True)
