"""Equilibria and small oscillations of a system with multiplier constraints.

With holonomic constraints g(q) = 0 (Jacobian A = ∂g/∂q, m rows) the equations of motion are
E(q, q̇, q̈) = Aᵀλ, E the Euler–Lagrange residuals without constraint forces
(mechbook.engine.lagrange). The motion lives on the manifold g = 0, of dimension k = n − m.

*Equilibrium.* q* with g(q*) = 0 and E(q*, 0, 0) = A*ᵀλ* for some λ*: the force left at
rest is a constraint force (normal to the manifold). With A* of full rank, λ* is unique:
λ* = (A*A*ᵀ)⁻¹A*E*, and the tangential residual E* − A*ᵀλ* must vanish.

*Linearization.* Choose k independent coordinates s (a subset of q whose complement's
columns of A* are invertible); to first order δq = N·δs with N = [I; −A_dep⁻¹A_ind] (rows in
the system's order), the null space of A*. Projecting the linearized equations on the
tangent space (Nᵀ A*ᵀ = 0 removes δλ):

    Nᵀ M N·δs̈ + Nᵀ C N·δṡ + Nᵀ (K − Σ_j λ*_j H_j) N·δs = Nᵀ F,

where M, C, K, F linearize E at the point and H_j is the Hessian of g_j there: the
constraint force λ*·A(q) turns with the manifold, and its curvature is a stiffness (a
pendulum written in x, y with x² + y² = l² gets g/l from it alone). This is the Hessian of
the Lagrange function V − λ*·g restricted to the tangent space, the textbook second-order
condition, and what sympy.physics.mechanics' Linearizer gives with dependent coordinates.
Moving (time-dependent) constraints and steady motions with constraints are refused.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate
from mechbook.engine.linear import LinearSystem
from mechbook.engine.residual import is_zero, show_point
from mechbook.errors import NotEquilibriumError, UnsupportedError


def constraint_functions(sys) -> list[sp.Expr]:
    """The constraint functions g_j(q), refused when one moves with time."""
    cons = [f for _, f in sys.constraints]
    if any(f.has(sys.t) for f in cons):
        raise UnsupportedError("equilibria and small oscillations with a moving (time-"
                               "dependent) multiplier constraint")
    return cons


def multipliers_at(E: list[sp.Expr], A: sp.Matrix) -> tuple[sp.Matrix, list[sp.Expr]]:
    """(λ*, tangential residual E − Aᵀλ*) for the force E left at rest and the constraint
    Jacobian A at a point: λ* by least squares, exact where the point is an equilibrium."""
    E = sp.Matrix(E)
    G = A * A.T
    lam = G.LUsolve(A * E) if G.shape[0] else sp.zeros(0, 1)
    return lam, list(E - A.T * lam)


def equilibrium_conditions(eq) -> tuple[list[sp.Expr], list[sp.Symbol]]:
    """Conditions in (q, λ) whose common roots are the constrained equilibria: E(q, 0, 0) −
    A(q)ᵀλ = 0 and g(q) = 0 (n + m equations in n + m unknowns)."""
    dyn, sys = eq.dyn, eq.sys
    cons = constraint_functions(sys)
    lam = dyn.multipliers
    A = dyn.constraint_jacobian
    rest = eq.rest_residuals()
    conds = [rest[i] - sum((A[j, i] * lam[j] for j in range(len(cons))), sp.S.Zero)
             for i in range(len(dyn.q))] + list(cons)
    return conds, list(dyn.q) + list(lam)


def residual_at(eq, point: dict) -> list[sp.Expr]:
    """What must vanish at a constrained equilibrium `point`: each constraint, and the force
    left at rest minus its normal (constraint) part."""
    dyn, sys = eq.dyn, eq.sys
    cons = constraint_functions(sys)
    A = dyn.constraint_jacobian.xreplace(point)
    E = [r.xreplace(point) for r in eq.rest_residuals()]
    _, tangential = multipliers_at(E, A)
    return [c.xreplace(point) for c in cons] + tangential


def _independent(A: sp.Matrix, q: list, values: dict) -> list[int]:
    """Indices of the dependent coordinates: m columns of A invertible at the default
    parameters (and at two nearby points), taken from the end so the first coordinates stay
    the independent ones."""
    m, n = A.shape
    rng = np.random.default_rng(11)
    points = [values] + [{k: v * float(np.exp(rng.uniform(-0.2, 0.2))) for k, v in
                          values.items()} for _ in range(2)]
    num = []
    for pt in points:
        env = {k: sp.Float(v, 30) for k, v in pt.items()}
        try:
            num.append(np.array([[evaluate(A[i, j], env)[0].real for j in range(n)]
                                 for i in range(m)]))
        except (NotNumeric, ZeroDivisionError, ValueError, TypeError, OverflowError):
            raise UnsupportedError("constrained linearization: the constraint Jacobian has no "
                                   "value at the parameters' defaults") from None
    if any(np.linalg.matrix_rank(a) < m for a in num):
        raise UnsupportedError("constrained linearization where the constraints are "
                               "dependent (their Jacobian loses rank at the point)")
    for dep in combinations(range(n - 1, -1, -1), m):
        cols = sorted(dep)
        if all(abs(np.linalg.det(a[:, cols])) > 1e-9 * max(1.0, np.abs(a).max()) ** m
               for a in num):
            return cols
    raise UnsupportedError("constrained linearization: no set of dependent coordinates "
                           "(the constraint Jacobian is singular at the point)")


def linearize_on_manifold(eq, point: dict, velocity: dict | None = None,
                          given: dict | None = None) -> LinearSystem:
    """The linear system about the constrained equilibrium `point`, over the independent
    coordinates (see the module docstring)."""
    dyn, sys = eq.dyn, eq.sys
    if velocity:
        raise UnsupportedError("linearization about a steady motion of a system with "
                               "multiplier constraints")
    cons = constraint_functions(sys)
    at = {q: sp.S(point.get(q, 0)) for q in dyn.q}
    values = sys.numeric_values()

    def restricted(x: sp.Expr) -> sp.Expr:
        return x.subs(given) if given else x

    off = [c for c in cons if not is_zero(restricted(c.subs(at)), values)]
    if off:
        raise NotEquilibriumError(f"the point {show_point(point)} violates the constraint "
                                  f"{sp.sstr(off[0])} = 0")
    zeroth, M, C, K, F = eq.expand(point, None, None)
    A = dyn.constraint_jacobian.subs(at)
    lam, tangential = multipliers_at(zeroth, A)
    bad = [r for r in tangential if not is_zero(restricted(r), values)]
    if bad:
        raise NotEquilibriumError(f"the point {show_point(point)} is not an equilibrium: a force "
                                  f"along the constraint manifold {sp.sstr(bad[0])[:120]} is "
                                  "left there")
    n, m = len(dyn.q), len(cons)
    dep = _independent(A, dyn.q, values)
    ind = [i for i in range(n) if i not in dep]
    N = sp.zeros(n, n - m)
    for j, i in enumerate(ind):
        N[i, j] = 1
    solved = -A[:, dep].LUsolve(A[:, ind])  # δq_dep = −A_dep⁻¹ A_ind δq_ind
    for r, i in enumerate(dep):
        for j in range(n - m):
            N[i, j] = sp.cancel(solved[r, j])
    curvature = sp.zeros(n, n)
    for j, g in enumerate(cons):
        curvature += lam[j] * sp.hessian(g, dyn.q).subs(at)
    Kc = K - curvature
    Nt = N.T

    def tidy(X: sp.Matrix) -> sp.Matrix:
        return X.applyfunc(sp.cancel)

    return LinearSystem(dyn, dict(point), tidy(Nt * M * N), tidy(Nt * C * N),
                        tidy(Nt * Kc * N), tidy(Nt * F), {},
                        coords=[dyn.q[i] for i in ind], embedding=N)
