"""Refusing systems that are not physical: a mass that is not positive, a kinetic energy that
is not positive definite in the velocities.

A negative or zero mass, or a coordinate with no inertia, makes the mass matrix indefinite or
singular; the engine then fails deep inside (a Cholesky factorization, an eigensolver) and
every part would report that instead of the cause. The file is refused when its system is
built (`mechbook validate`, and before any part of `mechbook check`), with the reason and the
line: each particle's and body's mass must be positive at the parameters' values, and the
Hessian of the Lagrangian in the velocities (the mass matrix), taken at rest, must be positive
definite at some of a few random points. A system with free coordinates whose Lagrangian holds
no velocity at all (`kinetic: 0`, or particles whose positions lost their coordinates) has no
inertia and is refused too; a kinetic energy that is not quadratic at rest (m*xdot**4) has a
singular mass matrix there, which is what the engine linearizes with.
"""

from __future__ import annotations

import random

import numpy as np
import sympy as sp

from mechbook.model.manifold import check_constraint_set

POINTS = 5  # random points; refused only if the mass matrix is not positive definite at all
SEED = 20260521


def check_physical(system) -> None:
    """SpecError (file:line, what is wrong, how to fix) if `system` is not physical."""
    values = system.numeric_values()
    _masses(system, values)
    _mass_matrix(system, values)
    check_constraint_set(system)  # dependent constraints; a rolling body off its surface


def _masses(system, values: dict) -> None:
    for kind, key in (("particles", "mass"), ("rigid_bodies", "mass")):
        for name, entry in (system.spec.get(kind) or {}).items():
            if not isinstance(entry, dict) or key not in entry:
                continue
            mass = system.masses.get(name) if kind == "particles" else None
            if mass is None:
                mass = system.problem.parse(entry[key], system.path + (kind, name, key),
                                            system.names)
            value = _number(mass.xreplace(values))
            if value is not None and value <= 0:
                raise system.problem.doc.error(
                    system.path + (kind, name, key),
                    f"mass {entry[key]} is {value:g} at the parameters' values: a mass must be "
                    "positive")


def _number(expr) -> float | None:
    try:
        value = complex(sp.N(expr, 15))
    except (TypeError, ValueError, ZeroDivisionError, OverflowError):
        return None
    return value.real if abs(value.imag) <= 1e-12 * max(1.0, abs(value.real)) else None


def _mass_matrix(system, values: dict) -> None:
    lag = system.lagrangian
    qd = list(system.qd)
    if not qd:
        return  # no free coordinate: nothing moves, nothing to judge
    if not lag.has(*qd):
        where = ("kinetic",) if "kinetic" in system.spec else ("coordinates",)
        raise system.problem.doc.error(
            system.path + where,
            "the system is not physical: its kinetic energy is zero (the Lagrangian holds no "
            f"velocity of {', '.join(system.coord_names)}): every coordinate needs mass or "
            "inertia, or make it a constraint or a driven coordinate")
    try:
        hess, jac, args = _derivatives(system)
    except Exception:  # noqa: BLE001 - SymEngine cannot take it: the engine judges later
        return
    rng = random.Random(SEED)
    known = {str(k): float(v) for k, v in values.items()}
    coords = {str(q) for q in system.q}
    velocities = {str(v) for v in qd}
    domains = {str(q): d for q, d in getattr(system, "domains", {}).items()}
    seen = []
    for _ in range(POINTS):
        point = {a: known[a] if a in known else (domains[a].sample(rng, values) if a in domains
                                                 else rng.uniform(-2.5, 2.5)) if a in coords
                 else rng.uniform(0.3, 1.7) * rng.choice((1, -1)) for a in args}
        # the mass matrix at rest (the velocities 0) where it evaluates: what the engine
        # linearizes with; a kinetic energy such as m*xdot**4 has none there
        at = _evaluated(hess, jac, args, {a: 0.0 if a in velocities else v
                                          for a, v in point.items()}) \
            or _evaluated(hess, jac, args, point)
        if at is None:
            continue
        m, j = at
        full = m
        if j.size:  # the velocities the constraints allow: the null space of J
            norms = np.linalg.norm(j, axis=1)  # each row to unit length: a constraint's
            j = j[norms > 0] / norms[norms > 0, None]  # scale (1e-12·(ẏ − ẋ)) is no rank
            _, sv, vt = np.linalg.svd(j) if j.size else (None, np.zeros(0), np.eye(len(m)))
            rank = int(np.sum(sv > 1e-10 * max(sv.max(initial=0.0), 1e-300)))
            basis = vt[rank:].T
            if basis.shape[1] == 0:
                return  # the constraints fix every coordinate: nothing moves
            m = basis.T @ m @ basis
        eig = np.linalg.eigvalsh((m + m.T) / 2)
        scale = max(np.max(np.abs(eig)), 1e-300)
        if eig[0] > 1e-10 * scale:
            return  # positive definite here: physical
        seen.append((eig, full, point))
    if not seen:
        return  # no point evaluated: judged later, by the engine, with its own messages
    _refuse(system, seen, bool(jac), sorted(set(args) - set(known)))


