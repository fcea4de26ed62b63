"""Canonical transformations (`canonical`): a map (q, p, t) → (Q, P) stated by the book,
whether it is canonical, the generating function that gives it, and the new Hamiltonian,
in the part's phase space (mechbook.verify.quantities.brackets: its canonical pairs, names
and residuals).

No inversion of a map is needed: canonical means the new variables' fundamental brackets
hold in the old variables; a generating function's relations are checked with the stated
map put in for its new arguments; a new Hamiltonian K through Hamilton's equations in the
new variables along the old flow and, with a generating function, K = H + ∂F/∂t.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from mechbook.verify.compare import Verdict, combine
from mechbook.verify.context import Context
from mechbook.verify.quantities.brackets import (
    PAIRS,
    PhaseSpace,
    bracket,
    free_sampler,
    identically_zero,
    in_phase_space,
    old_hamiltonian,
    phase_space,
    somewhere_nonzero,
)
from mechbook.verify.registration import EXPR, Family

FAMILY = Family()  # this module's quantities (mechbook.verify.registry lists it)
quantity = FAMILY.quantity

GENERATING = {  # F's arguments (old, new: 'q' or 'p' of each), and the relations it gives
    "F1": ("q", "Q"), "F2": ("q", "P"), "F3": ("p", "Q"), "F4": ("p", "P")}


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
    values = {s: in_phase_space(ctx, mapping[s.name], ("book", "transformation", s.name),
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
    F = in_phase_space(ctx, text, sub + (kind,), names, set(old) | set(new) | {space.t})
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
    K = in_phase_space(ctx, text, sub, names, set(tr.Q) | set(tr.P) | {space.t})
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
    K = in_phase_space(ctx, val["hamiltonian"], ("book", "hamiltonian"), names,
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
