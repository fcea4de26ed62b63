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

from dataclasses import dataclass
from functools import partial

import numpy as np
import sympy as sp

from mechbook.core.backends import FEW_CALLS_BACKEND
from mechbook.core.compile import compile_exprs
from mechbook.core.secalc import either, same
from mechbook.crosscheck.assembly import composite_inertia
from mechbook.crosscheck.contact import on_manifold
from mechbook.crosscheck.guard import guarded
from mechbook.crosscheck.kinematics import (
    body_angular_velocity,
    chain_angular_velocity,
    chain_matrix,
    inertia_of_shape,
)
from mechbook.engine.analysis import Analysis
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.model.system import motion_chains
from mechbook.records import CrossCheck, Status

NEWTON_TOL = 1e-9

# ---- Newton's second law -----------------------------------------------------------------------
def newton_crosscheck(analysis: Analysis, system_name: str | None = None,
                      samples: int = 6) -> CrossCheck:
    """Lagrange's equations of the engine against Newton's (and Euler's) in Cartesian form."""
    sys = analysis.system(system_name)
    out = CrossCheck(f"newton:{sys.name}", "newton", sys.name)
    with guarded(out):
        _newton(analysis, sys, out, samples)
    return out


def newton_residual(sys, symengine: bool = True, frames: dict | None = None) -> list:
    """Σ J·(m r̈ − F) + rigid-body Euler terms + the Lagrange expressions of everything the
    file gives other than particles and bodies − Q: SymEngine expressions where SymEngine
    can do the calculus, SymPy's where it cannot or `symengine` is False. `frames`, a dict,
    is filled with the bodies' frames computed on the way ({body: (inertia, ω, R)}: the
    check on the constraint manifold uses the same ones)."""
    spec = sys.spec
    if "approximation" in spec or "average" in spec:
        raise UnsupportedError("Newton cross-check: the Lagrangian is an approximation "
                               "(expanded or averaged; Newton's law holds for the exact one)")
    particles = dict(spec.get("particles") or {})
    bodies = dict(spec.get("rigid_bodies") or {})
    if not particles and not bodies:
        raise UnsupportedError("Newton cross-check: no particle or body positions (T and V "
                               "are given directly)")
    parse = sys.parse  # the system's own safe parser, at the file's paths
    n = len(sys.q)
    positions = {name: sys.positions[name] for name in list(particles) + list(bodies)}
    masses = {name: sys.masses[name] for name in positions}
    forces = _gravity(sys, spec, positions, masses, parse)
    rest = _springs(spec, positions, forces, parse) + _given_terms(spec, parse)
    frames = {} if frames is None else frames
    frames.update({name: _body_frame(sys, name, b, masses[name], parse)
                   for name, b in bodies.items()})
    pulls, attractor_q = _attractors(sys, spec, positions, masses, frames, parse)
    torque_q = _torques(sys, spec, frames, parse)
    friction_q = _friction(sys, spec, positions, frames, parse)
    given = [sys.declared_forces[i] + attractor_q[i] + torque_q[i] + friction_q[i]
             for i in range(n)]
    terms = _Terms(positions, masses, forces, frames, pulls, rest, given)
    build = partial(_assemble, sys, terms)
    return either(build) if symengine else build(same)  # SymEngine's calculus where it can


@dataclass
class _Terms:
    """What Newton's residual is assembled from, as SymPy objects."""

    positions: dict
    masses: dict
    forces: dict
    frames: dict
    pulls: dict
    rest: sp.Expr
    given: list  # generalized forces: declared, attractors' torques, torques, friction


