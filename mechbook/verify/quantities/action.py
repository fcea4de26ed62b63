"""Action–angle variables: `action` and `action_hamiltonian`.

The action of a coordinate is J = (1/2π)∮ p dq over one libration (the 1/2π convention: an
oscillator's J is E/ω, not 2πE/ω). The coordinate's motion is reduced to one degree of
freedom on the level set of the energy and the other coordinates' momenta (every other
coordinate cyclic: mechbook.engine.levelset), and J is its quadrature in 50-digit
arithmetic, the turning points' square-root singularities removed by c = mid − half·cos s;
the same at 60 digits must agree to 1e-20 (else the part is unsupported: the quadrature did
not reach its digits). A cyclic angle's action over a full turn is its momentum.

The motion is given by `initial:` (a start, as for the trajectory quantities) or by
`energy:` (an expression), `momenta:` (each cyclic coordinate's momentum) and `inside:` (a
value of the coordinate the motion passes through). A motion that is not a libration (the
coordinate runs away or goes round) has no action: an error at the part's line.

`action` compares the book's J with the engine's at random points; `action_hamiltonian`
takes the book's energy H(J1, J2, ...) as a function of the actions (`actions:` names each
action symbol's coordinate): at each point H at the engine's actions must be the energy,
and each frequency ∂H/∂J_i must be the engine's 2π/T (the libration's period, a second
quadrature) or, for a cyclic angle, its mean rate (advance per period / T). At one point
the frequency is also measured by integrating the full equations (mechbook.numerics.
measure, at its 1e-7) from `initial:`, or from the state at `inside:` with the part's
energy and momenta.
"""

from __future__ import annotations

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.numeval import evaluate_mp
from mechbook.engine.levelset import LevelSet, Orbit
from mechbook.engine.steady import cyclic_check
from mechbook.errors import UnsupportedError
from mechbook.numerics.measure import MEASURE_RTOL, measure, signal_functions
from mechbook.numerics.rhs import build_model
from mechbook.verify.compare import Verdict
from mechbook.verify.context import Context
from mechbook.verify.quantities.trajectory import initial_state
from mechbook.verify.registration import EXPR, POINT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

POINTS = 6
DPS, CHECK_DPS = 50, 60  # the quadrature's precision, and a second one that measures it
RESOLVED = mpmath.mpf(10) ** -20  # the two must agree to this
RTOL = 1e-15  # book against engine
MOTION = {"initial": POINT, "energy": EXPR, "inside": EXPR,
          "momenta": POINT}


