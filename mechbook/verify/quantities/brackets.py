"""Poisson brackets (`poisson_bracket`) over a part's phase space, which canonical
transformations (mechbook.verify.quantities.canonical) share.

The phase space of a part is its canonical pairs (q_i, p_i) and the time t: by default the
system's coordinates and momenta p_<q> (the variables of the engine's Hamiltonian, which a
part may call `H`), or the pairs `variables: [[x, p_x], ...]` lists (new names become
symbols of the part; `H:` then gives the Hamiltonian in them). Every expression of such a
part must be a function of those variables, t and the parameters: a velocity, a
multiplier or any other name is refused at its line, so a bracket over names that are not
canonical variables cannot be checked by mistake. Reading the part's names parses its own
keys too (`bracket:`, `variables:`, and a map's `new:`), so `mechbook validate` refuses a
malformed part before anything is derived.

Each claim becomes residuals in (q, p, t) that must vanish identically: decided at random
points in 30-digit arithmetic (mechbook.verify.compare.vanishes: 6 points, each residual
to 1e-20 of what cancels in it), then, for a pass, proved by SymPy where it reduces the
residual to 0 within 2 s (the verdict then says `symbolic`).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from mechbook.core.algebra_reach import within_exact_reach
from mechbook.core.identity import decide_zero
from mechbook.core.timeout import Timeout, time_limit
from mechbook.errors import UnsupportedError
from mechbook.verify.compare import Sampler, Verdict, combine, vanishes
from mechbook.verify.context import Context
from mechbook.verify.registration import EXPR, NAME, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

PAIRS = {"type": "array", "minItems": 1, "maxItems": 16,
         "items": {"type": "array", "minItems": 2, "maxItems": 2, "items": NAME}}
SYMBOLIC_SECONDS = 2.0  # the budget of SymPy's attempt to prove a residual zero


@dataclass(frozen=True)
class PhaseSpace:
    """A part's canonical pairs, its time, its names (the pairs' new symbols and `H`
    included) and the old Hamiltonian (None where there is none: no system, no `H:`)."""

    q: tuple
    p: tuple
    t: sp.Symbol
    names: dict
    hamiltonian: sp.Expr | None
    hsym: sp.Symbol | None  # the placeholder `H` parses to (replaced by the Hamiltonian)

    @property
    def variables(self) -> set:
        return set(self.q) | set(self.p) | {self.t}


def bracket(f: sp.Expr, g: sp.Expr, q, p) -> sp.Expr:
    """{f, g} = Σ ∂f/∂q_i ∂g/∂p_i − ∂f/∂p_i ∂g/∂q_i.

    >>> x, px = sp.symbols("x p_x")
    >>> bracket(x, px, [x], [px])
    1
    """
    return sum((sp.diff(f, qi) * sp.diff(g, pi) - sp.diff(f, pi) * sp.diff(g, qi)
                for qi, pi in zip(q, p, strict=True)), sp.S.Zero)


# ---- the part's phase space ---------------------------------------------------------------
def phase_space(ctx: Context) -> PhaseSpace:
    """The part's canonical pairs and names: `variables:` if given (each name new, or a
    coordinate or momentum of the system), else the system's coordinates and momenta."""
    names = dict(ctx.names)
    t = names.get("t") if isinstance(names.get("t"), sp.Symbol) else sp.Symbol("t", real=True)
    names.setdefault("t", t)
    system = ctx.system
    own = {}  # the system's canonical variables, by name
    if system is not None:
        for c, q in zip(system.coord_names, system.q, strict=True):
            own[c] = q
            own["p_" + c] = names["p_" + c]
    spec = ctx.part.data.get("variables")
    if spec is None:
        if system is None:
            raise ctx.part.error(("quantity",), f"a {ctx.part.quantity!r} part of a problem "
                                 "without a system names its canonical pairs: "
                                 "`variables: [[q, p], ...]`")
        q = tuple(system.q)
        p = tuple(names["p_" + c] for c in system.coord_names)
    else:
        q, p = _named_pairs(ctx, spec, names, own)
    hsym, hamiltonian = None, None
    if "H" in ctx.part.data:
        if "H" in ctx.names:
            raise ctx.part.error(("H",), "'H' is already a name of the problem or key")
        hsym = sp.Symbol("H", real=True)
        names["H"] = hsym
        hamiltonian = in_phase_space(ctx, ctx.part.data["H"], ("H",), names,
                                      set(q) | set(p) | {t})
    elif "H" not in names and system is not None and spec is None:
        hsym = sp.Symbol("H", real=True)  # the engine's Hamiltonian, derived when used
        names["H"] = hsym
    return PhaseSpace(q, p, t, names, hamiltonian, hsym)


