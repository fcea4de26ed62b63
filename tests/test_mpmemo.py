"""mechbook.core.mpmemo: remembered elementary functions give mpmath's numbers bit for bit
(at every precision, for real and complex arguments), and a lambdified 30-digit quadrature
through them has the closed form's value."""

import mpmath
import sympy as sp

from mechbook.core import mpmemo


def test_remembered_values_are_mpmaths_at_each_precision():
    for name in mpmemo.NAMES:
        f, g = mpmemo.NAMESPACE[name], getattr(mpmath, name)
        for dps in (15, 30, 60, 30):  # 30 again: the remembered values, not recomputed
            with mpmath.workdps(dps):
                for x in (mpmath.mpf("0.3"), mpmath.mpf(1) / 7, mpmath.mpc("0.2", "-0.4")):
                    assert f(x) == g(x), (name, dps, x)
                    assert type(f(x)) is type(g(x))
    # a value at 15 digits is not handed out at 30
    with mpmath.workdps(15):
        low = mpmemo.NAMESPACE["sin"](mpmath.mpf(1) / 3)
    with mpmath.workdps(30):
        third = mpmath.mpf(1) / 3
        assert mpmemo.NAMESPACE["sin"](third) == mpmath.sin(third) != low


def test_other_arguments_pass_through_and_errors_are_not_remembered():
    assert mpmemo.NAMESPACE["sqrt"](2.0) == mpmath.sqrt(2.0)
    assert mpmemo.NAMESPACE["sqrt"](mpmath.mpf(-4)) == mpmath.mpc(0, 2)  # mpmath's own
    calls = []

    def boom(x):
        calls.append(x)
        raise ValueError("no value")

    f = mpmemo.remembered(boom)
    for _ in range(2):
        try:
            f(mpmath.mpf(1))
        except ValueError:
            pass
    assert len(calls) == 2  # an error is raised again, not remembered


def test_memory_is_bounded():
    f = mpmemo.remembered(mpmath.cos)
    old = mpmemo.KEPT
    try:
        mpmemo.KEPT = 8
        with mpmath.workdps(30):
            xs = [mpmath.mpf(k) / 10 for k in range(30)]
            assert [f(x) for x in xs] == [mpmath.cos(x) for x in xs]
            assert [f(x) for x in xs] == [mpmath.cos(x) for x in xs]
    finally:
        mpmemo.KEPT = old


def test_quadrature_through_the_namespace_has_the_closed_form():
    # ∫₀^π sin²x·√(1 + cos²x)… kept simple: ∫₀^π (sin²x + cosh(x/π)) dx = π/2 + π·sinh(1)
    x = sp.Symbol("x")
    expr = sp.sin(x) ** 2 + sp.cosh(x / sp.pi)
    f = sp.lambdify([x], expr, modules=[mpmemo.NAMESPACE, "mpmath"], cse=True)
    g = sp.lambdify([x], expr, modules="mpmath", cse=True)
    with mpmath.workdps(30):
        exact = mpmath.pi / 2 + mpmath.pi * mpmath.sinh(1)
        for _ in range(2):  # the second time every node's functions are remembered
            got = mpmath.quad(f, [0, mpmath.pi / 2, mpmath.pi])
            assert got == mpmath.quad(g, [0, mpmath.pi / 2, mpmath.pi])  # bit for bit
            assert abs(got - exact) < mpmath.mpf(10) ** -28 * exact


def test_a_curves_quadrature_through_it_has_the_closed_form():
    # the cycloid x = a(θ − sin θ), y = a(1 − cos θ) over one arch is 8a long; the second
    # quadrature finds every node's sines and cosines remembered, the same number
    from mechbook.engine.curve import Curve, integral

    th, a = sp.Symbol("theta"), sp.Symbol("a", positive=True)
    x, y = a * (th - sp.sin(th)), a * (1 - sp.cos(th))
    curve = Curve(th, x, [y], (sp.Integer(0), 2 * sp.pi), [])
    length = sp.sqrt(sp.diff(x, th) ** 2 + sp.diff(y, th) ** 2)
    point = {a: sp.Float("0.7", 30)}
    first, _ = integral(length, curve, point)
    second, _ = integral(length, curve, point)
    assert first == second
    with mpmath.workdps(30):
        assert abs(first - 8 * mpmath.mpf("0.7")) < mpmath.mpf(10) ** -27
