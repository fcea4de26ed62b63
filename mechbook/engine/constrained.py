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
Moving (time-dependent) holonomic constraints are refused.

*Velocity constraints* (rolling without slipping: A_v(q, t)·q̇ + b(q, t) = 0) leave fewer
independent velocities than coordinates, so the linearization about a point or a uniform
motion q*(t) = q0 + v·t (`linearize_first_order`; v stated, zero where `about:` names the
coordinate, else solved from the constraints) is first order. With every constraint at the
velocity level, A(q)·q̇ + b = 0 (holonomic rows ġ), the multipliers μ* of the reference
motion from E* = A*ᵀμ*, and H = ∂(A(q)ᵀμ*)/∂q, D = ∂(A·q̇ + b)/∂q there:

    M·δq̈ + C·δq̇ + (K − H)·δq = F + A*ᵀδμ,   G·δq = 0,   A_v·δq̇ + D_v·δq = 0.

δq = N_h·δs (N_h the null space of the holonomic G, as above); the velocity constraints
then fix some of the rates δṡ by the others: δṡ = T·δu + R·δs, δu the independent speeds
(columns of A_v·N_h invertible, taken from the end). Projecting on the admissible
displacements P = N_h·T removes δμ, and δs̈ = T·δu̇ + R·δṡ gives

    δṡ = R·δs + T·δu,
    M_r·δu̇ = −Pᵀ(M·N_h·R² + C·N_h·R + (K − H)·N_h)·δs − Pᵀ(M·N_h·R·T + C·N_h·T)·δu + Pᵀ·F,

M_r = PᵀMP: a StateSpaceSystem (mechbook.engine.state_space) in z = (δs, δu). Without
velocity constraints T = 1, R = 0 and this is the second-order system above. The
coefficients must be free of t (the motion is a symmetry orbit), as for every steady motion.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
import sympy as sp

from mechbook.core.expansion import trig_canonical
from mechbook.core.numeval import NotNumeric, evaluate, without_absent
from mechbook.engine.linear import LinearSystem
from mechbook.engine.residual import is_zero, show_point
from mechbook.engine.state_space import StateSpaceSystem
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


def _at_rest_jacobian(dyn) -> sp.Matrix:
    """Every constraint's A at the velocity level (holonomic ∂g/∂q, velocity ∂c/∂q̇): the
    directions its force may take, at rest as in motion."""
    return dyn.velocity_jacobian


def equilibrium_conditions(eq) -> tuple[list[sp.Expr], list[sp.Symbol]]:
    """Conditions in (q, λ) whose common roots are the constrained equilibria: E(q, 0, 0) −
    A(q)ᵀλ = 0 and g(q) = 0 (n + m_h equations; a velocity constraint adds a multiplier and
    no equation, so its rest points come in families)."""
    dyn, sys = eq.dyn, eq.sys
    cons = constraint_functions(sys)
    lam = dyn.multipliers
    A = _at_rest_jacobian(dyn)
    rest = eq.rest_residuals()
    conds = [rest[i] - sum((A[j, i] * lam[j] for j in range(A.rows)), sp.S.Zero)
             for i in range(len(dyn.q))] + list(cons)
    return conds, list(dyn.q) + list(lam)


def residual_at(eq, point: dict) -> list[sp.Expr]:
    """What must vanish at a constrained equilibrium `point`: each constraint, and the force
    left at rest minus its part along the constraints' normals (their forces)."""
    dyn, sys = eq.dyn, eq.sys
    cons = constraint_functions(sys)
    A = _at_rest_jacobian(dyn).xreplace(point)
    E = [r.xreplace(point) for r in eq.rest_residuals()]
    _, tangential = multipliers_at(E, A)
    return [c.xreplace(point) for c in cons] + tangential