class Actions:
    """The actions of a part's motion: which coordinates librate, how the orbit is given."""

    def __init__(self, ctx: Context, coordinates: list[str], where: tuple):
        self.ctx, sys, data = ctx, ctx.system, ctx.part.data
        self._orbits: dict = {}  # (coordinate, digits, point): its Orbit
        self.coords = []
        for name in coordinates:
            if name is None:
                raise ctx.part.error((), "name the `coordinate:` whose action is given")
            if name not in sys.coord_names:
                raise ctx.part.error(where, f"{name!r} is not a coordinate")
            self.coords.append(sys.q[sys.coord_names.index(name)])
        if "initial" in data:
            if any(k in data for k in ("energy", "inside", "momenta")):
                raise ctx.part.error(("initial",), "give the motion by `initial:` or by "
                                     "`energy:`, `inside:`, `momenta:`, not both")
            self.start, self.energy = initial_state(ctx), None
        elif "energy" in data:
            self.start = None
            self.energy = ctx.parse(data["energy"], ("energy",))
            self.momenta = {k: ctx.parse(v, ("momenta", k))
                            for k, v in ctx.as_map(data.get("momenta", {}), ("momenta",)).items()}
            for k in self.momenta:
                if k not in sys.coord_names:
                    raise ctx.part.error(("momenta", k), f"{k!r} is not a coordinate")
        else:
            raise ctx.part.error((), "give the motion: `initial:` (a start) or `energy:` "
                                 "(with `inside:` and the cyclic coordinates' `momenta:`)")

    def level(self, c) -> LevelSet:
        ctx = self.ctx

        def build() -> LevelSet:
            level = LevelSet(ctx.dyn, c)
            level.reduced  # noqa: B018 - derive now: an unsupported reduction says so here
            return level

        return ctx.analysis.reuse(("level-set", ctx.part.system, str(c)), build)

    def librating(self) -> list:
        """The coordinates that librate (not cyclic: those have a level set of their own)."""
        out = []
        for c in self.coords:
            try:
                cyclic_check(self.ctx.dyn, [c])
            except UnsupportedError:
                out.append(c)
        return out

    def orbit(self, c, pt: dict, dps: int) -> Orbit:
        """The orbit of coordinate c at `pt`, computed once at each precision: a point's
        action, its frequencies and its energy read the same orbit (its turning points and
        quadratures are the orbit's cached properties, the same numbers whichever asks
        first), where each built and searched it again (three times at each of six points
        of an `action_hamiltonian`)."""
        key = (c, dps, tuple(sorted(pt.items(), key=lambda kv: str(kv[0]))))
        got = self._orbits.get(key)
        if got is None:
            got = self._orbits[key] = self._orbit(c, pt, dps)
        return got

    def _orbit(self, c, pt: dict, dps: int) -> Orbit:
        ctx, level = self.ctx, self.level(c)
        if self.start is not None:
            return level.orbit({k: v.subs(pt) for k, v in self.start.items()}, pt, dps)
        names = ctx.system.coord_names
        missing = [str(q) for q in level.cyclic if names[ctx.system.q.index(q)]
                   not in self.momenta]
        if missing:
            raise ctx.part.error(("momenta",), "give the momentum of each cyclic coordinate: "
                                 + ", ".join(missing))
        if "inside" not in ctx.part.data:
            raise ctx.part.error(("energy",), "with `energy:`, give `inside:` (a value of "
                                 f"{c} the motion passes through)")
        with mpmath.workdps(dps):
            def num(e):
                return evaluate_mp(e, pt, dps)

            P = [num(self.momenta[names[ctx.system.q.index(q)]]) for q in level.cyclic]
            inside = num(ctx.parse(ctx.part.data["inside"], ("inside",)))
            return level.orbit_at(num(self.energy), P, inside, pt, dps)

    def energy_at(self, pt: dict):
        """The motion's energy at `pt` (from `energy:` or the start)."""
        if self.energy is not None:
            return evaluate_mp(self.energy, pt, DPS)
        c = self.librating()[0] if self.librating() else self.coords[0]
        return self.orbit(c, pt, DPS).E

    def momentum(self, c, pt: dict):
        """A cyclic angle's action over a full turn: its momentum, constant on the motion."""
        ctx = self.ctx
        name = ctx.system.coord_names[ctx.system.q.index(c)]
        if self.start is None:
            if name not in self.momenta:
                raise ctx.part.error(("momenta",), f"give the momentum of {name}")
            return evaluate_mp(self.momenta[name], pt, DPS)
        qd = ctx.system.qd[ctx.system.q.index(c)]
        p = sp.diff(ctx.dyn.L, qd).xreplace({k: v.subs(pt) for k, v in self.start.items()})
        return evaluate_mp(p, pt, DPS)

    def start_state(self, c, pt: dict) -> dict:
        """A state of the part's motion at `pt`: the start, or (given by energy) c at
        `inside:`, the other coordinates 0 (cyclic: their values do not matter), the cyclic
        rates from their momenta and ċ > 0 from the energy."""
        if self.start is not None:
            return {k: v.subs(pt) for k, v in self.start.items()}
        sys, dyn = self.ctx.system, self.ctx.dyn
        level = self.level(c)
        orbit = self.orbit(c, pt, DPS)
        fixed = dict(pt)
        fixed.update({q: sp.S.Zero for q in sys.q})
        fixed[c] = sp.Float(orbit.c0, 30)
        cdot = sys.qd[sys.q.index(c)]
        rates = [sys.qd[sys.q.index(q)] for q in level.cyclic]
        eqs = [dyn.momenta[sys.q.index(q)].xreplace(fixed) - sp.Float(P, 30)
               for q, P in zip(level.cyclic, orbit.P, strict=True)]
        sol = sp.solve(eqs, rates, dict=True) if eqs else [{}]
        if len(sol) != 1:
            raise UnsupportedError("the cyclic rates from their momenta")
        energy = dyn.energy_function.xreplace(fixed).xreplace(sol[0])
        roots = [r for r in sp.Poly(sp.expand(energy - sp.Float(orbit.E, 30)), cdot).nroots(
            n=30) if r.is_real and r > 0]
        if not roots:
            raise UnsupportedError("a state at `inside:` with the part's energy")
        state = {q: fixed[q] for q in sys.q}
        state[cdot] = roots[-1]
        state.update({v: sol[0].get(v, sp.S.Zero).xreplace({cdot: roots[-1]})
                      for v in rates})
        return state

    def action(self, c, pt: dict):
        """(J, its resolution): the quadrature at DPS digits and its distance from CHECK_DPS."""
        if c not in self.librating():
            return self.momentum(c, pt), mpmath.mpf(0)
        unbound = self.ctx.part.error(("coordinate",), f"{c} does not librate (it runs away "
                                      "or goes round): an unbound motion has no action")
        try:
            one, two = (self.orbit(c, pt, d) for d in (DPS, CHECK_DPS))
            if not all(mpmath.isfinite(x) for x in one.turning_points):
                raise unbound  # a turning point at infinity: the orbit of a scattering
            J1, J2 = one.action, two.action
        except UnsupportedError as exc:
            if "no turning point" in exc.capability:
                raise unbound from None
            raise
        with mpmath.workdps(CHECK_DPS):
            err = abs(J1 - J2) / max(abs(J2), mpmath.mpf(10) ** -40)
        if not err <= RESOLVED:
            raise UnsupportedError(f"the action's quadrature reached only {float(err):.1g} "
                                   f"(two precisions; needed {float(RESOLVED):g})")
        return J1, err

    def frequency(self, c, pt: dict, librating_c):
        """∂H/∂J for coordinate c: 2π/T of its libration, or a cyclic angle's mean rate
        over the libration of `librating_c`."""
        if c in self.librating():
            return 2 * mpmath.pi / self.orbit(c, pt, DPS).period
        orbit = self.orbit(librating_c, pt, DPS)
        return orbit.advance(c) / orbit.period