def _named_pairs(ctx: Context, spec: list, names: dict, own: dict) -> tuple:
    q, p = [], []
    seen = set()
    for i, pair in enumerate(spec):
        pair_syms = []
        for j, name in enumerate(pair):
            sub = ("variables", i, j)
            if name in seen:
                raise ctx.part.error(sub, f"{name!r} is named twice among the canonical pairs")
            seen.add(name)
            if name in own:
                sym = own[name]
            elif name in ctx.names:
                raise ctx.part.error(sub, f"{name!r} is {_what(ctx, name)}, not a canonical "
                                     "variable: a pair names the system's coordinates and "
                                     "momenta (p_<q>) or new names")
            else:
                sym = sp.Symbol(name, real=True)
                names[name] = sym
            pair_syms.append(sym)
        q.append(pair_syms[0])
        p.append(pair_syms[1])
    return tuple(q), tuple(p)


def _what(ctx: Context, name: str) -> str:
    """What an existing name is, for a refusal."""
    sym = ctx.names[name]
    system = ctx.system
    if system is not None and sym in set(system.qd):
        return "a velocity"
    if isinstance(sym, sp.Symbol) and sym in ctx.sampler.base:
        return "a parameter (or answer symbol)"
    if name == "t":
        return "the time"
    return "a name of the problem or key (an abbreviation, a multiplier, a rate)"


def in_phase_space(ctx: Context, text, sub: tuple, names: dict, allowed: set) -> sp.Expr:
    """`text` parsed, and refused at `sub` if it holds a symbol that is neither an allowed
    variable nor a parameter (a velocity, a multiplier, a coordinate left out)."""
    expr = ctx.parse(text, sub, names=names)
    stray = sorted(str(s) for s in expr.free_symbols
                   if s not in allowed and s not in ctx.sampler.base)
    if stray:
        known = ", ".join(sorted(str(s) for s in allowed if s.name != "H"))
        known += " (and H, the Hamiltonian)" if any(s.name == "H" for s in allowed) else ""
        hint = " (a velocity: write the momentum p_<q>)" if any(
            s.endswith("dot") for s in stray) else ""
        raise ctx.part.error(sub, f"{', '.join(stray)} is not a canonical variable of this "
                             f"part{hint}; its variables are {known} and the parameters")
    return expr


def _with_hamiltonian(ctx: Context, space: PhaseSpace, expr: sp.Expr, sub: tuple) -> sp.Expr:
    """`expr` with the placeholder `H` replaced by the Hamiltonian (the engine's, of a
    system with no constraints and no forces outside V, or the part's `H:`)."""
    if space.hsym is None or space.hsym not in expr.free_symbols:
        return expr
    return expr.xreplace({space.hsym: old_hamiltonian(ctx, space, sub)})


def old_hamiltonian(ctx: Context, space: PhaseSpace, sub: tuple) -> sp.Expr:
    """H(q, p, t): the part's `H:`, or the engine's, whose flow is the system's motion only
    without constraints and without forces outside the Lagrangian."""
    if space.hamiltonian is not None:
        return space.hamiltonian
    if ctx.system is None or ctx.part.data.get("variables") is not None:
        raise ctx.part.error(sub, "the Hamiltonian of these variables is not known: give it "
                             "as `H:`")
    sys = ctx.system
    if sys.constraints or sys.velocity_constraints:
        raise UnsupportedError("canonical structure of a system with constraints (its "
                               "(q, p_q) are not canonical coordinates of the motion)")
    if any(f != 0 for f in sys.forces):
        raise UnsupportedError("canonical structure of a system with forces outside its "
                               "Lagrangian (its motion is not Hamilton's flow of H)")
    return ctx.dyn.hamiltonian


def free_sampler(ctx: Context) -> Sampler:
    """The part's sampler without a constraint manifold: phase-space points are drawn
    freely (a bracket is an identity over all of phase space)."""
    s = ctx.sampler
    return Sampler(s.base, s.conditions, policy=s.policy, rtol=s.rtol, fixed=list(s.fixed),
                   derived=s.derived, approximate=s.approximate)


# ---- deciding residuals ------------------------------------------------------------------
def identically_zero(residuals: list[tuple[str, sp.Expr]], sampler: Sampler) -> Verdict:
    """Every residual vanishes: at 6 random points at 30 digits (to 1e-20 of what cancels),
    then proved by SymPy where it reduces each to 0 within SYMBOLIC_SECONDS."""
    verdicts = []
    for label, expr in residuals:
        v = vanishes(expr, sampler, symbolic=False)
        if not v.ok:
            return Verdict(False, v.method, f"{label}: {v.detail}")
        verdicts.append(v)
    numeric = combine(verdicts)
    if all(_proved(e, sampler) for _, e in residuals):
        return Verdict(True, "symbolic", "SymPy reduces every residual to 0",
                       power=f"proved symbolically ({numeric.power} too)")
    return numeric