def _independent(A: sp.Matrix, q: list, values: dict,
                 prefer: list[int] | None = None) -> list[int]:
    """Indices of the dependent coordinates: m columns of A invertible at the default
    parameters (and at two nearby points), taken from the end so the first coordinates stay
    the independent ones; those of `prefer` first, where they will do."""
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
    order = list(range(n - 1, -1, -1))
    if prefer:
        order = [i for i in order if i in prefer] + [i for i in order if i not in prefer]
    for dep in combinations(order, m):
        cols = sorted(dep)
        if all(abs(np.linalg.det(a[:, cols])) > 1e-9 * max(1.0, np.abs(a).max()) ** m
               for a in num):
            return cols
    raise UnsupportedError("constrained linearization: no set of dependent coordinates "
                           "(the constraint Jacobian is singular at the point)")


def linearize_on_manifold(eq, point: dict, velocity: dict | None = None,
                          given: dict | None = None) -> LinearSystem | StateSpaceSystem:
    """The linear system about the constrained equilibrium `point`, over the independent
    coordinates (see the module docstring); first order where velocity constraints leave
    fewer independent velocities than coordinates, or about a steady motion."""
    dyn, sys = eq.dyn, eq.sys
    if sys.velocity_constraints or velocity:
        return linearize_first_order(eq, point, velocity, given)
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
    n = len(dyn.q)
    N, ind = _null_basis(A, _independent(A, dyn.q, values))  # δq_dep = −A_dep⁻¹ A_ind δq_ind
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


def reference_rates(eq, point: dict, velocity: dict, given: dict | None = None) -> dict:
    """Every coordinate's rate along the reference motion: stated (`velocity`), else solved
    from the constraints at the velocity level (the stated rates and the point fix them: a
    rolling disk's centre follows its spin). A coordinate the point names is at rest unless
    the constraints make it move: then its rate is solved for too (a rolling coin placed at
    x = y = 0 and spun: its centre's rate follows from the spin, not from `steady:`)."""
    dyn = eq.dyn
    values = eq.sys.numeric_values()
    stated = {q: sp.S(velocity[q]) for q in dyn.q if q in velocity}
    open_ = [i for i, q in enumerate(dyn.q) if q not in stated and q not in point]
    resting = [i for i, q in enumerate(dyn.q) if q not in stated and q in point]
    if not dyn.velocity_jacobian.rows:
        if open_:
            raise _open_rates(dyn, open_)
        return {**stated, **{dyn.q[i]: sp.S.Zero for i in resting}}
    at = {q: sp.S(point.get(q, 0)) for q in dyn.q}
    A = dyn.velocity_jacobian.xreplace(at)
    rest = {v: sp.S.Zero for v in dyn.qd}
    b = sp.Matrix([c.xreplace(rest).xreplace(at) for c in dyn.velocity_rows])
    solved, left = _solve_rates(dyn, A, b, stated, open_, given, values)
    while left and resting:  # free the resting coordinate that leaves the least unmet
        tries = []
        for i in resting:
            attempt = _solve_rates(dyn, A, b, stated, sorted(open_ + [i]), given, values)
            if attempt[0] is not None:
                tries.append((len(attempt[1]), i, attempt))
        if not tries or min(tries)[0] >= len(left):
            break
        _, i, (solved, left) = min(tries, key=lambda x: x[:2])
        open_, resting = sorted(open_ + [i]), [j for j in resting if j != i]
    if solved is None:
        raise _open_rates(dyn, open_)
    if left and open_:
        raise NotEquilibriumError("the stated rates break the velocity constraints: "
                                  f"{sp.sstr(left[0])[:120]} is left")
    return {**stated, **{dyn.q[i]: sp.S.Zero for i in resting}, **solved}


def _open_rates(dyn, open_: list[int]) -> UnsupportedError:
    names = ", ".join(str(dyn.q[i]) for i in open_)
    return UnsupportedError(f"the reference motion leaves the rates of {names} open: give "
                            "them (`steady:`) or the coordinates' values (`about:`)")