def _rel(a, b) -> float:
    return float(abs(a - b) / max(abs(a), abs(b), mpmath.mpf(10) ** -300))


@quantity('action',
          book='expression: J = (1/2π)∮p dq of `coordinate:` (in the energy, the momenta and '
               'the parameters)',
          how=('J of the libration of `coordinate:` on the level set of the energy and the '
               'cyclic momenta (every other coordinate cyclic), from `initial:` or from '
               '`energy:`/`inside:`/`momenta:`: a 50-digit quadrature with the turning '
               'points\' singularities removed, agreeing with a 60-digit one to 1e-20 (else '
               'unsupported); a cyclic angle\'s J is its momentum; equal to the book\'s at 6 '
               'points to 1e-15. An unbound motion is an error'),
          keys={"coordinate": {"type": "string"}, **MOTION})
def check_action(ctx: Context, val) -> Verdict:
    book = ctx.parse(val, ("book",))
    acts = Actions(ctx, [ctx.part.data.get("coordinate")], ("coordinate",))
    c = acts.coords[0]
    worst, resolution = 0.0, 0.0
    for k in range(1, POINTS + 1):
        pt = ctx.sampler.draw()
        J, err = acts.action(c, pt)
        resolution = max(resolution, float(err))
        with mpmath.workdps(DPS):
            want = evaluate_mp(book, pt, DPS)
            rel = _rel(want, J)
        worst = max(worst, rel)
        if not rel <= RTOL:
            return Verdict(False, f"quadrature({k} points)",
                           f"J of {c}: the book's {mpmath.nstr(want, 12)}, the engine's "
                           f"{mpmath.nstr(J, 12)} (relative difference {rel:.2g})")
    return Verdict(True, f"quadrature({POINTS} points, {DPS} digits)",
                   f"worst relative difference {worst:.2g}; quadrature resolved to "
                   f"{resolution:.1g}",
                   power=f"J at {POINTS} points to {RTOL:g} (quadrature resolved to "
                         f"{float(RESOLVED):g})")


@quantity('action_hamiltonian',
          book='expression: the energy H(J1, J2, ...) in the action symbols of `actions:`',
          how=('at 6 points the engine\'s actions (as for `action`) of the coordinates '
               '`actions:` names (action symbol: coordinate) put into the book\'s H give the '
               'energy to 1e-15, and each ∂H/∂J_i is the engine\'s frequency to 1e-15: 2π '
               'over the libration\'s period (a quadrature), or a cyclic angle\'s mean rate; '
               'the frequency also measured by integrating the full equations (1e-7) '
               'from the start, or from the state at `inside:`'),
          keys={"actions": {"type": "object", "minProperties": 1,
                            "additionalProperties": {"type": "string"}}, **MOTION})
