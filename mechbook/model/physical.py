"""Refusing systems that are not physical: a mass that is not positive, a kinetic energy that
is not positive definite in the velocities.

A negative or zero mass, or a coordinate with no inertia, makes the mass matrix indefinite or
singular; the engine then fails deep inside (a Cholesky factorization, an eigensolver) and
every part would report that instead of the cause. The file is refused when its system is
built (`mechbook validate`, and before any part of `mechbook check`), with the reason and the
line: each particle's and body's mass must be positive at the parameters' values, and the
Hessian of the Lagrangian in the velocities (the mass matrix) must be positive definite at
some of a few random points. A system whose Lagrangian holds no velocity at all (a statics
problem: equilibria of a potential) has no mass matrix and is not judged.
"""

from __future__ import annotations

import random

import numpy as np
import sympy as sp

POINTS = 5  # random points; refused only if the mass matrix is not positive definite at all
SEED = 20260521


def check_physical(system) -> None:
    """SpecError (file:line, what is wrong, how to fix) if `system` is not physical."""
    values = system.numeric_values()
    _masses(system, values)
    _mass_matrix(system, values)


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
    if not qd or not lag.has(*qd):
        return  # no velocities: statics, nothing to judge
    hess = sp.Matrix(len(qd), len(qd), lambda i, j: sp.diff(lag, qd[i], qd[j]))
    # constraints f(q, t) = 0 leave only the velocities along them: the mass matrix must be
    # positive definite there (a massless pulley held by strings is physical)
    jac = sp.Matrix([[sp.diff(f, q) for q in system.q] for _, f in system.constraints])
    free = sorted((hess.free_symbols | jac.free_symbols) - set(values), key=str)
    rng = random.Random(SEED)
    seen = []
    for _ in range(POINTS):
        point = {**values, **{s: rng.uniform(0.3, 1.7) * rng.choice((1, -1)) if
                              s not in system.q else rng.uniform(-2.5, 2.5) for s in free}}
        try:
            m = np.array(hess.xreplace(point).evalf(15).tolist(), dtype=float)
            if jac.rows:
                j = np.array(jac.xreplace(point).evalf(15).tolist(), dtype=float)
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            continue
        if not np.all(np.isfinite(m)) or (jac.rows and not np.all(np.isfinite(j))):
            continue
        if jac.rows:  # the velocities the constraints allow: the null space of J
            _, sv, vt = np.linalg.svd(j)
            rank = int(np.sum(sv > 1e-10 * max(sv.max(initial=0.0), 1e-300)))
            basis = vt[rank:].T
            if basis.shape[1] == 0:
                return  # the constraints fix every coordinate: nothing moves
            m = basis.T @ m @ basis
        eig = np.linalg.eigvalsh((m + m.T) / 2)
        scale = max(np.max(np.abs(eig)), 1e-300)
        if eig[0] > 1e-10 * scale:
            return  # positive definite here: physical
        seen.append((eig, point))
    if not seen:
        return  # no point evaluated: judged later, by the engine, with its own messages
    eig, point = seen[0]
    zero = [] if jac.rows else [c for c, row in zip(system.coord_names, hess.tolist(),
                                                     strict=True)
                                if all(x.xreplace(values) == 0 for x in row)]
    where = ", ".join(f"{s}={point[s]:.3g}" for s in free) or "every point"
    if zero:
        why = (f"{', '.join(zero)} carr{'y' if len(zero) > 1 else 'ies'} no inertia (the "
               "kinetic energy does not depend on its velocity): every coordinate needs mass "
               "or inertia, or make it a constraint or a driven coordinate")
    elif eig[0] < 0:
        why = (f"the kinetic energy is not positive definite in the velocities (the mass "
               f"matrix has eigenvalue {eig[0]:.3g} at {where}): masses and moments of "
               "inertia must be positive")
    else:
        why = (f"the mass matrix is singular (eigenvalue {eig[0]:.3g} at {where}): some "
               "combination of velocities carries no kinetic energy")
    raise system.problem.doc.error(system.path + ("coordinates",),
                                   f"the system is not physical: {why}")
