"""A system's Lagrangian built from its declarations: T and V directly, or from bodies.

Coordinates are plain real symbols q, with companions `qdot` and `qddot`; driven coordinates
are replaced by their prescribed functions of t. T, V and L come from whichever the problem
states: `lagrangian`, or `kinetic`/`potential`, plus particles, rigid bodies, gravity,
springs and attracting point masses, each adding its own term; torques on bodies become
generalized forces, and `average:` averages L over a fast angle (mechbook.model.loads).
Nothing else is modelled.
"""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp

from mechbook.core.expansion import expand_lagrangian
from mechbook.core.integrals import box_integral
from mechbook.core.numeval import is_zero, without_absent
from mechbook.core.secalc import SymEngineCannot, total_derivative
from mechbook.errors import NotFoundError, SpecError, UnsupportedError
from mechbook.model.attitude import body_rates, euler_chain, rotation_matrix
from mechbook.model.bodies import body_kinetic, shape_inertia
from mechbook.model.declared import Declared, declared
from mechbook.model.domains import Domain, assumptions, domain_of
from mechbook.model.field import field_names
from mechbook.model.friction import contacts
from mechbook.model.loads import attractor_potential, average_over, torque_forces
from mechbook.model.problem import RESERVED, Problem, SystemSpec, T
from mechbook.model.protocol import SystemLike
from mechbook.model.rolling import velocity_constraints


def motion_chains(system) -> tuple[list[tuple[sp.Symbol, sp.Symbol]], list[sp.Symbol]]:
    """d/dt along the motion of `system` (a System, or one reduced by Routh): the pairs
    (x, ẋ) with d/dt = ∂/∂t + Σ ẋ ∂/∂x — each coordinate and its rate, each rate and its
    acceleration, and a System's free driven coordinates likewise — and the symbols that
    have no time derivative (a free driven coordinate's second derivative). A system
    reduced by Routh differentiates its own coordinates only."""
    chains = [pair for q, qd, qdd in zip(system.q, system.qd, system.qdd, strict=True)
              for pair in ((q, qd), (qd, qdd))]
    stop = []
    if not system.reduced:
        for y, yd, ydd in system.free_driven:
            chains += [(y, yd), (yd, ydd)]
            stop.append(ydd)
    return chains, stop