def _assemble(sys, terms: _Terms, conv) -> list:
    """Σ (∂r/∂q_i)·(m r̈ − F) + Σ (∂ω/∂q̇_i)·(I ω̇ + ω × Iω) − pulls + the Lagrange
    expressions of `rest` − Q, in the algebra `conv` converts to: SymEngine's (`se.sympify`;
    `either` refuses its result where a derivative stays unevaluated) or SymPy's (the identity).
    The same few lines for both: `diff`, +, * and free_symbols are all either needs."""
    n = len(sys.q)
    q, qd = [conv(x) for x in sys.q], [conv(x) for x in sys.qd]
    t = conv(sys.t)
    pairs, stop = motion_chains(sys)
    chains = [(conv(a), conv(b)) for a, b in pairs]
    third = {conv(ydd) for ydd in stop}

    def dt(e):
        if third & e.free_symbols:
            raise UnsupportedError("third derivative of a free driven coordinate")
        out = e.diff(t)
        for x, v in chains:
            out += e.diff(x) * v
        return out

    def vec(m) -> list:
        return [conv(x) for x in m]

    def along(vectors: list, rate, other: list):  # Σ_k ∂v_k/∂rate · other_k
        return sum((v.diff(rate) * o for v, o in zip(vectors, other, strict=True)), conv(0))

    res = [conv(sp.S.Zero)] * n
    for name, r in terms.positions.items():
        rv, m = vec(r), conv(terms.masses[name])
        net = [m * dt(dt(x)) - f for x, f in zip(rv, vec(terms.forces[name]), strict=True)]
        res = [res[i] + along(rv, q[i], net) for i in range(n)]
    for tensor, omega, _ in terms.frames.values():
        inertia = [vec(tensor.row(a)) for a in range(tensor.rows)]
        w = vec(omega)
        torque = _times(inertia, [dt(x) for x in w])
        if len(w) == 3:  # + ω × Iω (a planar body's ω is one rate)
            iw = _times(inertia, w)
            torque = [a + b for a, b in zip(torque, _cross(w, iw), strict=True)]
        res = [res[i] + along(w, qd[i], torque) for i in range(n)]
    for name, pull in terms.pulls.items():
        res = [res[i] - along(vec(terms.positions[name]), q[i], vec(pull)) for i in range(n)]
    rest = conv(terms.rest)
    res = [res[i] + dt(rest.diff(qd[i])) - rest.diff(q[i]) - conv(terms.given[i])
           for i in range(n)]
    return res  # `either` refuses SymEngine's where it left a derivative unevaluated


def _times(matrix: list, v: list) -> list:
    return [sum((a * b for a, b in zip(row, v, strict=True)), 0 * v[0]) for row in matrix]


def _cross(a: list, b: list) -> list:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _gravity(sys, spec: dict, positions: dict, masses: dict, parse) -> dict[str, sp.Matrix]:
    """The Cartesian force of gravity on each particle and body (zero without `gravity:`)."""
    forces = {name: sp.zeros(r.rows, 1) for name, r in positions.items()}
    if "gravity" in spec:
        grav = spec["gravity"] or {}
        g = parse(grav["g"], ("gravity", "g")) if "g" in grav else sys.params["g"].symbol
        for name, r in positions.items():
            up = (sp.Matrix([parse(x, ("gravity", "up", i)) for i, x in enumerate(grav["up"])])
                  if "up" in grav else sp.Matrix([0] * (r.rows - 1) + [1]))
            forces[name] += -masses[name] * g * up
    return forces


def _springs(spec: dict, positions: dict, forces: dict, parse) -> sp.Expr:
    """Two-ended springs as Cartesian forces (added to `forces`); the Lagrangian terms of
    springs given by their `length` (returned)."""
    rest = sp.S.Zero
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
    return rest


def _given_terms(spec: dict, parse) -> sp.Expr:
    """The Lagrangian terms the file gives directly (`kinetic`, `lagrangian`, `potential`,
    `velocity_potential`)."""
    rest = sp.S.Zero
    for key in ("kinetic", "lagrangian"):
        if key in spec:
            rest += parse(spec[key], (key,))
    for key in ("potential", "velocity_potential"):
        if key in spec:
            rest -= parse(spec[key], (key,))
    return rest


