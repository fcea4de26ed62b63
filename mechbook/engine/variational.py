"""The calculus of variations of a declared functional, symbolically: the Euler–Lagrange
equations, Legendre's matrix, the coefficients of the Jacobi (accessory) equation, and
first integrals (Beltrami's, Noether's for a stated symmetry).

Everything is an expression in the jet symbols of mechbook.model.functional (x, y, y′, y″,
…): the total derivative D = ∂x + Σ y⁽ᵏ⁺¹⁾ ∂y⁽ᵏ⁾ turns ∂F/∂y′ into d/dx ∂F/∂y′ without
functions of x. Constraints enter through their multipliers: F̃ = F + Σ λ·G + Σ μ·φ.
"""

from __future__ import annotations

import sympy as sp

from mechbook.errors import UnsupportedError
from mechbook.model.functional import Functional


def total_derivative(expr: sp.Expr, fn: Functional) -> sp.Expr:
    """d/dx of `expr` along a curve: ∂x + Σ y⁽ᵏ⁺¹⁾·∂/∂y⁽ᵏ⁾ (the jets carried to order 2n).

    Example: D(y′·y) = y′² + y·y″.
    """
    out = sp.diff(expr, fn.x)
    used = expr.free_symbols
    for jet in fn.jets:
        for k in range(len(jet) - 1):
            if jet[k] in used:
                out += jet[k + 1] * sp.diff(expr, jet[k])
    return out


def augmented(fn: Functional) -> sp.Expr:
    """F̃ = F + Σ λ_c·G_c (isoperimetric) + Σ μ_c·φ_c (holonomic, μ a function of x)."""
    out = fn.integrand
    for c in fn.constraints:
        out += c.multiplier * c.expr
    return out


def euler_lagrange(fn: Functional, integrand: sp.Expr | None = None) -> list[sp.Expr]:
    """Σₖ (−D)ᵏ ∂F/∂y⁽ᵏ⁾ for each function, of `integrand` (default F̃): the equations
    E_i = 0 every extremal satisfies, each affine in the top derivative y⁽²ⁿ⁾."""
    F = augmented(fn) if integrand is None else integrand
    out = []
    for jet in fn.jets:
        e = sp.S.Zero
        for k in range(fn.order + 1):
            term = sp.diff(F, jet[k])
            for _ in range(k):
                term = -total_derivative(term, fn)
            e += term
        out.append(e)
    return out


def top_derivatives(fn: Functional) -> list[sp.Symbol]:
    """The highest derivatives the Euler–Lagrange equations hold (y″ for F(x, y, y′))."""
    return [jet[2 * fn.order] for jet in fn.jets]


def solved_top(equations: list[sp.Expr], top: list[sp.Symbol]) -> dict[sp.Symbol, sp.Expr]:
    """{y⁽²ⁿ⁾: its value} from equations affine in the top derivatives; UnsupportedError
    where they are not affine or do not determine them."""
    A = sp.Matrix([[sp.diff(e, s) for s in top] for e in equations])
    if any(sp.diff(a, s) != 0 for a in A for s in top):
        raise UnsupportedError("equations not affine in the highest derivatives")
    b = sp.Matrix([e.subs({s: 0 for s in top}) for e in equations])
    if A.shape[0] != A.shape[1] or A.det() == 0:
        raise UnsupportedError("equations that do not determine the highest derivatives")
    sol = A.LUsolve(-b)
    return {s: sol[i] for i, s in enumerate(top)}


def legendre_matrix(fn: Functional, integrand: sp.Expr | None = None) -> sp.Matrix:
    """∂²F̃/∂y⁽ⁿ⁾ᵢ∂y⁽ⁿ⁾ⱼ (n the integrand's order): positive definite along a minimum
    (Legendre's condition)."""
    F = augmented(fn) if integrand is None else integrand
    top = fn.function_symbols(fn.order)
    return sp.Matrix([[sp.diff(F, a, b) for b in top] for a in top])


def jacobi_coefficients(fn: Functional, integrand: sp.Expr | None = None):
    """(P, R, Q) of the second variation ½∫(h′ᵀPh′ + 2hᵀRh′ + hᵀQh) dx: P = F_{y′y′},
    R = F_{yy′}, Q = F_{yy} (first-order integrands only)."""
    if fn.order != 1:
        raise UnsupportedError("the Jacobi equation of an integrand with y″")
    F = augmented(fn) if integrand is None else integrand
    y, yp = fn.function_symbols(0), fn.function_symbols(1)
    P = sp.Matrix([[sp.diff(F, a, b) for b in yp] for a in yp])
    R = sp.Matrix([[sp.diff(F, a, b) for b in yp] for a in y])
    Q = sp.Matrix([[sp.diff(F, a, b) for b in y] for a in y])
    return P, R, Q


def beltrami(fn: Functional) -> sp.Expr:
    """F̃ − Σ y′ᵢ·∂F̃/∂y′ᵢ, constant along every extremal when F̃ holds no x (Noether's
    integral of the shift x → x + ε); UnsupportedError otherwise."""
    F = augmented(fn)
    if fn.order != 1:
        raise UnsupportedError("Beltrami's integral of an integrand with y″")
    if fn.x in F.free_symbols:
        raise UnsupportedError(f"Beltrami's integral: the integrand depends on {fn.x}")
    if any(c.kind == "holonomic" for c in fn.constraints):
        raise UnsupportedError("Beltrami's integral with a holonomic constraint")
    return F - sum((s * sp.diff(F, s) for s in fn.function_symbols(1)), sp.S.Zero)


def noether(fn: Functional, xi: sp.Expr, eta: list[sp.Expr]) -> tuple[sp.Expr, sp.Expr]:
    """(invariance residual, Noether's integral) of the generator ξ∂x + Σηᵢ∂yᵢ (ξ, η in
    x and the functions): the residual pr⁽¹⁾X(F̃) + F̃·Dξ vanishes for a symmetry, and then
    I = Σ ∂F̃/∂y′ᵢ·(ηᵢ − y′ᵢξ) + F̃ξ is constant along every extremal."""
    if fn.order != 1:
        raise UnsupportedError("Noether's integral of an integrand with y″")
    F = augmented(fn)
    dxi = total_derivative(xi, fn)
    y, yp = fn.function_symbols(0), fn.function_symbols(1)
    residual = xi * sp.diff(F, fn.x) + F * dxi
    for yi, ypi, e in zip(y, yp, eta, strict=True):
        residual += e * sp.diff(F, yi) + (total_derivative(e, fn) - ypi * dxi) * sp.diff(F, ypi)
    charge = F * xi + sum((sp.diff(F, ypi) * (e - ypi * xi)
                           for ypi, e in zip(yp, eta, strict=True)), sp.S.Zero)
    return residual, charge


def on_shell_rate(fn: Functional, expr: sp.Expr) -> sp.Expr:
    """D(expr) with the top derivatives given by the Euler–Lagrange equations: zero exactly
    when `expr` is a first integral (constant along every extremal)."""
    if any(c.kind == "holonomic" for c in fn.constraints):
        raise UnsupportedError("first integrals with a holonomic constraint")
    top = top_derivatives(fn)
    sol = solved_top(euler_lagrange(fn), top)
    rate = total_derivative(expr, fn)
    if any(s in rate.free_symbols for jet in fn.jets for s in jet[2 * fn.order + 1:]):
        raise UnsupportedError("a first integral holding derivatives above the equation's "
                               "order")
    return rate.subs(sol)
