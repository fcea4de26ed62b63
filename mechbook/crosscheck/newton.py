"""Cross-check: the engine's Lagrange equations against Newton's and Euler's.

For a system built from particles and rigid bodies, the engine's Lagrange expressions E_i
must equal Σ (∂r/∂q_i)·(m r̈ − F) over particles (F: gravity and two-ended springs, as
Cartesian forces) plus, for rigid bodies, the Euler terms (∂ω/∂q̇_i)·(I ω̇ + ω × Iω);
whatever the file gives other than as particles and bodies (`kinetic`, `potential`,
`lagrangian`, `velocity_potential`, springs given by `length`, `forces`) enters through its
own Lagrange expression, read from the file again. Compared at random states and
accelerations (off-shell, so constraint forces do not enter) and perturbed parameters, to
1e-9 relative.

Independent of the engine's kinematics: the bodies' angular velocities and inertia tensors
are computed here their own way (mechbook.crosscheck.kinematics), never by the engine's
`mechbook.model.bodies`, so a wrong inertia or body rate there cannot pass both sides.
"""

from __future__ import annotations

import time

import numpy as np
import sympy as sp

from mechbook.core.compile import compile_exprs
from mechbook.crosscheck.kinematics import body_angular_velocity, inertia_of_shape
from mechbook.engine.analysis import Analysis
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.records import CrossCheck

NEWTON_TOL = 1e-9

# ---- Newton's second law -----------------------------------------------------------------------
def newton_crosscheck(analysis: Analysis, system_name: str | None = None,
                      samples: int = 6) -> CrossCheck:
    """Lagrange's equations of the engine against Newton's (and Euler's) in Cartesian form."""
    start = time.perf_counter()
    sys = analysis.system(system_name)
    out = CrossCheck(f"newton:{sys.name}", "newton", sys.name)
    try:
        _newton(analysis, sys, out, samples)
    except UnsupportedError as exc:
        out.status, out.detail = "n.a.", exc.capability
    except (MechbookError, ValueError, TypeError, np.linalg.LinAlgError) as exc:
        out.status, out.detail = "error", f"{type(exc).__name__}: {exc}"
    out.seconds = time.perf_counter() - start
    return out


def _newton_residual(sys) -> list[sp.Expr]:
    """Σ J·(m r̈ − F) + rigid-body Euler terms + the Lagrange expressions of everything the
    file gives other than particles and bodies − Q."""
    spec = sys.spec
    if "approximation" in spec:
        raise UnsupportedError("Newton cross-check: the Lagrangian is an approximation "
                               "(Newton's law holds for the exact one)")
    particles = dict(spec.get("particles") or {})
    bodies = dict(spec.get("rigid_bodies") or {})
    if not particles and not bodies:
        raise UnsupportedError("Newton cross-check: no particle or body positions (T and V "
                               "are given directly)")
    parse = sys._parse  # the system's own safe parser, at the file's paths
    q, qd = sys.q, sys.qd
    n = len(q)
    forces: dict[str, sp.Matrix] = {}
    positions = {name: sys.positions[name] for name in list(particles) + list(bodies)}
    masses = {name: sys.masses[name] for name in positions}
    for name, r in positions.items():
        forces[name] = sp.zeros(r.rows, 1)
    if "gravity" in spec:
        grav = spec["gravity"] or {}
        g = parse(grav["g"], ("gravity", "g")) if "g" in grav else sys.params["g"].symbol
        for name, r in positions.items():
            up = (sp.Matrix([parse(x, ("gravity", "up", i)) for i, x in enumerate(grav["up"])])
                  if "up" in grav else sp.Matrix([0] * (r.rows - 1) + [1]))
            forces[name] += -masses[name] * g * up
    rest = sp.S.Zero  # Lagrangian terms not given as particles or bodies
    for i, spring in enumerate(spec.get("springs") or []):
        k = parse(spring["k"], ("springs", i, "k"))
        natural = (parse(spring["natural_length"], ("springs", i, "natural_length"))
                   if "natural_length" in spring else sp.S.Zero)
        if "length" in spring:
            length = parse(spring["length"], ("springs", i, "length"))
            rest -= k * (length - natural) ** 2 / 2
            continue
        ends = []
        for j, end in enumerate(spring["between"]):
            ends.append((end, positions[end]) if isinstance(end, str) else
                        (None, sp.Matrix([parse(x, ("springs", i, "between", j, m))
                                          for m, x in enumerate(end)])))
        d = ends[0][1] - ends[1][1]
        length = sp.sqrt(d.dot(d))
        pull = -k * (length - natural) / length * d  # force on the first end
        if ends[0][0] is not None:
            forces[ends[0][0]] += pull
        if ends[1][0] is not None:
            forces[ends[1][0]] -= pull
    for key in ("kinetic", "lagrangian"):
        if key in spec:
            rest += parse(spec[key], (key,))
    for key in ("potential", "velocity_potential"):
        if key in spec:
            rest -= parse(spec[key], (key,))
    res = [sp.S.Zero] * n
    for name, r in positions.items():
        acc = sys.dt(sys.dt(r))
        net = masses[name] * acc - forces[name]
        for i in range(n):
            res[i] += sp.diff(r, q[i]).dot(net)
    for name, b in bodies.items():
        rot = _euler_terms(sys, name, b, masses[name], parse)
        for i in range(n):
            res[i] += rot[i]
    for i in range(n):
        res[i] += sys.dt(sp.diff(rest, qd[i])) - sp.diff(rest, q[i]) - sys.forces[i]
    return res