def _friction(sys, spec: dict, positions: dict, frames: dict, parse) -> list[sp.Expr]:
    """Generalized forces of sliding friction (`friction:`): F = −μN v_t/|v_t| at the
    contact, whose material velocity is v_G + ω × (p − r_G) with this module's own ω (from
    Rᵀ·dR/dt) and R; Q_k = F·∂v/∂q̇_k."""
    out = [sp.S.Zero] * len(sys.q)
    for i, c in enumerate(spec.get("friction") or []):
        sub = ("friction", i)
        body = c["body"]
        r = positions[body]
        p = sp.Matrix([parse(x, sub + ("point", j)) for j, x in enumerate(c["point"])])
        v = sys.dt(r)
        if body in frames:
            _, omega, R = frames[body]
            d = p - r
            if R is None and omega.rows == 1:  # planar
                v = v + sp.Matrix([-omega[0] * d[1], omega[0] * d[0]])
            else:
                w = R * omega if R is not None else omega
                v = v + w.cross(d)
        n = (sp.Matrix([parse(x, sub + ("normal", j)) for j, x in enumerate(c["normal"])])
             if "normal" in c else sp.Matrix([0] * (r.rows - 1) + [1]))
        n = n / sp.sqrt(n.dot(n))
        vt = v - v.dot(n) * n
        F = -parse(c["mu"], sub + ("mu",)) * parse(c["normal_force"], sub + ("normal_force",)) \
            * vt / sp.sqrt(vt.dot(vt))
        for k, qd in enumerate(sys.qd):
            out[k] += F.dot(sp.diff(v, qd))
    return out


def _body_frame(sys, name: str, b: dict, m, parse):
    """(inertia, ω in body axes, R body -> space or None) of a body, computed here: ω from
    Rᵀ·dR/dt of the body's own rotation chain; for a planar body (moment, ω, None)."""
    sub = ("rigid_bodies", name)
    planar = len(b["position"]) == 2
    inertia = b["inertia"]
    if isinstance(inertia, dict) and "body" in inertia:  # a body made of parts
        tensor = composite_inertia(sys.problem, inertia["body"])[2]
    elif isinstance(inertia, dict):
        dims = {k: parse(v, sub + ("inertia", k)) for k, v in inertia.items()
                if k in ("radius", "length", "height")}
        for key in ("sides", "semi_axes"):
            if key in inertia:
                dims[key] = [parse(v, sub + ("inertia", key, i))
                             for i, v in enumerate(inertia[key])]
        tensor = inertia_of_shape(inertia["shape"], m, dims)
    elif isinstance(inertia, list):
        tensor = sp.Matrix([[parse(x, sub + ("inertia", i, j)) for j, x in enumerate(row)]
                            for i, row in enumerate(inertia)])
    else:
        tensor = parse(inertia, sub + ("inertia",))
    if planar:
        moment = tensor[2, 2] if isinstance(tensor, sp.MatrixBase) else tensor
        omega = parse(b["angular_velocity"], sub + ("angular_velocity",))
        return sp.Matrix([[moment]]), sp.Matrix([omega]), None
    R = None
    if "euler_angles" in b:
        angles = [parse(x, sub + ("euler_angles", i)) for i, x in enumerate(b["euler_angles"])]
        omega = body_angular_velocity(angles, sys.dt)
        R = chain_matrix(list(zip("zxz", angles, strict=True)))
    elif "rotation" in b:
        chain = [(axis, parse(angle, sub + ("rotation", i, 1)))
                 for i, (axis, angle) in enumerate(b["rotation"])]
        omega = chain_angular_velocity(chain, sys.dt)
        R = chain_matrix(chain)
    else:
        omega = sp.Matrix([parse(x, sub + ("angular_velocity", i))
                           for i, x in enumerate(b["angular_velocity"])])
    return tensor, omega, R


def _torques(sys, spec: dict, frames: dict, parse) -> list[sp.Expr]:
    """Generalized forces of `torques:`: the torque's power N·ω per unit rate."""
    out = [sp.S.Zero] * len(sys.q)
    for i, t in enumerate(spec.get("torques") or []):
        _, omega, R = frames[t["body"]]
        N = sp.Matrix([parse(x, ("torques", i, "components", j))
                       for j, x in enumerate(t["components"])])
        if t.get("axes", "body") == "space":
            omega = R * omega
        out = [o + N.dot(sp.diff(omega, v)) for o, v in zip(out, sys.qd, strict=True)]
    return out


