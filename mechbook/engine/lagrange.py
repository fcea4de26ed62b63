"""Lagrange's and Hamilton's equations of a system, derived once and cached.

Sign conventions (tested against Newton's law): the Euler–Lagrange residual of coordinate i is
    E_i = d/dt(∂L/∂q̇_i) − ∂L/∂q_i − Q_i − Σ_j λ_j ∂f_j/∂q_i,
and the equations of motion are E = 0, i.e. M(q,t)·q̈ = f(q,q̇,t) + Aᵀλ with A = ∂f/∂q.
λ_j ∂f_j/∂q_i is the generalized force that constraint j exerts on coordinate i.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cached_property

import sympy as sp

from mechbook.core.numeval import is_zero
from mechbook.core.secalc import SymEngineCannot, euler_lagrange
from mechbook.core.timeout import Timeout, time_limit, try_simplify
from mechbook.engine.affine import solve_unknowns
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.model.protocol import SystemLike
from mechbook.model.system import motion_chains


class SingularMassError(MechbookError):
    """The equations do not determine every acceleration: M (with the constraint rows) is
    singular, as when a coordinate carries no kinetic energy."""


def solve_accelerations(M: sp.Matrix, rhs: sp.Matrix, unknowns: list) -> sp.Matrix:
    """M·x = rhs solved for `unknowns`; a singular M is a SingularMassError that names the
    unknowns whose rows of M vanish (the usual cause), not a SymPy traceback."""
    try:
        return M.LUsolve(rhs)
    except (sp.matrices.exceptions.NonInvertibleMatrixError, ValueError,
            ZeroDivisionError) as exc:
        empty = [str(u) for i, u in enumerate(unknowns[: M.rows])
                 if all(is_zero(M[i, j]) for j in range(M.cols))]
        why = (f"no inertia for {', '.join(empty)}" if empty else
               "its rows are dependent")
        raise SingularMassError(f"the mass matrix is singular ({why}): the Lagrangian does "
                                f"not determine every acceleration [{exc}]") from None


def lagrange_expressions(system: SystemLike, L: sp.Expr,
                         forces: Sequence[sp.Expr] | None = None) -> list[sp.Expr]:
    """expand(d/dt(∂L/∂q̇_i) − ∂L/∂q_i − Q_i) for each coordinate of `system` (Q = 0 when
    `forces` is None), d/dt along the system's motion (its free driven coordinates too);
    by SymEngine (core.secalc, ten times sooner) where it can, else by SymPy."""
    forces = list(forces) if forces is not None else [sp.S.Zero] * len(system.q)
    chains, stop = motion_chains(system)
    try:
        return euler_lagrange(L, system.q, system.qd, chains, system.t, forces, stop)
    except SymEngineCannot:
        pass
    out = []
    for q, qd, force in zip(system.q, system.qd, forces, strict=True):
        e = system.dt(sp.diff(L, qd)) - sp.diff(L, q) - force
        out.append(sp.expand(e))
    return out


class Dynamics:
    """Equations of motion, momenta, conserved quantities and the Hamiltonian of a system."""

    def __init__(self, system: SystemLike, simplify: bool = False):
        self.sys: SystemLike = system  # a System, or one reduced by Routh
        self.simplify = simplify
        self.q, self.qd, self.qdd = system.q, system.qd, system.qdd
        self.L = system.lagrangian

    def _simp(self, expr):
        """Simplified for a human reader (`simplify=True`: `mechbook solve`); the checks
        and cross-checks work on the raw expressions, which are equal and far cheaper."""
        return try_simplify(expr) if self.simplify else expr

    # ---- Lagrange ------------------------------------------------------------------------
    @cached_property
    def momenta(self) -> list[sp.Expr]:
        """Generalized momenta p_i = ∂L/∂q̇_i."""
        return [self._simp(sp.diff(self.L, v)) for v in self.qd]

    @cached_property
    def residuals(self) -> list[sp.Expr]:
        """E_i without constraint forces (see module docstring), differentiated and expanded
        by SymEngine (core.secalc, ten times sooner) where it can, else by SymPy."""
        return lagrange_expressions(self.sys, self.L, self.sys.forces)

    @cached_property
    def mass_matrix(self) -> sp.Matrix:
        """M_ij = ∂E_i/∂q̈_j."""
        return sp.Matrix([[self._simp(sp.diff(e, a)) for a in self.qdd] for e in self.residuals])

    @cached_property
    def forcing(self) -> sp.Matrix:
        """f in M·q̈ = f (everything but the accelerations, moved to the right)."""
        zero = {a: sp.S.Zero for a in self.qdd}
        return sp.Matrix([self._simp(-e.xreplace(zero)) for e in self.residuals])

    @cached_property
    def constraint_jacobian(self) -> sp.Matrix:
        """∂g/∂q of the holonomic constraints g(q, t) = 0 (m_h × n)."""
        cons = [f for _, f in self.sys.constraints]
        return sp.Matrix([[sp.diff(f, q) for q in self.q] for f in cons]) if cons else sp.zeros(0,
                                                                                              len(self.q))

    @property
    def constrained(self) -> bool:
        """Whether any constraint, holonomic or on the velocities, is held by multipliers."""
        return bool(self.sys.constraints or self.sys.velocity_constraints)

    @cached_property
    def velocity_jacobian(self) -> sp.Matrix:
        """A of every constraint at the velocity level, A(q, t)·q̇ + b(q, t) = 0: the
        holonomic constraints' ∂g/∂q (their ġ), then the velocity constraints' ∂c/∂q̇.
        The multipliers (`multipliers`, in the same order) exert the generalized force Aᵀλ."""
        rows = [sp.Matrix([[sp.diff(c, v) for v in self.qd]])
                for _, c in self.sys.velocity_constraints]
        return sp.Matrix.vstack(self.constraint_jacobian, *rows) if rows else \
            self.constraint_jacobian

    @cached_property
    def velocity_rows(self) -> list[sp.Expr]:
        """Every constraint at the velocity level, c(q, q̇, t) = A·q̇ + b (each must vanish
        along the motion): ġ of the holonomic ones, then the velocity constraints."""
        return ([self.sys.dt(g) for _, g in self.sys.constraints]
                + [c for _, c in self.sys.velocity_constraints])

    @cached_property
    def constraint_bias(self) -> sp.Matrix:
        """The rest of dc/dt once A·q̈ is taken out: A·q̈ + bias = 0 along the motion (g̈ of
        the holonomic constraints, ċ of the velocity constraints, at q̈ = 0)."""
        zero = {a: 0 for a in self.qdd}
        return sp.Matrix([self.sys.dt(self.sys.dt(fc)).subs(zero) for _, fc in self.sys.constraints]
                         + [self.sys.dt(c).subs(zero) for _, c in self.sys.velocity_constraints])

    @cached_property
    def multipliers(self) -> list[sp.Symbol]:
        """λ of each constraint (the holonomic ones, then those on the velocities)."""
        return [sp.Symbol(f"lambda_{name}", real=True)
                for name, _ in list(self.sys.constraints) + list(self.sys.velocity_constraints)]

    @cached_property
    def solved(self) -> dict:
        """Accelerations (and multipliers) solved as functions of q, q̇, t: with constraints,
        M·q̈ − Aᵀλ = f and A·q̈ = −bias together (valid on the constraint manifold)."""
        n = len(self.q)
        M, f = self.mass_matrix, self.forcing
        if not self.constrained:
            try:
                with time_limit(60):
                    sol = solve_accelerations(M, f, list(self.qdd))
            except Timeout:
                raise UnsupportedError("solving the mass matrix symbolically (too large: past "
                                       "its time limit of 60 s of CPU)") from None
            return {a: self._simp(s) for a, s in zip(self.qdd, sol, strict=True)}
        A = self.velocity_jacobian
        b = self.constraint_bias
        m = A.rows
        big = sp.zeros(n + m, n + m)
        big[:n, :n] = M
        big[:n, n:] = -A.T
        big[n:, :n] = A
        rhs = sp.Matrix.vstack(f, -b)
        unknowns = list(self.qdd) + self.multipliers
        sol = solve_accelerations(big, rhs, unknowns)
        return {u: self._simp(s) for u, s in zip(unknowns, sol, strict=True)}

    @cached_property
    def accelerations(self) -> list[sp.Expr]:
        return [self.solved[a] for a in self.qdd]

    def on_shell(self, expr: sp.Expr) -> sp.Expr:
        """Replace accelerations in `expr` by their values from the equations of motion."""
        return expr.subs({a: self.solved[a] for a in self.qdd})

    # ---- conservation --------------------------------------------------------------------
    @cached_property
    def cyclic(self) -> dict[sp.Symbol, sp.Expr]:
        """Ignorable coordinates (absent from L, no force, no constraint) and their momenta."""
        cons = [f for _, f in self.sys.constraints]
        held = [c for _, c in self.sys.velocity_constraints]  # no force along q: c free of q̇
        out = {}
        for q, v, p, force in zip(self.q, self.qd, self.momenta, self.sys.forces, strict=True):
            if (force == 0 and all(sp.diff(c, q) == 0 for c in cons)
                    and all(sp.diff(c, v) == 0 for c in held)
                    and is_zero(sp.diff(self.L, q))):
                out[q] = p
        return out

    @cached_property
    def energy_function(self) -> sp.Expr:
        """h = Σ q̇ ∂L/∂q̇ − L."""
        h = sum((v * p for v, p in zip(self.qd, self.momenta, strict=True)), sp.S.Zero) - self.L
        return self._simp(h)

    @cached_property
    def energy_power(self) -> sp.Expr:
        """dh/dt along the motion = −∂L/∂t + Σ Q_i q̇_i (zero means h is conserved)."""
        power = -sp.diff(self.L, self.sys.t)
        power += sum((f * v for f, v in zip(self.sys.forces, self.qd, strict=True)), sp.S.Zero)
        if any(sp.diff(f, self.sys.t) != 0 for _, f in self.sys.constraints):
            return sp.nan  # moving constraints do work; not decided here
        rest = {v: 0 for v in self.qd}
        if any(c.has(self.sys.t) or not is_zero(c.xreplace(rest))
               for _, c in self.sys.velocity_constraints):
            return sp.nan  # A·q̇ + b = 0 with b ≠ 0 (a turntable): its force does work
        return self._simp(power)

    @property
    def energy_conserved(self) -> bool:
        power = self.energy_power
        return power is not sp.nan and is_zero(power)

    # ---- Hamilton ------------------------------------------------------------------------
    @cached_property
    def p(self) -> list[sp.Symbol]:
        return [sp.Symbol("p_" + q.name, real=True) for q in self.q]

    @cached_property
    def velocities_of_momenta(self) -> dict[sp.Symbol, sp.Expr]:
        """q̇(q, p, t) from p = ∂L/∂q̇: with T quadratic in the velocities p = M·q̇ + a, a
        linear system in the mass matrix (engine.affine: LU, milliseconds); SymPy's solve
        otherwise. A time limit that runs out is said so (UnsupportedError)."""
        eqs = [mom - pi for pi, mom in zip(self.p, self.momenta, strict=True)]
        sol = solve_unknowns(eqs, self.qd, "Legendre transform: q̇ from p = ∂L/∂q̇", 60)
        return {v: self._simp(sol[v]) for v in self.qd}

    @cached_property
    def hamiltonian(self) -> sp.Expr:
        """H(q, p, t) = h expressed in the momenta."""
        return self._simp(self.energy_function.subs(self.velocities_of_momenta))

    @cached_property
    def hamilton_equations(self) -> tuple[list[sp.Expr], list[sp.Expr]]:
        """(q̇ = ∂H/∂p, ṗ = −∂H/∂q + Q)."""
        H = self.hamiltonian
        qdot = [self._simp(sp.diff(H, pi)) for pi in self.p]
        forces = [f.subs(self.velocities_of_momenta) for f in self.sys.forces]
        pdot = [self._simp(-sp.diff(H, q) + f) for q, f in zip(self.q, forces, strict=True)]
        return qdot, pdot