def _euler_terms(sys, name: str, b: dict, m, parse) -> list[sp.Expr]:
    """(∂ω/∂q̇_i)·(I ω̇ + ω × Iω) (3-D, body axes) or (∂ω/∂q̇_i) I ω̇ (planar)."""
    sub = ("rigid_bodies", name)
    planar = len(b["position"]) == 2
    inertia = b["inertia"]
    if isinstance(inertia, dict):
        dims = {k: parse(v, sub + ("inertia", k)) for k, v in inertia.items()
                if k in ("radius", "length")}
        if "sides" in inertia:
            dims["sides"] = [parse(v, sub + ("inertia", "sides", i))
                             for i, v in enumerate(inertia["sides"])]
        tensor = inertia_of_shape(inertia["shape"], m, dims)
    elif isinstance(inertia, list):
        tensor = sp.Matrix([[parse(x, sub + ("inertia", i, j)) for j, x in enumerate(row)]
                            for i, row in enumerate(inertia)])
    else:
        tensor = parse(inertia, sub + ("inertia",))
    if planar:
        moment = tensor[2, 2] if isinstance(tensor, sp.MatrixBase) else tensor
        omega = parse(b["angular_velocity"], sub + ("angular_velocity",))
        return [sp.diff(omega, v) * moment * sys.dt(omega) for v in sys.qd]
    if "euler_angles" in b:
        angles = [parse(x, sub + ("euler_angles", i)) for i, x in enumerate(b["euler_angles"])]
        omega = body_angular_velocity(angles, sys.dt)
    else:
        omega = sp.Matrix([parse(x, sub + ("angular_velocity", i))
                           for i, x in enumerate(b["angular_velocity"])])
    torque = tensor * sys.dt(omega) + omega.cross(tensor * omega)
    return [sp.diff(omega, v).dot(torque) for v in sys.qd]


def _newton(analysis: Analysis, sys, out: CrossCheck, samples: int) -> None:
    dyn = analysis.dynamics(sys.name)
    newton = _newton_residual(sys)
    engine = list(dyn.residuals)
    params = [p.symbol for p in sys.params.values()]
    free = [s for trio in sys.free_driven for s in trio]
    args = [sys.t, *sys.q, *sys.qd, *sys.qdd, *free, *params]
    exprs = engine + newton
    stray = set().union(*(e.free_symbols for e in exprs)) - set(args)
    if stray:
        raise UnsupportedError("Newton cross-check: symbols without values: "
                               + ", ".join(sorted(map(str, stray))))
    fn, _ = compile_exprs(args, exprs)
    n = len(sys.q)
    rng = np.random.default_rng(20261123)
    base = np.array([p.value for p in sys.params.values()])
    positive = np.array([p.positive for p in sys.params.values()])
    worst, used = 0.0, 0
    for _ in range(40 * samples):
        if used >= samples:
            break
        pv = np.where(positive, base * np.exp(rng.uniform(-0.3, 0.3, len(base))),
                      base + rng.uniform(-0.3, 0.3, len(base)))
        x = np.concatenate(([rng.uniform(0, 1)], rng.uniform(0.05, 0.6, n),
                            rng.uniform(-1, 1, 2 * n), rng.uniform(-1, 1, len(free)), pv))
        with np.errstate(all="ignore"):
            val = fn(x)
        if not np.all(np.isfinite(val)):
            continue
        e, nw = val[:n], val[n:]
        scale = max(float(np.max(np.abs(e))), float(np.max(np.abs(nw))), 1e-300)
        worst = max(worst, float(np.max(np.abs(e - nw))) / scale)
        used += 1
    if used < 3:
        raise MechbookError("Newton cross-check: the equations do not evaluate at random "
                            "states")
    out.error = worst
    out.status = "pass" if worst < NEWTON_TOL else "fail"
    what = []
    spec = sys.spec
    if spec.get("particles"):
        what.append("particles")
    if spec.get("rigid_bodies"):
        what.append("rigid bodies (Euler)")
    other = [k for k in ("kinetic", "potential", "lagrangian", "velocity_potential", "forces",
                         "dissipation") if k in spec]
    if any("length" in s for s in spec.get("springs") or []):
        other.append("length springs")
    out.detail = (f"E = Jᵀ(m r̈ − F) over {' and '.join(what)} at {used} random states, "
                  f"max relative difference {worst:.1e}"
                  + (f"; as generalized forces: {', '.join(other)}" if other else ""))