def _attractors(sys, spec, positions, masses, frames, parse) -> tuple[dict, list]:
    """({body or particle: Cartesian force}, generalized forces of the torques on bodies):
    the inverse-square pull on every particle and the pull of a point mass on each body's
    centre (monopole plus the gradient of the quadrupole term, its inertia held fixed),
    and the gravity-gradient torque 3GM' d × (I_s d)/d⁵ (space axes) on each body."""
    pulls: dict = {}
    torque_q = [sp.S.Zero] * len(sys.q)
    dx = sp.Matrix(sp.symbols("dx_ dy_ dz_", real=True))
    for name, a in (spec.get("attractors") or {}).items():
        sub = ("attractors", name)
        M = parse(a["mass"], sub + ("mass",))
        G = parse(a["G"], sub + ("G",)) if "G" in a else sys.params["G"].symbol
        at = sp.Matrix([parse(x, sub + ("position", i))
                        for i, x in enumerate(a.get("position", [0, 0, 0]))])
        for obj, r in positions.items():
            d = r - at
            dist = sp.sqrt(d.dot(d))
            pull = -G * M * masses[obj] * d / dist**3
            frame = frames.get(obj)
            if frame is not None and frame[2] is not None:
                tensor, omega, R = frame
                Is = R * tensor * R.T
                ddx = dx.dot(dx)
                quad = -G * M * (Is.trace() * ddx - 3 * (dx.T * Is * dx)[0, 0]) \
                    / (2 * sp.sqrt(ddx)**5)
                grad = sp.Matrix([-sp.diff(quad, c) for c in dx])
                pull += grad.subs(dict(zip(dx, d, strict=True)))
                torque = 3 * G * M * d.cross(Is * d) / dist**5
                w_space = R * omega
                for i, v in enumerate(sys.qd):
                    torque_q[i] += torque.dot(sp.diff(w_space, v))
            pulls[obj] = pulls.get(obj, sp.zeros(r.rows, 1)) + pull
    return pulls, torque_q


def _newton(analysis: Analysis, sys, out: CrossCheck, samples: int) -> None:
    dyn = analysis.dynamics(sys.name)
    newton = newton_residual(sys, frames=(frames := {}))  # the bodies' frames it computed
    engine = list(dyn.residuals)
    params = [p.symbol for p in sys.params.values()]
    free = [s for trio in sys.free_driven for s in trio]
    args = [sys.t, *sys.q, *sys.qd, *sys.qdd, *free, *params]
    exprs = engine + newton
    # by name: the Newton side is SymEngine's where SymEngine could build it
    stray = {str(s) for e in exprs for s in e.free_symbols} - {str(a) for a in args}
    if stray:
        raise UnsupportedError("Newton cross-check: symbols without values: "
                               + ", ".join(sorted(stray)))
    fn, _ = compile_exprs(args, exprs, FEW_CALLS_BACKEND)  # 3 to 40 × samples calls
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
    out.status = Status.PASS if worst < NEWTON_TOL else Status.FAIL
    out.detail = _what_was_compared(sys.spec, used, worst)
    if sys.constraints or sys.velocity_constraints:
        rows, force, states = on_manifold(analysis, sys, newton, frames, samples)
        out.error = max(worst, rows, force)
        if max(rows, force) >= NEWTON_TOL:
            out.status = Status.FAIL
        out.detail += (f"; on the constraint manifold ({states} states): Newton–Euler with "
                       f"the constraint forces from the engine's multipliers, max relative "
                       f"imbalance {force:.1e}"
                       + (f"; rolling contacts' own tangential velocity against the engine's "
                          f"constraint rows, max relative difference {rows:.1e}"
                          if sys.spec.get("rolling") else ""))


def _what_was_compared(spec: dict, used: int, worst: float) -> str:
    what = []
    if spec.get("particles"):
        what.append("particles")
    if spec.get("rigid_bodies"):
        what.append("rigid bodies (Euler)")
    if spec.get("torques"):
        what.append("torques")
    if spec.get("attractors"):
        what.append("attracting masses (force and gravity-gradient torque)")
    if spec.get("friction"):
        what.append("sliding friction (own contact velocity)")
    other = [k for k in ("kinetic", "potential", "lagrangian", "velocity_potential", "forces",
                         "dissipation") if k in spec]
    if any("length" in s for s in spec.get("springs") or []):
        other.append("length springs")
    return (f"E = Jᵀ(m r̈ − F) over {' and '.join(what)} at {used} random states, "
            f"max relative difference {worst:.1e}"
            + (f"; as generalized forces: {', '.join(other)}" if other else ""))