class System(SystemLike):
    """Symbols and the Lagrangian of one system of a problem (the full system: nothing
    reduced, no momenta held; mechbook.model.protocol)."""

    def __init__(self, problem: Problem, spec: SystemSpec,
                 declarations: Callable[[], Declared] | None = None):
        """`declarations`: the problem's declared vectors, tensors and bodies, for a rigid
        body made of parts (model.built.Built passes the one it keeps; without it, the
        system builds them when a body needs them)."""
        self.problem = problem
        self._declarations = declarations
        self.name = spec.name
        self.spec = spec.data
        self.path = spec.path
        self.t = T
        self.params = problem.parameters
        self.small_params = [p.symbol for p in self.params.values() if p.small]
        self._build_symbols()
        self._build_energies()

    # ---- symbols -------------------------------------------------------------------------
    def error(self, sub: tuple, message: str) -> SpecError:
        """A SpecError at `sub` of this system's declarations (file and line)."""
        return self.problem.doc.error(self.path + sub, message)

    def parse(self, text, sub: tuple, relation: bool = False):
        """An expression at `sub` of this system's declarations, in its names; SpecError
        (file and line) if it does not parse."""
        return self.problem.parse(text, self.path + sub, self.names, relation)

    def _build_symbols(self) -> None:
        coords = list(self.spec["coordinates"])
        specs = self.spec["coordinates"]
        self.q = [sp.Symbol(c, **assumptions(specs[c])) for c in coords]
        self.qd = [sp.Symbol(c + "dot", real=True) for c in coords]
        self.qdd = [sp.Symbol(c + "ddot", real=True) for c in coords]
        self.coord_names = coords
        names: dict[str, sp.Basic] = dict(self.problem.names())
        taken = set(names) | RESERVED
        for c, q, qd, qdd in zip(coords, self.q, self.qd, self.qdd, strict=True):
            for sym in (q, qd, qdd):
                if sym.name in taken:
                    raise self.error(("coordinates", c), f"name {sym.name!r} is already taken "
                                      "(parameter, reserved word, or another coordinate)")
                taken.add(sym.name)
                names[sym.name] = sym
        names["t"] = T
        self.domains: dict[sp.Symbol, Domain] = {}  # a coordinate's declared domain
        for c, q in zip(coords, self.q, strict=True):
            dom = domain_of(c, specs[c], lambda text, sub, c=c: self.problem.parse(
                text, self.path + ("coordinates", c) + sub, self.problem.names()))
            if dom is not None:
                self.domains[q] = dom
        self.driven: dict[str, sp.Expr] = {}
        self.free_driven: list[tuple[sp.Symbol, sp.Symbol, sp.Symbol]] = []
        for name, text in (self.spec.get("driven") or {}).items():
            if name in taken or name + "dot" in taken or name + "ddot" in taken:
                raise self.error(("driven", name), f"name {name!r} is already taken")
            if isinstance(text, dict):  # {free: true}: an arbitrary prescribed function of t
                syms = tuple(sp.Symbol(name + s, real=True) for s in ("", "dot", "ddot"))
                self.free_driven.append(syms)
                names.update({s.name: s for s in syms})
                taken |= {s.name for s in syms}
                continue
            expr = self._parse_with(text, ("driven", name), names)
            if any(s in expr.free_symbols for s in self.q + self.qd + self.qdd):
                raise self.error(("driven", name), "a driven coordinate is a function of t and "
                                  "parameters only")
            self.driven[name] = expr
            names[name] = expr
            names[name + "dot"] = sp.diff(expr, T)
            names[name + "ddot"] = sp.diff(expr, T, 2)
            taken |= {name, name + "dot", name + "ddot"}
        self.names = names

    def _parse_with(self, text, sub: tuple, names: dict):
        return self.problem.parse(text, self.path + sub, names)

    # ---- energies ------------------------------------------------------------------------
    def _build_energies(self) -> None:
        s = self.spec
        if "lagrangian" in s and ("kinetic" in s or "potential" in s):
            raise self.error(("lagrangian",), "give either 'lagrangian' or 'kinetic'/'potential'")
        kinetic = self.parse(s["kinetic"], ("kinetic",)) if "kinetic" in s else sp.S.Zero
        potential = self.parse(s["potential"], ("potential",)) if "potential" in s else sp.S.Zero
        self.positions: dict[str, sp.Matrix] = {}
        self.masses: dict[str, sp.Expr] = {}
        self.attitudes: dict[str, list] = {}  # body -> chain of rotations (3-D bodies)
        self.inertias: dict[str, sp.Matrix] = {}  # body -> inertia tensor in body axes
        self.body_rates: dict[str, sp.Matrix] = {}  # body -> ω in body axes
        # each particle's and body's own kinetic energy and potential energy in gravity
        # (mechbook.engine.part_energy: the energy of one part of the system)
        self.part_kinetic: dict[str, sp.Expr] = {}
        self.part_potential: dict[str, sp.Expr] = {}
        for name, p in (s.get("particles") or {}).items():
            m = self.parse(p["mass"], ("particles", name, "mass"))
            r = sp.Matrix([self.parse(x, ("particles", name, "position", i))
                           for i, x in enumerate(p["position"])])
            self.positions[name], self.masses[name] = r, m
            v = self.dt(r)
            self.part_kinetic[name] = m * v.dot(v) / 2
            kinetic += self.part_kinetic[name]
        for name, b in (s.get("rigid_bodies") or {}).items():
            self.part_kinetic[name] = self._rigid_body(name, b)
            kinetic += self.part_kinetic[name]
        potential += self._gravity() + self._springs()
        if "string" in s:
            t_string, v_string = self._string()
            kinetic += t_string
            potential += v_string
        if s.get("attractors"):
            potential += attractor_potential(self, s["attractors"])
        if "lagrangian" in s:
            lag = self.parse(s["lagrangian"], ("lagrangian",))
            if self.positions or s.get("rigid_bodies"):
                lag += kinetic - potential
        else:
            lag = kinetic - potential
        if "velocity_potential" in s:
            lag -= self.parse(s["velocity_potential"], ("velocity_potential",))
        if lag == 0:
            raise self.error(("coordinates",), "the system has no kinetic or potential energy")
        if "average" in s:  # averaged over a fast angle, e.g. a planet's orbital position
            rest = lag - (kinetic - potential)  # the average is linear: T and V once each
            kinetic, potential, rest = (average_over(self, e, s["average"])
                                        for e in (kinetic, potential, rest))
            lag = kinetic - potential + rest
        if "approximation" in s:  # the approximation the problem makes, e.g. small angles
            approx = s["approximation"]
            point = self.point(approx["about"], ("approximation", "about"))
            lag = expand_lagrangian(lag, self.q, self.qd, point, self.small_params,
                                    approx.get("order", 2))
        self.kinetic = without_absent(kinetic, [T, *self.q])
        self.potential = without_absent(potential, [T, *self.q])
        self.lagrangian = without_absent(lag, [T, *self.q])
        self.declared_forces = self._forces()  # `forces:` as the file gives them
        self.forces = list(self.declared_forces)
        if s.get("torques"):
            self.forces = [f + g for f, g in zip(self.forces, torque_forces(self, s["torques"]),
                                                  strict=True)]
        self.contacts = []  # sliding friction (mechbook.model.friction)
        self.forces_without_friction = list(self.forces)
        if s.get("friction"):
            self.contacts = contacts(self, s["friction"])
            self.forces = [f + sp.Add(*(c.force[k] for c in self.contacts))
                           for k, f in enumerate(self.forces)]
        self.constraints = [(c["name"], self.parse(c["expr"], ("constraints", i, "expr")))
                            for i, c in enumerate(s.get("constraints") or [])]
        for i, (cname, f) in enumerate(self.constraints):
            if f.free_symbols & set(self.qd + self.qdd):
                raise self.error(("constraints", i, "expr"),
                                  f"constraint {cname!r} must be holonomic: f(q, t) = 0")
            if f"lambda_{cname}" in self.names:  # the engine's name for its multiplier
                raise self.error(("constraints", i, "name"),
                                  f"constraint {cname!r} has the multiplier lambda_{cname}, "
                                  f"which is already a name here: rename the constraint or "
                                  f"lambda_{cname}")
        # velocity constraints A(q, t)·q̇ + b(q, t) = 0 and rolling contacts (model.rolling)
        self.velocity_constraints: list[tuple[str, sp.Expr]] = []
        if s.get("velocity_constraints") or s.get("rolling"):
            self.velocity_constraints = velocity_constraints(self)

    def _rigid_body(self, name: str, b: dict) -> sp.Expr:
        sub = ("rigid_bodies", name)
        inertia = b["inertia"]
        composite = None
        if isinstance(inertia, dict) and "body" in inertia:
            composite = self._composite(inertia["body"], sub + ("inertia", "body"))
        if "mass" in b:
            m = self.parse(b["mass"], sub + ("mass",))
            if composite is not None and not is_zero(m - composite.mass):
                raise self.error(sub + ("mass",), f"the mass differs from body "
                                  f"{inertia['body']!r}'s ({composite.mass}); leave it out")
        elif composite is not None:
            m = composite.mass
        else:
            raise self.error(sub, "a rigid body needs 'mass' (unless its inertia names a body)")
        r = sp.Matrix([self.parse(x, sub + ("position", i)) for i, x in enumerate(b["position"])])
        self.positions[name], self.masses[name] = r, m
        if composite is not None:
            if r.rows != 3:
                raise self.error(sub + ("position",), "a body made of parts moves in 3-D")
            tensor = composite.inertia()  # about its centre of mass, in its own axes
        elif isinstance(inertia, dict):
            dims = {k: self.parse(v, sub + ("inertia", k)) for k, v in inertia.items()
                    if k in ("radius", "length", "height")}
            for key in ("sides", "semi_axes"):
                if key in inertia:
                    dims[key] = [self.parse(v, sub + ("inertia", key, i))
                                 for i, v in enumerate(inertia[key])]
            try:
                tensor = shape_inertia(inertia["shape"], m, dims)
            except ValueError as exc:
                raise self.error(sub + ("inertia",), str(exc)) from None
            if r.rows == 2 and tensor[2, 2] == 0 and inertia["shape"] != "point":  # own z
                raise self.error(sub + ("inertia",), f"a planar body uses the moment about "
                                  f"its own z axis (normal to the plane), and a "
                                  f"{inertia['shape']}'s is 0 (its length is along its own "
                                  "z): give the moment as a number, e.g. m*l**2/12 for a rod")
        elif isinstance(inertia, list):
            tensor = sp.Matrix([[self.parse(x, sub + ("inertia", i, j)) for j, x in enumerate(row)]
                                for i, row in enumerate(inertia)])
            if tensor != tensor.T:
                raise self.error(sub + ("inertia",), "inertia tensor must be symmetric")
        else:
            tensor = self.parse(inertia, sub + ("inertia",))  # planar: scalar moment
        omega = None
        if "angular_velocity" in b:
            w = b["angular_velocity"]
            omega = (sp.Matrix([self.parse(x, sub + ("angular_velocity", i))
                                for i, x in enumerate(w)]) if isinstance(w, list)
                     else self.parse(w, sub + ("angular_velocity",)))
        chain = self._attitude(sub, b)
        try:
            kinetic = body_kinetic(m, self.dt(r), tensor, omega, chain, self.dt)
        except ValueError as exc:
            raise self.error(sub, str(exc)) from None
        if isinstance(tensor, sp.MatrixBase) and r.rows == 3:
            self.inertias[name] = tensor
            self.body_rates[name] = body_rates(chain, self.dt) if chain is not None else omega
            if chain is not None:
                self.attitudes[name] = chain
        self._rate_names(name, sub, b)
        return kinetic

    def _attitude(self, sub: tuple, b: dict) -> list | None:
        """The body's chain of rotations: `euler_angles` (z-x-z) or `rotation`."""
        if "euler_angles" in b and "rotation" in b:
            raise self.error(sub + ("rotation",), "give either 'euler_angles' or 'rotation'")
        if "euler_angles" in b:
            return euler_chain([self.parse(x, sub + ("euler_angles", i))
                                for i, x in enumerate(b["euler_angles"])])
        if "rotation" in b:
            return [(axis, self.parse(angle, sub + ("rotation", i, 1)))
                    for i, (axis, angle) in enumerate(b["rotation"])]
        return None

    def _rate_names(self, name: str, sub: tuple, b: dict) -> None:
        """`rates: [w1, w2, w3]` and `space_rates: [wx, wy, wz]`: names for the body-axis
        and the space-axis components of ω (functions of the state), each with its time
        derivative `<name>dot` (which holds accelerations)."""
        for key in ("rates", "space_rates"):
            if key not in b:
                continue
            omega = self.body_rates.get(name)
            if omega is None or (key == "space_rates" and name not in self.attitudes):
                raise self.error(sub + (key,), f"'{key}' names the angular velocity of a 3-D "
                                  "body with an attitude (or, for 'rates', a vector "
                                  "angular_velocity)")
            if key == "space_rates":
                omega = rotation_matrix(self.attitudes[name]) * omega
            for i, rname in enumerate(b[key]):
                for n in (rname, rname + "dot"):
                    if n in self.names or n in RESERVED:
                        raise self.error(sub + (key, i), f"name {n!r} is already taken")
                self.names[rname] = omega[i]
                self.names[rname + "dot"] = self.dt(omega[i])

    def _composite(self, body: str, sub: tuple):
        """A body declared under the problem's `bodies:` (made of parts)."""
        if self._declarations is None:  # built once for all of this system's bodies
            decl = declared(self.problem)
            self._declarations = lambda: decl
        bodies = self._declarations().bodies
        if body not in bodies:
            known = ", ".join(sorted(bodies)) or "none declared"
            raise self.error(sub, f"no body {body!r} under 'bodies:' ({known})")
        return bodies[body]

    def _gravity(self) -> sp.Expr:
        if "gravity" not in self.spec:
            return sp.S.Zero
        grav = self.spec["gravity"] or {}
        if "g" in grav:
            g = self.parse(grav["g"], ("gravity", "g"))
        elif "g" in self.params:
            g = self.params["g"].symbol
        else:
            raise self.error(("gravity",), "gravity needs a parameter 'g' (declare it; default "
                              "value 9.81) or gravity.g")
        if not self.positions:
            raise self.error(("gravity",), "gravity acts on particles or rigid bodies; none given")
        total = sp.S.Zero
        for name, r in self.positions.items():
            if "up" in grav:
                up = sp.Matrix([self.parse(x, ("gravity", "up", i))
                                for i, x in enumerate(grav["up"])])
                if up.shape != r.shape:
                    raise self.error(("gravity", "up"), f"'up' has {up.rows} components, "
                                      f"{name}'s position has {r.rows}")
            else:
                up = sp.Matrix([0] * (r.rows - 1) + [1])  # default: last axis points up
            self.part_potential[name] = self.masses[name] * g * r.dot(up)
            total += self.part_potential[name]
        return total

    def _springs(self) -> sp.Expr:
        total = sp.S.Zero
        for i, spring in enumerate(self.spec.get("springs") or []):
            sub = ("springs", i)
            k = self.parse(spring["k"], sub + ("k",))
            if "length" in spring:
                length = self.parse(spring["length"], sub + ("length",))
            else:
                ends = []
                for j, end in enumerate(spring["between"]):
                    if isinstance(end, str):
                        if end not in self.positions:
                            raise self.error(sub + ("between", j), f"no particle or body {end!r}")
                        ends.append(self.positions[end])
                    else:
                        ends.append(sp.Matrix([self.parse(x, sub + ("between", j, n))
                                               for n, x in enumerate(end)]))
                if ends[0].shape != ends[1].shape:
                    raise self.error(sub + ("between",), "spring ends differ in dimension")
                d = ends[0] - ends[1]
                length = sp.sqrt(d.dot(d))
            natural = (self.parse(spring["natural_length"], sub + ("natural_length",))
                       if "natural_length" in spring else sp.S.Zero)
            total += k * (length - natural) ** 2 / 2
        return total

    def _string(self) -> tuple[sp.Expr, sp.Expr]:
        """A stretched string fixed at x = 0 and x = l, its transverse displacement expanded
        in the first N sine modes, u(x, t) = sum_k q_k(t)*sin(k*pi*x/l) (a Galerkin form:
        the coordinates `amplitudes` are the q_k). T = (1/2)*integral sigma(x)*u_t**2 dx and
        V = (1/2)*integral tau*u_x**2 dx, integrated exactly (products of sines turned into
        sums first); sigma may depend on x, tau is constant. The truncation to N modes is a
        discretization: its accuracy is measured in tests/test_string.py and stated in
        docs/schema.md."""
        from sympy.simplify.fu import TR8

        spec = self.spec["string"]
        sub = ("string",)
        x = sp.Symbol("x", real=True)
        names = dict(self.names)
        if "x" in names:
            raise self.error(sub, "the string's coordinate along it is x: the name is taken")
        names["x"] = x
        length = self._parse_with(spec["length"], sub + ("length",), names)
        tension = self._parse_with(spec["tension"], sub + ("tension",), names)
        density = self._parse_with(spec["density"], sub + ("density",), names)
        if tension.has(x) or length.has(x):
            raise self.error(sub, "the length and the tension do not depend on x")
        amps = []
        for i, name in enumerate(spec["amplitudes"]):
            if name not in self.coord_names:
                raise self.error(sub + ("amplitudes", i), f"{name!r} is not a coordinate")
            amps.append(self.coord_names.index(name))
        modes = [sp.sin((k + 1) * sp.pi * x / length) for k in range(len(amps))]
        kinetic = potential = sp.S.Zero
        known: dict = {}  # the pairs of modes share most of their terms' integrals
        for a, ia in enumerate(amps):
            for b, ib in enumerate(amps):
                if b < a:
                    continue
                mult = 1 if a == b else 2
                try:
                    mass = box_integral(sp.expand(TR8(density * modes[a] * modes[b])),
                                        ((x, 0, length),), known)
                except Exception as exc:  # noqa: BLE001 - SymPy's many failure modes
                    raise self.error(sub + ("density",), f"cannot integrate: {exc}") from None
                if mass.has(sp.Integral) or mass.has(x):
                    raise self.error(sub + ("density",), "the mass integrals have no closed "
                                      "form")
                kinetic += mult * mass * self.qd[ia] * self.qd[ib] / 2
            k = a + 1
            potential += tension * (k * sp.pi / length) ** 2 * (length / 2) * self.q[ia] ** 2 / 2
        if "field" in spec:  # u(x, t) and integrals over the string as names (model/field)

            named = field_names(spec["field"], x, modes, [self.q[i] for i in amps],
                                [self.qd[i] for i in amps])
            for n in named:
                if n in self.names or n in RESERVED:
                    raise self.error(sub + ("field",), f"name {n!r} is already taken")
            self.names.update(named)
        return kinetic, potential

    def _forces(self) -> list[sp.Expr]:
        forces = self.spec.get("forces") or {}
        out = []
        for c in self.coord_names:
            out.append(self.parse(forces[c], ("forces", c)) if c in forces else sp.S.Zero)
        unknown = set(forces) - set(self.coord_names)
        if unknown:
            raise self.error(("forces", sorted(unknown)[0]), "generalized forces are keyed by "
                              "coordinate; no coordinate of that name")
        if "dissipation" in self.spec:  # Rayleigh's function R(q, q̇): Q_k = −∂R/∂q̇_k
            rayleigh = self.parse(self.spec["dissipation"], ("dissipation",))
            out = [f - sp.diff(rayleigh, v) for f, v in zip(out, self.qd, strict=True)]
        return out

    # ---- calculus ------------------------------------------------------------------------
    def dt(self, expr):
        """Total time derivative along the motion: d/dt = ∂t + Σ qdot ∂q + Σ qddot ∂qdot."""
        if isinstance(expr, sp.MatrixBase):
            return expr.applyfunc(self.dt)
        chains, stop = motion_chains(self)
        if isinstance(expr, sp.Basic) and not any(expr.has(ydd) for ydd in stop):
            # SymEngine's calculus (core.secalc: the same derivative, ten times sooner)
            try:
                return total_derivative(expr, T, chains)
            except SymEngineCannot:
                pass
        out = sp.diff(expr, T)
        for q, qd, qdd in zip(self.q, self.qd, self.qdd, strict=True):
            out += sp.diff(expr, q) * qd + sp.diff(expr, qd) * qdd
        for y, yd, ydd in self.free_driven:
            if expr.has(ydd):
                raise UnsupportedError("third derivative of a free driven coordinate")
            out += sp.diff(expr, y) * yd + sp.diff(expr, yd) * ydd
        return out

    def point(self, mapping: dict, sub: tuple) -> dict[sp.Symbol, sp.Expr]:
        """A configuration {coordinate: expr} parsed at `sub` of the file."""
        out = {}
        for name, text in mapping.items():
            if name not in self.coord_names:
                raise self.error(sub + (name,), f"{name!r} is not a coordinate of this system")
            out[self.q[self.coord_names.index(name)]] = self.parse(text, sub + (name,))
        return out

    def numeric_values(self) -> dict[sp.Symbol, float]:
        return self.problem.values()

    # ---- the contract's kind (mechbook.model.protocol) -----------------------------------
    @property
    def reduced(self) -> bool:
        return False

    @property
    def full(self) -> System:
        return self

    @property
    def held_momenta(self) -> dict[sp.Symbol, sp.Expr]:
        return {}

    @property
    def held(self) -> dict[sp.Symbol, sp.Expr]:
        return {}


def system_name(problem: Problem, name: str | None = None) -> str:
    """`name`, checked, or the problem's only system (of several, the one named `main`).
    NotFoundError (a KeyError too) names the systems there are."""
    if name is None:
        if len(problem.systems) == 1:
            return next(iter(problem.systems))
        if "main" in problem.systems:
            return "main"
        raise NotFoundError(f"{problem.id} has several systems: "
                            f"{', '.join(problem.systems)}")
    if name not in problem.systems:
        raise NotFoundError(f"{problem.id} has no system {name!r} (has "
                            f"{', '.join(problem.systems)})")
    return name


def system_of(problem: Problem, name: str | None = None,
              declarations: Callable[[], Declared] | None = None) -> System:
    """The system `name` of a problem, or its only one (of several, the one named `main`),
    built anew: what is built once and kept is kept by its builder (model.built.Built, which
    an engine Analysis owns). NotFoundError (a KeyError too) names the systems there are."""
    name = system_name(problem, name)
    return System(problem, problem.systems[name], declarations)
