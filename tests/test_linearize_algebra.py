"""The Lagrangian linearization's second derivatives in SymEngine and in SymPy agree.

`Equilibria._linearize_lagrangian` takes them in SymEngine and falls back to SymPy where
SymEngine cannot (an unknown function): the two algebras must give the same matrices."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import symengine as se
import sympy as sp

from mechbook.core.secalc import to_sympy
from mechbook.engine.analysis import Analysis
from mechbook.engine.equilibria import second_derivatives
from mechbook.model.problem import load_problem

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize(("pid", "name"), [("lim/2043.yaml", "general"),
                                          ("lim/2057.yaml", "planar"),
                                          ("symon/11-18.yaml", None)])
def test_second_derivatives_agree_in_both_algebras(pid, name):
    an = Analysis(load_problem(ROOT / "problems" / pid))
    sys = an.system(name)
    dyn = an.dynamics(sys.name)
    rng = np.random.default_rng(3)
    at = {q: sp.Float(rng.uniform(0.1, 0.9)) for q in dyn.q}
    rest = {v: sp.S.Zero for v in dyn.qd}
    names = set(dyn.L.free_symbols)
    fast = [[to_sympy(x, names) for x in part] for part in
            second_derivatives(dyn.L, dyn.q, dyn.qd, at, rest, sys.held, se.sympify)]
    slow = second_derivatives(dyn.L, dyn.q, dyn.qd, at, rest, sys.held, lambda e: e)
    symbols = sorted(set().union(*(e.free_symbols for part in slow for e in part)), key=str)
    point = {s: sp.Float(rng.uniform(0.5, 1.5)) for s in symbols}
    for part_fast, part_slow in zip(fast, slow, strict=True):
        assert len(part_fast) == len(part_slow) and part_slow
        for a, b in zip(part_fast, part_slow, strict=True):
            va, vb = complex(a.xreplace(point).evalf()), complex(b.xreplace(point).evalf())
            assert abs(va - vb) <= 1e-12 * max(1.0, abs(vb)), (a, b)


def test_either_algebra_falls_back_to_sympy_and_lets_a_problem_fault_through():
    from mechbook.core.secalc import either, same
    from mechbook.errors import UnsupportedError

    x = sp.Symbol("x", real=True)
    used = []

    def build(conv):
        used.append(conv)
        e = conv(sp.floor(x) * x)  # SymEngine leaves d/dx floor(x) unevaluated
        d = e.diff(conv(x))
        if conv is not same and d.atoms(se.Derivative):
            raise ValueError("unevaluated")
        return d

    assert either(build) == sp.diff(sp.floor(x) * x, x) and used == [se.sympify, same]
    assert either(lambda conv: conv(x**2).diff(conv(x))) == 2 * se.Symbol("x")

    def refused(conv):
        raise UnsupportedError("a capability the engine lacks")

    with pytest.raises(UnsupportedError):
        either(refused)




@pytest.mark.parametrize("at", ["0", "pi"])
def test_the_first_order_expansion_is_the_closed_form(tmp_path, at):
    """`Equilibria.expand` takes d/dε of the residuals in SymEngine (SymPy's where it
    cannot). The pendulum on a pivot y0 = a cos ωt, by hand: T = m(l²θ̇² + ẏ0² + 2ẏ0 l
    sinθ θ̇)/2, V = mg(y0 − l cosθ), so E = m l² θ̈ + m l (g + ÿ0) sinθ with ÿ0 = −aω²cos ωt;
    about θ = 0 (sinθ ≈ δ) and θ = π (sinθ ≈ −δ): M = m l², C = 0, K = ±m l (g − aω²cos ωt),
    no remainder. The engine's sign of E may be either: K/M is compared, and M, C, K the
    same through SymPy's own diff."""
    from systems import KAPITZA, load_analysis

    import mechbook.engine.equilibria as eqm

    an = load_analysis(tmp_path, KAPITZA, "9811")
    sys_ = an.system(None)
    eq = an.equilibria(None)
    theta = sys_.q[0]
    point = {theta: sp.pi if at == "pi" else sp.S.Zero}
    names = {p.symbol.name: p.symbol for p in sys_.params.values()}
    m, ell, a, w, g = (names[k] for k in ("m", "l", "a", "omega", "g"))
    t = sys_.t
    zeroth, M, C, K, F = eq.expand(point)
    sign = 1 if at == "0" else -1
    assert all(sp.simplify(z) == 0 for z in zeroth)
    assert sp.simplify(C[0, 0]) == 0 and all(sp.simplify(f) == 0 for f in F)
    want = sign * (g - a * w**2 * sp.cos(w * t)) / ell
    assert sp.simplify(K[0, 0] / M[0, 0] - want) == 0, (M, K)
    assert sp.simplify(M[0, 0] ** 2 - (m * ell**2) ** 2) == 0  # M = ±m l²
    slow = pytest.MonkeyPatch()
    slow.setattr(eqm, "derivative", sp.diff)
    try:
        again = eq.expand(point)
    finally:
        slow.undo()
    for x, y in zip((M, C, K, F), again[1:], strict=True):
        assert all(sp.simplify(u - v) == 0 for u, v in zip(x, y, strict=True))
