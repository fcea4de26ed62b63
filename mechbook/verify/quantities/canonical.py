"""Canonical structure: Poisson brackets (`poisson_bracket`) and canonical transformations
(`canonical`), over the system's canonical variables or over pairs a part names.

The phase space of a part is its canonical pairs (q_i, p_i) and the time t: by default the
system's coordinates and momenta p_<q> (the variables of the engine's Hamiltonian, which a
part may call `H`), or the pairs `variables: [[x, p_x], ...]` lists (new names become
symbols of the part; `H:` then gives the Hamiltonian in them). Every expression of such a
part must be a function of those variables, t and the parameters: a velocity, a
multiplier or any other name is refused at its line, so a bracket over names that are not
canonical variables cannot be checked by mistake. Reading the part's names parses its own
keys too (`bracket:`, `variables:`, `new:`), so `mechbook validate` refuses a malformed part
before anything is derived.

Each claim becomes residuals in (q, p, t) that must vanish identically: decided at random
points in 30-digit arithmetic (mechbook.verify.compare.vanishes: 6 points, each residual
to 1e-20 of what cancels in it), then, for a pass, proved by SymPy where it reduces the
residual to 0 within 2 s (the verdict then says `symbolic`). No inversion of a map is
needed: a generating function's relations are checked with the stated map put in, and a
new Hamiltonian K through Hamilton's equations in the new variables along the old flow.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

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
GENERATING = {  # F's arguments (old, new: 'q' or 'p' of each), and the relations it gives
    "F1": ("q", "Q"), "F2": ("q", "P"), "F3": ("p", "Q"), "F4": ("p", "P")}


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
        hamiltonian = _in_phase_space(ctx, ctx.part.data["H"], ("H",), names,
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


def _in_phase_space(ctx: Context, text, sub: tuple, names: dict, allowed: set) -> sp.Expr:
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
                   derived=s.derived)


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
    f, g = (_in_phase_space(ctx, text, ("bracket", i), space.names, allowed)
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
    h = _in_phase_space(ctx, ctx.part.data.get("book"), ("book",), space.names, allowed)
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
    h = _in_phase_space(ctx, val, ("book",), space.names, allowed)
    f, g, h = (_with_hamiltonian(ctx, space, e, sub)
               for e, sub in ((f, ("bracket", 0)), (g, ("bracket", 1)), (h, ("book",))))
    residual = bracket(f, g, space.q, space.p) - h
    return identically_zero([("{f, g} − h", residual)], free_sampler(ctx))


# ---- canonical ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Transformation:
    """A map (q, p, t) → (Q, P): the new symbols and their values in the old variables."""

    Q: tuple
    P: tuple
    values: dict  # new symbol -> its expression in (q, p, t)


def _book_map(ctx: Context, val) -> dict:
    if not isinstance(val, dict) or "transformation" not in val:
        raise ctx.part.error(("book",), "a 'canonical' part's book is a mapping: "
                             "{transformation: {Q: ..., P: ...}, canonical: true, "
                             "generating: {F2: ...}, hamiltonian: K}")
    extra = set(val) - {"transformation", "canonical", "generating", "hamiltonian"}
    if extra:
        raise ctx.part.error(("book", sorted(extra)[0]), "the book of a 'canonical' part "
                             "holds transformation, canonical, generating, hamiltonian")
    if not isinstance(val["transformation"], dict):
        raise ctx.part.error(("book", "transformation"), "expected a mapping {Q: ..., P: ...}")
    if not isinstance(val.get("canonical", True), bool):
        raise ctx.part.error(("book", "canonical"), "canonical: true or false")
    return val


def _new_names(ctx: Context, space: PhaseSpace, mapping: dict) -> tuple[list, list]:
    """The new pairs: `new:` if given, else the transformation's names in order, each new
    coordinate followed by its momentum."""
    n = len(space.q)
    spec = ctx.part.data.get("new")
    if spec is None:
        keys = list(mapping)
        if len(keys) != 2 * n:
            raise ctx.part.error(("book", "transformation"), f"{2 * n} new variables for "
                                 f"{n} canonical pair(s), each coordinate followed by its "
                                 "momentum (or name the pairs with `new:`)")
        spec = [keys[2 * i: 2 * i + 2] for i in range(n)]
        where = ("book", "transformation")
    else:
        where = ("new",)
        if len(spec) != n:
            raise ctx.part.error(where, f"{n} new pair(s), one per old pair")
        missing = [x for pair in spec for x in pair if x not in mapping]
        if missing or len(mapping) != 2 * n:
            raise ctx.part.error(("book", "transformation"), "the transformation gives each "
                                 "new variable of `new:` and nothing else"
                                 + (f" ({missing[0]!r} is missing)" if missing else ""))
    seen = set()
    for pair in spec:
        for name in pair:
            if name in space.names or name in seen:
                raise ctx.part.error(where, f"{name!r} is already a name: a new variable "
                                     "needs a name of its own")
            seen.add(name)
    return [pair[0] for pair in spec], [pair[1] for pair in spec]


def _setting(ctx: Context, val) -> tuple[PhaseSpace, Transformation, dict]:
    """The part's phase space, its map (parsed, each value a function of the old
    variables) and the names its other claims use (the new variables too)."""
    val = _book_map(ctx, val)
    space = phase_space(ctx)
    mapping = val["transformation"]
    qs, ps = _new_names(ctx, space, mapping)
    names = dict(space.names)
    Q = tuple(sp.Symbol(x, real=True) for x in qs)
    P = tuple(sp.Symbol(x, real=True) for x in ps)
    names.update({s.name: s for s in Q + P})
    values = {s: _in_phase_space(ctx, mapping[s.name], ("book", "transformation", s.name),
                                 space.names, space.variables) for s in Q + P}
    return space, Transformation(Q, P, values), names


def _open_claim(data: dict) -> tuple:
    """What a change of the part's book cannot show (mechbook.verify.power): "not
    canonical" holds for every map near one that is not ("open"), and a generating function
    is defined up to an added constant ("shift": a shifted map or K then fails the
    generating function's relations, so only F's constant is left unseen)."""
    book = data.get("book")
    if not isinstance(book, dict):
        return ()
    if book.get("canonical") is False:
        return ("open",)
    return ("shift",) if "generating" in book else ()


def _canonical_names(ctx: Context) -> dict:
    return _setting(ctx, ctx.part.data.get("book"))[2]


def fundamental(space: PhaseSpace, tr: Transformation) -> list[tuple[str, sp.Expr]]:
    """{Q_i, Q_j}, {P_i, P_j} (i < j) and {Q_i, P_j} − δ_ij in the old variables: all
    vanish exactly when MᵀJM = J (the map is canonical, valence 1)."""
    val = tr.values
    out = []
    n = len(tr.Q)
    for i in range(n):
        for j in range(n):
            out.append((f"{{{tr.Q[i]}, {tr.P[j]}}} − {int(i == j)}",
                        bracket(val[tr.Q[i]], val[tr.P[j]], space.q, space.p) - int(i == j)))
            if i < j:
                for a in (tr.Q, tr.P):
                    out.append((f"{{{a[i]}, {a[j]}}}",
                                bracket(val[a[i]], val[a[j]], space.q, space.p)))
    return out


def generated(ctx: Context, space: PhaseSpace, tr: Transformation, names: dict,
              spec) -> tuple[list[tuple[str, sp.Expr]], str, sp.Expr]:
    """The relations a generating function gives, as residuals in the old variables with
    the stated map put in (no inversion); its kind and F itself.
    F1(q, Q): p = ∂F/∂q, P = −∂F/∂Q.  F2(q, P): p = ∂F/∂q, Q = ∂F/∂P.
    F3(p, Q): q = −∂F/∂p, P = −∂F/∂Q.  F4(p, P): q = −∂F/∂p, Q = ∂F/∂P."""
    sub = ("book", "generating")
    if not isinstance(spec, dict) or len(spec) != 1 or next(iter(spec)) not in GENERATING:
        raise ctx.part.error(sub, "one generating function: {F1: ...}, {F2: ...}, {F3: ...} "
                             "or {F4: ...}")
    kind, text = next(iter(spec.items()))
    old_kind, new_kind = GENERATING[kind]
    old = space.q if old_kind == "q" else space.p
    new = tr.Q if new_kind == "Q" else tr.P
    F = _in_phase_space(ctx, text, sub + (kind,), names, set(old) | set(new) | {space.t})
    put = {s: tr.values[s] for s in new}
    out = []
    n = len(space.q)
    for i in range(n):
        if old_kind == "q":  # p_i = ∂F/∂q_i
            out.append((f"∂{kind}/∂{space.q[i]} − {space.p[i]}",
                        sp.diff(F, space.q[i]).xreplace(put) - space.p[i]))
        else:  # q_i = −∂F/∂p_i
            out.append((f"−∂{kind}/∂{space.p[i]} − {space.q[i]}",
                        -sp.diff(F, space.p[i]).xreplace(put) - space.q[i]))
        if new_kind == "Q":  # P_i = −∂F/∂Q_i
            out.append((f"−∂{kind}/∂{tr.Q[i]} − {tr.P[i]}",
                        -sp.diff(F, tr.Q[i]).xreplace(put) - tr.values[tr.P[i]]))
        else:  # Q_i = ∂F/∂P_i
            out.append((f"∂{kind}/∂{tr.P[i]} − {tr.Q[i]}",
                        sp.diff(F, tr.P[i]).xreplace(put) - tr.values[tr.Q[i]]))
    return out, kind, F.diff(space.t).xreplace(put)


def new_hamiltonian(ctx: Context, space: PhaseSpace, tr: Transformation, names: dict,
                    text, dF_dt: sp.Expr | None) -> list[tuple[str, sp.Expr]]:
    """The book's K(Q, P, t) as residuals in the old variables: Hamilton's equations in the
    new variables along the old flow, Q̇ = {Q, H} + ∂Q/∂t = ∂K/∂P and Ṗ = −∂K/∂Q (which fix
    K up to a function of t alone), and, where a generating function is given,
    K = H + ∂F/∂t itself."""
    sub = ("book", "hamiltonian")
    K = _in_phase_space(ctx, text, sub, names, set(tr.Q) | set(tr.P) | {space.t})
    H = old_hamiltonian(ctx, space, sub)
    put = dict(tr.values)
    out = []
    for Qi, Pi in zip(tr.Q, tr.P, strict=True):
        qv, pv = tr.values[Qi], tr.values[Pi]
        out.append((f"{Qi}' − ∂K/∂{Pi}", bracket(qv, H, space.q, space.p) + qv.diff(space.t)
                    - K.diff(Pi).xreplace(put)))
        out.append((f"{Pi}' + ∂K/∂{Qi}", bracket(pv, H, space.q, space.p) + pv.diff(space.t)
                    + K.diff(Qi).xreplace(put)))
    if dF_dt is not None:
        out.append(("K − (H + ∂F/∂t)", K.xreplace(put) - H - dF_dt))
    return out


def hamiltonian_claim(ctx: Context) -> tuple | None:
    """(new pairs [(Q, P)], {new symbol: its value in (q, p, t)}, K) of a canonical part
    that states a new Hamiltonian over the system's own variables (for a cross-check:
    mechbook.crosscheck.brackets); None otherwise."""
    val = ctx.part.data.get("book")
    if ctx.part.data.get("variables") is not None or "H" in ctx.part.data or \
            not isinstance(val, dict) or "hamiltonian" not in val or \
            val.get("canonical", True) is False:
        return None
    space, tr, names = _setting(ctx, val)
    K = _in_phase_space(ctx, val["hamiltonian"], ("book", "hamiltonian"), names,
                        set(tr.Q) | set(tr.P) | {space.t})
    return list(zip(tr.Q, tr.P, strict=True)), dict(tr.values), K


@quantity('canonical',
          book=('`{transformation: {Q: …, P: …}, canonical: true or false, generating: '
                '{F2: F} (or F1, F3, F4), hamiltonian: K}` (only `transformation` required)'),
          how=('the map (q, p, t) → (Q, P), each new variable a function of the old '
               'canonical variables (the system\'s, or `variables:`), t and the parameters, '
               'in pairs (each new coordinate then its momentum, or `new: [[Q, P], …]`): '
               'canonical (valence 1) exactly when its fundamental brackets {Q_i, P_j} = '
               'δ_ij, {Q_i, Q_j} = {P_i, P_j} = 0 hold (MᵀJM = J), as residuals at 6 random '
               'points at 30 digits (to 1e-20 of their scale; `symbolic` where SymPy '
               'proves them); `canonical: false` passes only where one fails at a point. '
               '`generating:` F1(q, Q, t), F2(q, P, t), F3(p, Q, t) or F4(p, P, t) must '
               'give the stated map (p = ∂F1/∂q, P = −∂F1/∂Q, …, with the map put in: no '
               'inversion); `hamiltonian:` K(Q, P, t) must satisfy Hamilton\'s equations '
               'in the new variables along the old flow (Q̇ = {Q, H} + ∂Q/∂t = ∂K/∂P, '
               'Ṗ = −∂K/∂Q) and, with a generating function, equal H + ∂F/∂t (without '
               'one K is fixed only up to a function of t, and the verdict says so)'),
          keys={"variables": PAIRS, "new": PAIRS, "H": EXPR},
          names=_canonical_names, equivalent=_open_claim,
          crosschecks=("new_hamiltonian",))
def check_canonical(ctx: Context, val) -> Verdict:
    """The map's fundamental brackets, its generating function, its new Hamiltonian."""
    space, tr, names = _setting(ctx, val)
    sampler = free_sampler(ctx)
    if not val.get("canonical", True):
        if "generating" in val or "hamiltonian" in val:
            raise ctx.part.error(("book", "canonical"), "a map that is not canonical has no "
                                 "generating function or new Hamiltonian")
        return somewhere_nonzero(fundamental(space, tr), sampler)
    verdicts = [identically_zero(fundamental(space, tr), sampler)]
    if not verdicts[-1].ok:
        return _labelled(verdicts[-1], "not canonical")
    dF_dt = None
    if "generating" in val:
        relations, kind, dF_dt = generated(ctx, space, tr, names, val["generating"])
        verdicts.append(identically_zero(relations, sampler))
        if not verdicts[-1].ok:
            return _labelled(verdicts[-1], f"{kind} does not generate the map")
    if "hamiltonian" in val:
        verdicts.append(identically_zero(
            new_hamiltonian(ctx, space, tr, names, val["hamiltonian"], dF_dt), sampler))
        if not verdicts[-1].ok:
            return _labelled(verdicts[-1], "the new Hamiltonian is not K")
    out = combine(verdicts)
    claims = ["the fundamental brackets"] + (["the generating function"] if dF_dt is not None
                                             else [])
    if "hamiltonian" in val:
        claims.append("K" if dF_dt is not None else
                      "K up to a function of t (no generating function given)")
    detail = "; ".join(dict.fromkeys(v.detail for v in verdicts if v.detail))
    return Verdict(True, out.method, detail, power=f"{', '.join(claims)}: {out.power}")


def _labelled(v: Verdict, what: str) -> Verdict:
    return Verdict(False, v.method, f"{what}: {v.detail}", power=v.power)