def _derivatives(system) -> tuple[list, list, list[str]]:
    """The Hessian of L in the velocities and the constraints' Jacobian, by SymEngine
    (SymPy takes seconds per entry on a long chain's Lagrangian; SymEngine milliseconds),
    and the names of their arguments."""
    import symengine as se

    lag = se.sympify(system.lagrangian)
    vel = [se.sympify(v) for v in system.qd]
    grad = [lag.diff(v) for v in vel]
    hess = [[grad[i].diff(vel[j]) for j in range(len(vel))] for i in range(len(vel))]
    coords = [se.sympify(q) for q in system.q]
    jac = [[se.sympify(f).diff(q) for q in coords] for _, f in system.constraints]
    jac += [[se.sympify(c).diff(v) for v in vel]  # A of A·q̇ + b = 0: a function of q
            for _, c in getattr(system, "velocity_constraints", [])]
    args = set()
    for e in [x for row in hess + jac for x in row]:
        args |= {str(a) for a in e.free_symbols}
    return hess, jac, sorted(args)


def _evaluated(hess: list, jac: list, args: list[str], point: dict):
    """(mass matrix, constraints' Jacobian) at `point` if every entry is finite, else None."""
    try:
        m, j = _at(hess, jac, args, point)
    except (TypeError, ValueError, ZeroDivisionError, OverflowError, RuntimeError):
        return None
    if not np.all(np.isfinite(m)) or not np.all(np.isfinite(j)):
        return None
    return m, j


def _at(hess: list, jac: list, args: list[str], point: dict) -> tuple[np.ndarray, np.ndarray]:
    import symengine as se

    subs = {se.Symbol(a): point[a] for a in args}
    m = np.array([[float(x.subs(subs)) for x in row] for row in hess])
    j = np.array([[float(x.subs(subs)) for x in row] for row in jac]) if jac else \
        np.zeros((0, len(hess)))
    return m, j


def _refuse(system, seen: list, constrained: bool, drawn: list[str]) -> None:
    eig, full, point = seen[0]
    zero = [] if constrained else [
        c for i, c in enumerate(system.coord_names)
        if all(np.all(np.abs(f[i]) <= 1e-12 * max(np.max(np.abs(f)), 1e-300))
               for _, f, _ in seen)]
    where = ", ".join(f"{a}={point[a]:.3g}" for a in drawn) or "every point"
    if zero:
        moving = [c for c, v in zip(system.coord_names, system.qd, strict=True)
                  if c in zero and system.lagrangian.has(v)]
        how = ("the kinetic energy has no part quadratic in its velocity, so none at rest"
               if moving else "the kinetic energy does not depend on its velocity")
        why = (f"{', '.join(zero)} carr{'y' if len(zero) > 1 else 'ies'} no inertia ({how}): "
               "every coordinate needs mass or inertia, or make it a constraint or a driven "
               "coordinate")
    elif eig[0] < 0:
        why = (f"the kinetic energy is not positive definite in the velocities (the mass "
               f"matrix has eigenvalue {eig[0]:.3g} at {where}): masses and moments of "
               "inertia must be positive")
    else:
        why = (f"the mass matrix is singular (eigenvalue {eig[0]:.3g} at {where}): some "
               "combination of velocities carries no kinetic energy")
    raise system.problem.doc.error(system.path + ("coordinates",),
                                   f"the system is not physical: {why}")