def _solve_rates(dyn, A: sp.Matrix, b: sp.Matrix, stated: dict, open_: list[int],
                 given: dict | None, values: dict) -> tuple[dict | None, list]:
    """The rates of the coordinates `open_` (indices) that meet A q̇ + b = 0 with the
    stated ones and the others at rest, by least squares; with the constraint rows left
    unmet. (None, []) where they are not fixed (A's columns of `open_` dependent)."""
    fixed = {i: stated.get(q, sp.S.Zero) for i, q in enumerate(dyn.q) if i not in open_}
    known = sorted(fixed)
    rhs = -b - A[:, known] * sp.Matrix([fixed[i] for i in known]) if known else -b
    if not open_:
        solved = sp.zeros(0, 1)
        residual = -rhs
    else:
        Ao = A[:, open_]
        if sp.Matrix(Ao).rank(iszerofunc=lambda x: is_zero(x, values)) < len(open_):
            return None, []
        solved = (Ao.T * Ao).LUsolve(Ao.T * rhs).applyfunc(sp.cancel)
        residual = Ao * solved - rhs
    left = [r for r in residual if not is_zero(sp.S(r).subs(given or {}), values)]
    return {dyn.q[i]: solved[k] for k, i in enumerate(open_)}, left


def linearize_first_order(eq, point: dict, velocity: dict | None = None,
                          given: dict | None = None) -> LinearSystem | StateSpaceSystem:
    """The linearization about the point (at rest) or the uniform motion point + v·t on
    the constraint manifold, velocity constraints and all (the module docstring): a
    StateSpaceSystem in (δs, δu); a LinearSystem over δs where no velocity constraint
    leaves fewer speeds than coordinates."""
    dyn, sys = eq.dyn, eq.sys
    t = sys.t
    values = sys.numeric_values()
    cons = constraint_functions(sys)
    rates = reference_rates(eq, point, dict(velocity or {}), given)
    moving = {q: r for q, r in rates.items() if not (r == 0)}
    where = {q: sp.S(point.get(q, 0)) + moving.get(q, 0) * t for q in dyn.q}
    where.update({v: rates[q] for q, v in zip(dyn.q, dyn.qd, strict=True)})

    def restricted(x: sp.Expr) -> sp.Expr:
        return x.subs(given) if given else x

    def along(x: sp.Expr, what: str) -> sp.Expr:
        """x on the reference motion, which must not depend on t there."""
        x = without_absent(x.xreplace(where), [t])
        if x.has(t):
            raise UnsupportedError(f"linearization about a motion along which {what} "
                                   "changes with time (not a symmetry orbit)")
        return x

    off = [c for c in cons if not is_zero(restricted(along(c, "a constraint")), values)]
    if off:
        raise NotEquilibriumError(f"the point {show_point(point)} violates the constraint "
                                  f"{sp.sstr(off[0])} = 0")
    n, mh = len(dyn.q), len(cons)
    A = dyn.velocity_jacobian.applyfunc(lambda x: along(x, "a constraint's direction"))
    rows = [along(c, "a constraint") for c in dyn.velocity_rows]
    broken = [c for c in rows if not is_zero(restricted(c), values)]
    if broken:
        raise NotEquilibriumError(f"the motion {show_point(point)} with rates "
                                  f"{show_point(moving)} breaks a velocity constraint "
                                  f"({sp.sstr(broken[0])[:120]} is left)")
    zeroth, M, C, K, F = eq.expand(point, moving, given)
    lam, tangential = multipliers_at(zeroth[:n], A)
    bad = [r for r in tangential if not is_zero(restricted(r), values)]
    if bad:
        raise NotEquilibriumError(f"the point {show_point(point)} is not an equilibrium (or "
                                  f"steady motion): a force the constraints cannot take, "
                                  f"{sp.sstr(bad[0])[:120]}, is left there")
    lam = lam.applyfunc(sp.cancel)
    # the constraint forces Aᵀμ* turn with the state: a stiffness H; the constraints'
    # rows' dependence on q at the motion's rates: D
    force = dyn.velocity_jacobian.T * lam
    H = sp.Matrix(n, n, lambda i, k: along(sp.diff(force[i], dyn.q[k]), "a constraint force"))
    D = sp.Matrix(len(rows), n, lambda j, k: along(sp.diff(dyn.velocity_rows[j], dyn.q[k]),
                                                     "a constraint"))
    Kc = K - H
    if mh:
        Nh, ind = _null_basis(A[:mh, :], _independent(A[:mh, :], dyn.q, values))
        drift = (D[:mh, :] * Nh).applyfunc(sp.cancel)
        if any(not is_zero(x, values) for x in drift):
            raise UnsupportedError("linearization about a motion along which the holonomic "
                                   "constraints' normals turn")
    else:
        Nh, ind = sp.eye(n), list(range(n))
    coords = [dyn.q[i] for i in ind]
    k = Nh.cols
    Av, Dv = (A[mh:, :] * Nh), (D[mh:, :] * Nh)
    mv = Av.rows
    if mv:
        # the dependent speeds: those of ignorable coordinates first (a rolling body's
        # centre follows its turning): then the ignorable states drop out of the
        # linearization whole, with their zero exponents (engine.state_space)
        dep_s = _independent(Av, coords, values, _ignorable(dyn, A, coords))
        ind_s = [i for i in range(k) if i not in dep_s]
        T = sp.zeros(k, k - mv)
        R = sp.zeros(k, k)
        for j, i in enumerate(ind_s):
            T[i, j] = 1
        inv_d = Av[:, dep_s]
        Td = -inv_d.LUsolve(Av[:, ind_s])
        Rd = -inv_d.LUsolve(Dv)
        for r, i in enumerate(dep_s):
            for j in range(k - mv):
                T[i, j] = sp.cancel(Td[r, j])
            for j in range(k):
                R[i, j] = sp.cancel(Rd[r, j])
    else:
        ind_s = list(range(k))
        T, R = sp.eye(k), sp.zeros(k, k)
    P = Nh * T
    Pt = P.T

    def tidy(X: sp.Matrix) -> sp.Matrix:  # cos² + sin² collapsed, then one fraction
        return X.applyfunc(lambda x: sp.cancel(trig_canonical(x)))

    Mr = tidy(Pt * M * P)
    if not mv:  # second order over δs: a LinearSystem, as at rest
        return LinearSystem(dyn, dict(point), Mr, tidy(Pt * C * Nh), tidy(Pt * Kc * Nh),
                            tidy(Pt * F), dict(moving), coords=coords, embedding=Nh)
    MN, CN = M * Nh, C * Nh
    low_s = tidy(-Pt * (MN * R * R + CN * R + Kc * Nh))
    low_u = tidy(-Pt * (MN * R * T + CN * T))
    d = k - mv
    E = sp.diag(sp.eye(k), Mr)
    Ahat = sp.Matrix.vstack(sp.Matrix.hstack(R, T), sp.Matrix.hstack(low_s, low_u))
    f = sp.Matrix.vstack(sp.zeros(k, 1), tidy(Pt * F))
    speeds = [dyn.qd[dyn.q.index(coords[i])] for i in ind_s]
    assert len(speeds) == d
    return StateSpaceSystem(dyn, dict(point), E, Ahat, f, coords, speeds, Nh, (T, R),
                            dict(moving))


def _ignorable(dyn, A: sp.Matrix, coords: list) -> list[int]:
    """Indices (in `coords`) of the coordinates absent from L, the forces and the
    constraints' directions: their positions enter no equation."""
    absent = set(dyn.q) - dyn.L.free_symbols
    absent -= set().union(*(f.free_symbols for f in dyn.sys.forces))
    absent -= set().union(*(x.free_symbols for x in dyn.velocity_jacobian))
    absent -= set().union(*(c.free_symbols for c in dyn.velocity_rows))
    return [i for i, q in enumerate(coords) if q in absent]


def _null_basis(G: sp.Matrix, dep: list[int]) -> tuple[sp.Matrix, list[int]]:
    """(N, independent columns): N = [I; −G_dep⁻¹G_ind] in the system's order, so that
    δq = N·δs over the independent coordinates and G·N = 0."""
    m, n = G.shape
    ind = [i for i in range(n) if i not in dep]
    N = sp.zeros(n, n - m)
    for j, i in enumerate(ind):
        N[i, j] = 1
    solved = -G[:, dep].LUsolve(G[:, ind])
    for r, i in enumerate(dep):
        for j in range(n - m):
            N[i, j] = sp.cancel(solved[r, j])
    return N, ind
