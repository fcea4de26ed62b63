"""The Legendre transform (mechbook.engine.affine, Dynamics.velocities_of_momenta): momenta
affine in the velocities solved as a linear system, and a time limit that runs out said as
such, never as "not uniquely solvable"."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from systems import load_analysis

from mechbook.core.timeout import hard_time_limit
from mechbook.engine.affine import affine_parts, solve_unknowns, solve_within
from mechbook.errors import UnsupportedError

# A pendulum (rod l, bob m1) whose bob carries a mass m2 on a spring (stiffness k, natural
# length a), swinging in the plane: coordinates theta (the rod), r and phi (the spring's
# length and angle). A velocity-dependent term U = -b*r**2*phidot/2 (L = T - V - U) makes
# the momenta affine, not linear: p = M*qdot + a with a = (0, 0, b*r**2/2).
# SymPy's solve took 115 s for these momenta and then reported them "not uniquely
# solvable" (its time limit had run out).
SPRING_PENDULUM = """\
id: lim-9501
source: test
title: a pendulum whose bob carries a mass on a spring
parameters:
  m1: {value: 1.0}
  m2: {value: 0.5}
  l: {value: 1.2}
  k: {value: 3.0}
  a: {value: 0.6}
  b: {value: 0.7}
  g: {}
coordinates:
  theta: {}
  r: {}
  phi: {}
particles:
  bob: {mass: m1, position: [l*sin(theta), -l*cos(theta)]}
  bead: {mass: m2, position: [l*sin(theta) + r*sin(phi), -l*cos(theta) - r*cos(phi)]}
springs:
  - {k: k, length: r, natural_length: a}
velocity_potential: -b*r**2*phidot/2
gravity: {}
"""


def hand_hamiltonian(v: dict, theta, r, phi, p) -> float:
    """H = ½(p − a)ᵀM⁻¹(p − a) + V, written out by hand (not by the engine): the bead's
    velocity (l θ̇ cos θ + ṙ sin φ + r φ̇ cos φ, l θ̇ sin θ − ṙ cos φ + r φ̇ sin φ) has
    |v|² = l²θ̇² + ṙ² + r²φ̇² + 2 l θ̇ ṙ sin(φ − θ) + 2 l r θ̇ φ̇ cos(φ − θ), so in
    (θ, r, φ) M = [[(m1 + m2) l², m2 l sin(φ−θ), m2 l r cos(φ−θ)], [·, m2, 0],
    [·, 0, m2 r²]]; a = ∂(−U)/∂q̇ = (0, 0, b r²/2), and U, linear in the velocities,
    leaves the energy function: h = T + V."""
    m1, m2, l, k, a, b, g = (v[n] for n in ("m1", "m2", "l", "k", "a", "b", "g"))  # noqa: E741
    s, c = np.sin(phi - theta), np.cos(phi - theta)
    M = np.array([[(m1 + m2) * l**2, m2 * l * s, m2 * l * r * c],
                  [m2 * l * s, m2, 0.0],
                  [m2 * l * r * c, 0.0, m2 * r**2]])
    shift = np.asarray(p) - np.array([0.0, 0.0, b * r**2 / 2])
    V = -(m1 + m2) * g * l * np.cos(theta) - m2 * g * r * np.cos(phi) + k * (r - a)**2 / 2
    return float(shift @ np.linalg.solve(M, shift) / 2 + V)


def test_three_coordinates_hamiltonian_in_seconds_without_simplification(tmp_path):
    an = load_analysis(tmp_path, SPRING_PENDULUM, "9501")
    dyn = an.dynamics()
    assert not dyn.simplify
    with hard_time_limit(30):  # 115 s, and a false "not solvable", before
        H = dyn.hamiltonian
    values = {s.name: float(x) for s, x in an.system().numeric_values().items()}
    names = {s.name: s for s in H.free_symbols}
    rng = np.random.default_rng(7)
    for _ in range(5):
        theta, phi = rng.uniform(-2, 2, 2)
        r = rng.uniform(0.3, 1.5)
        p = rng.uniform(-2, 2, 3)
        point = {names[n]: x for n, x in values.items() if n in names}
        point.update({names["theta"]: theta, names["r"]: r, names["phi"]: phi,
                      names["p_theta"]: p[0], names["p_r"]: p[1], names["p_phi"]: p[2]})
        got = float(H.xreplace({k: sp.Float(x, 30) for k, x in point.items()}).evalf(30))
        want = hand_hamiltonian(values, theta, r, phi, p)
        assert got == pytest.approx(want, rel=1e-12, abs=1e-12)
        # and the velocities invert the momenta: p(q̇(p)) = p
        qd = {v: e.xreplace({k: sp.Float(x, 30) for k, x in point.items()})
              for v, e in dyn.velocities_of_momenta.items()}
        again = [float(m.xreplace({k: sp.Float(x, 30) for k, x in point.items()})
                       .xreplace(qd).evalf(30)) for m in dyn.momenta]
        assert again == pytest.approx(list(p), rel=1e-12, abs=1e-12)
    # a wrong mass (m2 one percent heavier) in the hand formula is seen
    wrong = dict(values, m2=values["m2"] * 1.01)
    assert got != pytest.approx(hand_hamiltonian(wrong, theta, r, phi, p), rel=1e-6)


def test_affine_parts_and_a_singular_matrix():
    x, y, u, w = sp.symbols("x y u w")
    J, b = affine_parts([x * u + sp.sin(x) * w - 1, y**2 * w + x], [u, w])
    assert J == sp.Matrix([[x, sp.sin(x)], [0, y**2]]) and b == sp.Matrix([-1, x])
    assert affine_parts([u**2 - x], [u]) is None
    # (u + w)**2 expanded once and differentiated: still affine, the unknowns cancel
    assert affine_parts([sp.diff((u + w) ** 2 * x, u) - y], [u, w]) is not None
    # a coordinate with no kinetic energy: the momenta do not determine its velocity
    with pytest.raises(UnsupportedError, match="singular"):
        solve_unknowns([x * (u + w) - y, 2 * x * (u + w) - y], [u, w], "test", 10)
    assert solve_unknowns([x * u - y], [u], "test", 10) == {u: y / x}


def test_a_time_limit_is_said_as_such(monkeypatch):
    """Equations that are not affine go to SymPy's solve; when its limit runs out the
    message says so and does not call them unsolvable. The solve is made to spin (a real
    SymPy solve may give up with NotImplementedError before a short limit, or finish
    inside a long one, depending on the cache), so the limit is what ends it."""
    x = sp.Symbol("x")

    def spinning_solve(*args, **kwargs):
        while True:
            pass

    with monkeypatch.context() as patch:
        patch.setattr("mechbook.engine.affine.sp.solve", spinning_solve)
        with pytest.raises(UnsupportedError) as info:
            solve_within([x**7 + sp.sin(x) * x**3 - 1], [x], "test", 0.05)
    assert "time limit" in str(info.value) and "not uniquely" not in str(info.value)
    # SymPy's own refusal is said as a refusal, not as a time limit
    with pytest.raises(UnsupportedError, match="cannot") as info:
        solve_within([x - sp.cos(x)], [x], "test", 60)
    assert "time limit" not in str(info.value)
    with pytest.raises(UnsupportedError, match="2 solutions"):
        solve_within([x**2 - 1], [x], "test", 10)
