"""The energy of one part of a system along a motion: `part_energy`.

The engine's side is mechbook.engine.part_energy: the part's kinetic and gravitational energy to
second order about the equilibrium (counted from its value there), along the linearized
initial-value solution from `initial:`, all at 40 digits. The helpers here (the start, the
motion, the energy at a state) serve `extremum` too, whose `over: motion` is the supremum
of a part's energy over all later times.
"""

from __future__ import annotations

import mpmath
import numpy as np
import sympy as sp

from mechbook.core.numeval import evaluate_mp
from mechbook.core.words import plural
from mechbook.engine.part_energy import LinearMotion, quadratic_part_energy
from mechbook.verify.compare import Verdict
from mechbook.verify.context import Context
from mechbook.verify.registration import POINT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

POINTS = 4
TIMES = (0.37, 1.3, 2.9, 7.1)
RTOL = 1e-20  # both sides at 40 digits


def part_energy_expr(ctx: Context, name: str | None = None, sub: tuple = ("body",)
                     ) -> sp.Expr:
    """The quadratic energy of the part `name` (default: the part's `body:`) about the
    part's equilibrium."""
    name = ctx.part.data.get("body") if name is None else name
    if not isinstance(name, str):
        raise ctx.part.error((), "name the particle or rigid body with `body:`")
    try:
        lin = ctx.linear()
        return quadratic_part_energy(ctx.system, name, lin.point)
    except KeyError as exc:
        raise ctx.part.error(sub, str(exc.args[0])) from None


def linear_motion(ctx: Context, pt: dict) -> LinearMotion:
    """The linearized motion from `initial:` (coordinates and velocities, the rest at the
    equilibrium and at rest) at the parameter point."""
    sys, lin = ctx.system, ctx.linear()
    if "initial" not in ctx.part.data:
        raise ctx.part.error((), "a motion needs `initial:` (coordinates and velocities at "
                             "t = 0; the others at the equilibrium, at rest)")
    eq = [sp.S(lin.point.get(q, 0)) for q in sys.q]
    given_q, given_v = ctx.initial()
    q0 = [given_q.get(i, e) for i, e in enumerate(eq)]
    v0 = [given_v.get(i, sp.S.Zero) for i in range(len(sys.q))]
    if lin.coord_names != list(sys.coord_names):
        raise ctx.part.error(("initial",), "a part's energy along a motion needs every "
                             "coordinate in the linear system (no constraint or reduction)")
    with mpmath.workdps(60):
        dq = [evaluate_mp(a - b, pt, 60) for a, b in zip(q0, eq, strict=True)]
        dv = [evaluate_mp(v, pt, 60) for v in v0]
    return LinearMotion(lin, pt, dq, dv)


class QuadraticEnergy:
    """The part's energy as a function of the displacement state δy = (δq, δq̇):
    g·δy + δy·H·δy/2 (exact: it has no higher terms), g and H at the point in 60 digits;
    calling it evaluates in mpmath, `scan` the same in double precision at many states."""

    def __init__(self, g: list, H: list):
        self.g, self.H = g, H
        self._gf = np.array([float(x) for x in g])
        self._Hf = np.array([[float(x) for x in row] for row in H])

    def __call__(self, dy: list):
        g, H, m = self.g, self.H, len(dy)
        return sum(g[i] * dy[i] for i in range(m)) + sum(
            H[i][j] * dy[i] * dy[j] for i in range(m) for j in range(m)) / 2

    def scan(self, dy: np.ndarray) -> np.ndarray:
        """The energy at each row of dy (states), in double precision."""
        return dy @ self._gf + np.einsum("ki,ij,kj->k", dy, self._Hf, dy) / 2


def energy_at(ctx: Context, energy: sp.Expr, pt: dict) -> QuadraticEnergy:
    """The part's energy about the linearization point as a QuadraticEnergy of δy."""
    sys, lin = ctx.system, ctx.linear()
    y = list(sys.q) + list(sys.qd)
    at0 = {q: sp.S(lin.point.get(q, 0)) for q in sys.q}
    at0.update({v: sp.S.Zero for v in sys.qd})
    with mpmath.workdps(60):
        env = dict(pt)
        for k, v in at0.items():
            env[k] = sp.Float(evaluate_mp(v, pt, 60), 60) if v.free_symbols else v
        grad = [sp.diff(energy, a) for a in y]
        g = [mpmath.re(evaluate_mp(d, env, 60)) for d in grad]
        H = [[mpmath.re(evaluate_mp(sp.diff(d, b), env, 60)) for b in y] for d in grad]
    return QuadraticEnergy(g, H)


@quantity('part_energy',
          book='expression in t: the energy of the part `body:` along the motion',
          how=("the kinetic energy of the particle or rigid body `body:` plus its potential "
               "energy in gravity (a spring's or another interaction's energy belongs to no "
               "one part), to second order about the equilibrium (`about:`) and counted from "
               "its value there, along the linearized motion from `initial:` (state-matrix "
               "eigenvectors at 40 digits): equal to the book's at 4 times at 4 points, "
               "to 1e-20 of the part's energy scale"),
          keys={"body": {"type": "string"}, "initial": POINT})
def check_part_energy(ctx: Context, val) -> Verdict:
    book = ctx.parse(val, ("book",))
    energy = part_energy_expr(ctx)
    t = ctx.system.t
    worst = 0.0
    for k in range(POINTS):
        pt = ctx.sampler.draw()
        motion = linear_motion(ctx, pt)
        at = energy_at(ctx, energy, pt)
        with mpmath.workdps(45):
            engine = [at(motion.state(mpmath.mpf(tv))) for tv in TIMES]
            scale = max([abs(e) for e in engine] + [mpmath.mpf(10) ** -300])
            for tv, e in zip(TIMES, engine, strict=True):
                b = mpmath.re(evaluate_mp(book, {**pt, t: sp.Float(tv, 45)}, 45))
                rel = float(abs(b - e) / scale)
                worst = max(worst, rel)
                if not rel <= RTOL:
                    return Verdict(False, f"numeric({plural(k + 1, 'point')})",
                                   f"at t = {tv}: book {mpmath.nstr(b, 12)}, engine "
                                   f"{mpmath.nstr(e, 12)} (relative {rel:.2g})")
    return Verdict(True, f"numeric({POINTS} points x {len(TIMES)} times, 40 digits)",
                   f"worst relative {worst:.2g}",
                   power=f"{POINTS} points x {len(TIMES)} times at 40 digits, within "
                         f"{RTOL:g} of the part's energy")
