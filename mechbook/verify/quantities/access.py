"""Whether a configuration lies inside the region the first integrals allow: `accessible`.

The book states a relation between the values of first integrals (the energy E, a cyclic
momentum p_phi) and the parameters under which a motion reaches a configuration (an angle
where a string goes slack). The part names the configuration (`at:`, which may use the
integrals' names) and what each name of the relation is (`integrals: {E: {of: energy,
value: ...}, p_phi: {of: p_phi, value: ...}}`: the energy function, or the momentum
p_<q> of a cyclic coordinate; `value` centres their sampling). In this part those names
stand for numbers. A name that is also an abbreviation of the key (a first integral
written through the state) must be the engine's quantity itself (the energy function
exactly, constant included: the relation is about its values); otherwise it is an error.

The engine's verdict (mechbook.engine.access): reachable exactly when the least energy
at the configuration, with the momenta held, is at most E. The relation is decided at its
boundary (mechbook.verify.boundary) over the parameters and the integrals' values, so a
boundary moved by 1e-8 fails. Where the configuration does not exist (a cosine beyond
±1) there is no verdict.
"""

from __future__ import annotations

import mpmath
import sympy as sp

from mechbook.core.numeval import NotNumeric, evaluate_mp
from mechbook.engine.access import Access
from mechbook.verify import boundary
from mechbook.verify.compare import Sampler, Verdict, equal
from mechbook.verify.context import Context
from mechbook.verify.registration import POINT, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

INTEGRALS = {"type": "object", "minProperties": 1,
             "propertyNames": {"pattern": "^[A-Za-z][A-Za-z0-9_]*$"},
             "additionalProperties": {
                 "type": "object", "required": ["of", "value"], "additionalProperties": False,
                 "properties": {"of": {"type": "string"}, "value": {"type": "number"}}}}


def _integrals(ctx: Context) -> tuple[dict, dict, dict]:
    """(names for parsing, {symbol: 'energy' or coordinate}, {symbol: default value})."""
    data = ctx.part.data
    if "integrals" not in data:
        raise ctx.part.error((), "name the first integrals the relation uses: `integrals: "
                             "{E: {of: energy, value: ...}}`")
    dyn, sys = ctx.dyn, ctx.system
    abbreviations = ctx.part.key.doc.data.get("abbreviations") or {}
    names = dict(ctx.names)
    what, base = {}, {}
    for name, spec in data["integrals"].items():
        sub = ("integrals", name)
        of = spec["of"]
        if of == "energy":
            engine = dyn.energy_function
        elif of.startswith("p_") and of[2:] in sys.coord_names:
            engine = dyn.momenta[sys.coord_names.index(of[2:])]
        else:
            raise ctx.part.error(sub + ("of",), "an integral is `energy` or the momentum "
                                 "p_<coordinate> of a cyclic coordinate")
        if name in names and name != of:
            if name not in abbreviations:
                raise ctx.part.error(sub, f"{name!r} is already a name of the problem or key "
                                     "(a parameter, coordinate or symbol)")
            same = equal(names[name], engine, ctx.sampler, symbolic=False)
            if not same.ok:
                raise ctx.part.error(sub, f"abbreviation {name!r} is not the engine's {of} "
                                     f"({same.detail}): the relation would be about another "
                                     "quantity")
        sym = sp.Symbol(name, real=True)
        names[name] = sym
        what[sym] = "energy" if of == "energy" else sys.q[sys.coord_names.index(of[2:])]
        base[sym] = float(spec["value"])
    if "energy" not in what.values():
        raise ctx.part.error(("integrals",), "the energy must be one of the integrals (with "
                             "only momenta held every configuration is reachable)")
    return names, what, base


@quantity('accessible',
          book='relation between the first integrals\' values (`integrals:`) and the '
               'parameters under which the configuration `at:` is reached',
          how=('holds exactly where the configuration can be reached on the level set: the '
               'least energy function over the velocities there, with the named cyclic '
               'momenta held and the constraints\' velocities, is at most the energy (one '
               'linear solve, 40 digits); decided at the relation\'s boundary over the '
               'parameters and the integrals\' values (8 rays, crossings to 1e-8); an '
               'abbreviation used as an integral\'s name must be the engine\'s integral'),
          keys={"at": POINT, "integrals": INTEGRALS})
def check_accessible(ctx: Context, val) -> Verdict:
    names, what, base = _integrals(ctx)
    sys = ctx.system
    cond = ctx.parse(val, ("book",), relation=True, names=names)
    at = ctx.as_map(ctx.part.data.get("at") or {}, ("at",))
    config = {}
    for k, v in at.items():
        if k not in sys.coord_names:
            raise ctx.part.error(("at", k), f"{k!r} is not a coordinate")
        config[sys.q[sys.coord_names.index(k)]] = ctx.parse(v, ("at", k), names=names)
    for q in sys.q:
        if q not in config and q not in ctx.dyn.cyclic:
            raise ctx.part.error(("at",), f"the configuration leaves {q} open (only cyclic "
                                 "coordinates may be left out)")
        config.setdefault(q, sp.S.Zero)
    energy = next(s for s, w in what.items() if w == "energy")
    held = {w: s for s, w in what.items() if w != "energy"}
    access = Access(ctx.dyn, list(held))
    sampler = Sampler({**ctx.sampler.base, **base}, ctx.sampler.conditions,
                      policy=ctx.policy, derived=ctx.sampler.derived,
                      approximate=ctx.sampler.approximate)

    def reachable(pt: dict, near: bool):
        dps = 60 if near else 40
        with mpmath.workdps(dps):
            cfg = {}
            for q, e in config.items():
                try:  # numeval: SymPy's subs and N at every sample cost far more
                    v = mpmath.mpmathify(evaluate_mp(e, pt, dps))
                except (NotNumeric, ValueError, ZeroDivisionError, TypeError, OverflowError):
                    return None  # the configuration does not exist here
                re, im = mpmath.re(v), mpmath.im(v)
                if not mpmath.isfinite(re) or abs(im) > 1e-25 * max(1, abs(re)):
                    return None
                cfg[q] = sp.Float(re, dps)
            if access.on_constraints(cfg, pt, dps) > 1e-20:
                raise ctx.part.error(("at",), "the configuration is not on the constraints")
            try:
                least = access.least_energy(cfg, {q: pt[s] for q, s in held.items()}, pt, dps)
            except ValueError:
                return None
            return bool(least <= mpmath.mpf(pt[energy]._mpf_))

    return boundary.verdict(boundary.compare(cond, reachable, sampler,
                                             ("reached", "not reached")))