def _proved(expr: sp.Expr, sampler: Sampler) -> bool:
    """0 by the exact canonical forms (milliseconds), else by SymPy within its seconds."""
    if not expr.atoms(sp.Float) and decide_zero(expr).zero is True:
        return True
    if not within_exact_reach(expr):  # simplify would abort the process in gmp
        return False
    seconds = sampler.policy.seconds if sampler.policy.prove else SYMBOLIC_SECONDS
    try:
        with time_limit(seconds):
            if expr == 0 or sp.expand(expr) == 0:
                return True
            return sp.simplify(expr) == 0
    except Timeout:
        return False
    except Exception:  # noqa: BLE001 - SymPy's odd failures: the points have decided
        return False


def somewhere_nonzero(residuals: list[tuple[str, sp.Expr]], sampler: Sampler) -> Verdict:
    """A claim that the residuals do not all vanish: it passes where one of them is clearly
    nonzero at a point (beyond 1e-20 of its scale), and fails where all vanish."""
    for label, expr in residuals:
        v = vanishes(expr, sampler, symbolic=False)
        if not v.ok and "residual" in v.detail:
            return Verdict(True, v.method, f"{label} does not hold: {v.detail}",
                           power="a point where it fails, at 30 digits")
        if not v.ok:
            raise UnsupportedError(f"{label}: {v.detail}")
    return Verdict(False, "numeric", "every one holds at every point drawn: "
                   + ", ".join(label for label, _ in residuals))


# ---- poisson_bracket ---------------------------------------------------------------------
def _bracket_names(ctx: Context) -> dict:
    """The names a bracket's `book:` may use: the phase space's (its `bracket:` parsed too)."""
    space = phase_space(ctx)
    _bracket_of(ctx, space)
    return space.names


def _bracket_of(ctx: Context, space: PhaseSpace) -> tuple[sp.Expr, sp.Expr]:
    of = ctx.part.data.get("bracket")
    if not isinstance(of, list) or len(of) != 2:
        raise ctx.part.error(("bracket",), "a bracket names its two functions: `bracket: [f, g]`")
    allowed = space.variables | ({space.hsym} if space.hsym is not None else set())
    f, g = (in_phase_space(ctx, text, ("bracket", i), space.names, allowed)
            for i, text in enumerate(of))
    return f, g


def bracket_claim(ctx: Context) -> tuple | None:
    """(f, g, h, H) of a bracket part over the system's own variables, H the placeholder
    of the engine's Hamiltonian (for a cross-check: mechbook.crosscheck.brackets); None
    where the part names its variables or its Hamiltonian."""
    if ctx.part.data.get("variables") is not None or "H" in ctx.part.data:
        return None
    space = phase_space(ctx)
    if space.hsym is None:
        return None
    f, g = _bracket_of(ctx, space)
    allowed = space.variables | {space.hsym}
    h = in_phase_space(ctx, ctx.part.data.get("book"), ("book",), space.names, allowed)
    return f, g, h, space.hsym


@quantity('poisson_bracket',
          book='expression h: the bracket {f, g} of the two functions `bracket: [f, g]`',
          how=('{f, g} = Σ ∂f/∂q ∂g/∂p − ∂f/∂p ∂g/∂q over the system\'s canonical variables '
               '(coordinates and momenta `p_<q>`; `H` is the engine\'s Hamiltonian) or the '
               'pairs `variables: [[q, p], …]` names (`H:` their Hamiltonian); f, g, h '
               'functions of those, t and the parameters (any other name refused at its '
               'line): {f, g} − h vanishes at 6 random points at 30 digits (to 1e-20 of its '
               'scale), and `symbolic` where SymPy reduces it to 0. The fundamental '
               'brackets are `bracket: [q, p]`, `book: 1`'),
          keys={"bracket": {"type": "array", "minItems": 2, "maxItems": 2, "items": EXPR},
                "variables": PAIRS, "H": EXPR},
          names=_bracket_names, crosschecks=("bracket_flow",))
def check_poisson_bracket(ctx: Context, val) -> Verdict:
    """{f, g} = h as an identity in the part's phase space."""
    space = phase_space(ctx)
    f, g = _bracket_of(ctx, space)
    allowed = space.variables | ({space.hsym} if space.hsym is not None else set())
    h = in_phase_space(ctx, val, ("book",), space.names, allowed)
    f, g, h = (_with_hamiltonian(ctx, space, e, sub)
               for e, sub in ((f, ("bracket", 0)), (g, ("bracket", 1)), (h, ("book",))))
    residual = bracket(f, g, space.q, space.p) - h
    return identically_zero([("{f, g} − h", residual)], free_sampler(ctx))