def check_action_hamiltonian(ctx: Context, val) -> Verdict:
    spec = ctx.as_map(ctx.part.data.get("actions"), ("actions",))
    if not spec:
        raise ctx.part.error((), "name the action symbols and their coordinates: "
                             "`actions: {J: x}`")
    symbols = {}
    for name in spec:
        sym = ctx.names.get(name)
        if not isinstance(sym, sp.Symbol):
            raise ctx.part.error(("actions", name), f"{name!r} is not a symbol of the key")
        symbols[name] = sym
    book = ctx.parse(val, ("book",))
    acts = Actions(ctx, list(spec.values()), ("actions",))
    librating = acts.librating()
    if not librating:
        raise ctx.part.error(("actions",), "no coordinate of `actions:` librates")
    pairs = list(zip(symbols.values(), acts.coords, strict=True))
    slopes = [sp.diff(book, s) for s, _ in pairs]
    worst = 0.0
    for k in range(1, POINTS + 1):
        pt = ctx.sampler.draw()
        at = dict(pt)
        for s, c in pairs:
            at[s] = sp.Float(acts.action(c, pt)[0], DPS)
        with mpmath.workdps(DPS):
            E = acts.energy_at(pt)
            H = evaluate_mp(book, at, DPS)
            rel = _rel(H, E)
            worst = max(worst, rel)
            if not rel <= RTOL:
                return Verdict(False, f"quadrature({k} points)",
                               f"H at the engine's actions is {mpmath.nstr(H, 12)}, the "
                               f"energy {mpmath.nstr(E, 12)} (relative {rel:.2g})")
            for (s, c), slope in zip(pairs, slopes, strict=True):
                w_book = evaluate_mp(slope, at, DPS)
                w = acts.frequency(c, pt, librating[0])
                rel = _rel(w_book, w)
                worst = max(worst, rel)
                if not rel <= RTOL:
                    return Verdict(False, f"quadrature({k} points)",
                                   f"∂H/∂{s} = {mpmath.nstr(w_book, 12)}, the engine's "
                                   f"frequency of {c} {mpmath.nstr(w, 12)} (relative "
                                   f"{rel:.2g})")
    detail = f"worst relative difference {worst:.2g}"
    measured = _measured(ctx, acts, pairs, slopes, librating[0])
    if measured is not None:
        ok, text = measured
        detail += "; " + text
        if not ok:
            return Verdict(False, "measured", detail)
    return Verdict(True, f"quadrature({POINTS} points, {DPS} digits)", detail,
                   power=f"H(J) and ∂H/∂J at {POINTS} points to {RTOL:g}")


def _measured(ctx: Context, acts: Actions, pairs, slopes, librating_c):
    """At the default point, ∂H/∂J of the librating coordinate against 2π over the period
    measured by integrating the full equations from `initial:`, or from the state at
    `inside:` that has the part's energy and momenta."""
    pt = ctx.sampler.default()
    i = [c for _, c in pairs].index(librating_c)
    at = dict(pt)
    for s, c in pairs:
        at[s] = sp.Float(acts.action(c, pt)[0], DPS)
    with mpmath.workdps(DPS):
        w_book = float(evaluate_mp(slopes[i], at, DPS))
    sys = ctx.system
    try:
        params = {k: float(v) for k, v in pt.items() if k in sys.problem.values()}
        model = build_model(sys, ctx.dyn, params)
        fn = signal_functions(sys, ctx.dyn, pt, librating_c)
        st = acts.start_state(librating_c, pt)
        q0 = np.array([float(st[q]) for q in sys.q])
        qd0 = np.array([float(st[v]) for v in sys.qd])
        q0, qd0 = ctx.settled(q0, qd0, pt)
        period = measure(model, fn, q0, qd0, 1.0 / (1.0 + float(np.max(np.abs(qd0))))).period()
    except UnsupportedError as exc:
        return True, f"the integrated motion not measured ({exc.capability})"
    w = 2 * float(mpmath.pi) / period
    rel = abs(w - w_book) / abs(w)
    return rel <= MEASURE_RTOL, (f"the integrated motion's frequency {w:.10g}, ∂H/∂J "
                                 f"{w_book:.10g} (relative {rel:.2g}, stated {MEASURE_RTOL:g})")
