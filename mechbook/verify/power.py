"""When a changed answer still means the same: the equivalent mutants of a power measurement.

A mutant that the checker passes is a miss only if it is wrong. It is not wrong when it
provably means what the original meant, or is itself a true statement of the same kind:

- the same value (a factor that cancels), at 30-digit random points;
- an equation multiplied by a factor free of the motion (q, q̇, q̈, t);
- a relation true at exactly the same points (compared at its boundary,
  mechbook.verify.boundary);
- the same to the order a `limit:` claims (the two differ only beyond it; for a mode
  shape, measured against the whole shape);
- a free answer symbol (declared in `symbols:`, sampled, fixed by nothing) that occurs once
  in the part, rescaled — or a constant added where such a symbol enters additively: the
  same family of answers, reparametrized (C·t + D with D → D + c);
- a bare first integral changed into another one (its time derivative along the motion
  proved zero by SymPy);
- a change the quantity declares it cannot see (`equivalent=` in its registration): a
  conserved quantity's function ("function"), a constant added ("shift"), a factor
  ("scale"), a total time derivative ("gauge"), a mode shape's or an axis's length
  ("direction").

Anything not shown to mean the same counts against the checker (bench/power.py,
tests/test_power.py).
"""

from __future__ import annotations

import ast
import itertools

import sympy as sp

from mechbook.core.algebra_reach import within_exact_reach
from mechbook.core.numeval import NotNumeric, evaluate_mp, holds
from mechbook.core.timeout import Timeout, time_limit
from mechbook.errors import UnsupportedError
from mechbook.model.expr import split_single_equals
from mechbook.model.tensorexpr import parse_tensor, parse_tensor_equation
from mechbook.verify import boundary
from mechbook.verify.asymptotic import asymptotic
from mechbook.verify.compare import equal, vanishes
from mechbook.verify.context import Context, split_named, strip_const
from mechbook.verify.instances import branches, generic_symbols, rational_point
from mechbook.verify.quantities.perturbation import formula_difference
from mechbook.verify.quantities.tensors import branch_names

PROOF_SECONDS = 10.0  # a symbolic proof that a mutant is itself a first integral
TEXT_KEYS = {"part", "cite", "quantity", "note", "origin", "system", "derivation",
             "unsupported", "transcription"}


def _motion(ctx: Context) -> list[sp.Symbol]:
    sys = ctx.system
    if sys is None:
        return []
    dyn = ctx.dyn
    return list(sys.q) + list(sys.qd) + list(dyn.qdd) + [sys.t]


def _kind(text: str) -> str:
    if any(c in text for c in "<>"):
        return "relation"
    pieces = split_single_equals(text)
    if len(pieces) == 2 and pieces[1].strip() not in ("const", "constant"):
        return "equation"
    return "expression"


def _free_of_motion(expr: sp.Expr, ctx: Context) -> bool:
    grads = [sp.diff(expr, x) for x in _motion(ctx) if expr.has(x)]
    return all(vanishes(g, ctx.sampler, symbolic=False).ok for g in grads)


def _proportional(a: sp.Expr, b: sp.Expr, ctx: Context) -> bool:
    """a = c·b with c free of the motion (and nonzero)."""
    xs = [x for x in _motion(ctx) if a.has(x) or b.has(x)]
    return all(vanishes(a * sp.diff(b, x) - b * sp.diff(a, x), ctx.sampler, symbolic=False).ok
               for x in xs)


def _functionally_dependent(a: sp.Expr, b: sp.Expr, ctx: Context) -> bool:
    """a is a function of b (their gradients in the motion variables are parallel)."""
    xs = [x for x in _motion(ctx) if a.has(x) or b.has(x)]
    ga = [sp.diff(a, x) for x in xs]
    gb = [sp.diff(b, x) for x in xs]
    return all(vanishes(ga[i] * gb[j] - ga[j] * gb[i], ctx.sampler, symbolic=False).ok
               for i in range(len(xs)) for j in range(i + 1, len(xs)))


def is_function_of(b: sp.Expr, stated: list[sp.Expr], ctx: Context) -> bool:
    """b is locally a function of the `stated` first integrals: its gradient in the motion
    variables lies in the span of theirs (every (k+1)-minor of the gradients vanishes at
    the sampled states), with more motion variables than integrals (else any b would do).
    Then b is conserved with them, whatever its form (Symon 11-6: |ω|² with wz's exponent
    moved, given wz conserved)."""
    xs = [x for x in _motion(ctx) if b.has(x) or any(a.has(x) for a in stated)]
    k = len(stated)
    if len(xs) <= k:
        return False
    grads = sp.Matrix([[sp.diff(e, x) for x in xs] for e in [b, *stated]])
    return all(vanishes(grads[:, list(cols)].det(method="berkowitz"), ctx.sampler,
                        symbolic=False).ok
               for cols in itertools.combinations(range(len(xs)), k + 1))


def _stated_integrals(ctx: Context, path: tuple, parse) -> list[sp.Expr]:
    """The other first integrals the part states beside the one at `path` (unnamed ones,
    as the book gives them: they passed with it)."""
    if not path or not isinstance(path[-1], int):  # a list of integrals only
        return []
    out = []
    for i, text in enumerate(_siblings(ctx, path)):
        if i == path[-1] or not isinstance(text, str) or "=" in text:
            continue
        name, value = split_named(text)
        if name is None:
            try:
                out.append(parse(value))
            except Exception:  # noqa: BLE001 - one that does not parse: not used
                continue
    return out


def _identifiers(text: str) -> list[str]:
    try:
        tree = ast.parse(str(text).strip(), mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return []
    return [n.id for n in ast.walk(tree) if isinstance(n, ast.Name)]


def _names_in(data) -> list[str]:
    """Every identifier in the expressions of a part's data (any key but its text)."""
    if isinstance(data, dict):
        return [n for k, v in data.items() if k not in TEXT_KEYS for n in _names_in(v)]
    if isinstance(data, list):
        return [n for v in data for n in _names_in(v)]
    if isinstance(data, str):
        text = strip_const(data)
        return _identifiers(text.replace("=", "-", 1) if text.count("=") == 1 else text)
    return []


def _occurrences(ctx: Context, name: str) -> int:
    """How often `name` occurs in a part, counting its uses inside the key's
    abbreviations the part names (an abbreviation is its definition)."""
    abbreviations = ctx.part.key.doc.data.get("abbreviations") or {}

    def count(names: list[str], depth: int) -> int:
        total = 0
        for n in names:
            if n == name:
                total += 1
            elif n in abbreviations and depth < 20:
                total += count(_identifiers(str(abbreviations[n])), depth + 1)
        return total

    return count(_names_in(ctx.part.data), 0)


def _free_symbols(ctx: Context) -> dict[str, sp.Symbol]:
    """The key's answer symbols that are sampled freely (not fixed, not derived)."""
    out = {}
    for name, sym in ctx.part.key.symbols.items():
        if not isinstance(sym, sp.Symbol) or sym in ctx.sampler.fixed or \
                sym in ctx.sampler.derived:
            continue
        out[name] = sym
    return out


def _reparametrized(ctx: Context, old: sp.Expr | None, new: sp.Expr | None,
                    token: str) -> str:
    """A free answer symbol occurring once in the part, rescaled (token) or shifted."""
    free = _free_symbols(ctx)
    if token:
        if token in free and _occurrences(ctx, token) == 1:
            return f"the free answer symbol {token} rescaled (the same family of answers)"
        return ""
    if old is None or new is None:
        return ""
    motion = set(_motion(ctx))
    for name, sym in free.items():
        if not old.has(sym) or _occurrences(ctx, name) != 1:
            continue
        slope = sp.diff(old, sym)
        if slope.has(sym) or slope.free_symbols & motion:
            continue
        if _free_of_motion(new - old, ctx) and not vanishes(slope, ctx.sampler,
                                                            symbolic=False).ok:
            return f"a constant added, absorbed by the free answer symbol {name}"
    return ""


def same_meaning(ctx: Context, path: tuple, old, new, token: str = "") -> str:
    """Why the value `new` at `path` means the same as `old` ('' if it does not, or if that
    cannot be shown). `token`: the name a scaling mutant multiplied ('' otherwise)."""
    declared = ctx.quantity.equivalent
    if callable(declared):
        declared = declared(ctx.part.data)
    if isinstance(new, bool) or not isinstance(new, str):
        return ""
    if ctx.tensor_mode:  # tensors, vectors, bodies: at a random rational instance
        if "direction" in declared and _only_component(ctx, path, parse=False):
            return "the only nonzero component of a direction scaled (its direction is kept)"
        return _tensor_same(ctx, str(old), new)
    q = ctx.quantity
    names = q.names(ctx) if q.names else ctx.names

    def parse(text, **kw):
        return ctx.parse(text, path, names=names, **kw)

    old_text = str(old)
    kind = _kind(old_text)
    if kind == "relation":  # a condition's truth depends on its symbols: never rescaled
        a, b = parse(old_text, relation=True), parse(new, relation=True)
        try:
            got = boundary.compare(b, lambda pt, near: holds(a, pt), ctx.sampler,
                                   ("true", "false"))
        except (ValueError, TypeError):
            return ""  # a relation in variables the parameter sampler does not draw
        return "the same relation (boundaries agree)" if got.ok else ""
    if kind == "equation" and ctx.part.quantity != "conserved":
        a, b = parse(old_text, equation=True), parse(new, equation=True)
        if _proportional(b, a, ctx):
            return "the same equation times a factor"
        return _reparametrized(ctx, None, None, token)
    name, old_value = split_named(old_text)
    new_name, new_value = split_named(new)
    a, b = parse(old_value), parse(new_value)
    if equal(a, b, ctx.sampler, symbolic=False).ok:
        return "the same value"
    why = _reparametrized(ctx, a, b, token)
    if why:
        return why
    if "limit" in ctx.part.data and _asymptotically_equal(ctx, a, b, path):
        return "the same to the order the `limit:` states (they differ beyond it)"
    if "gauge" in declared and _total_derivative(b - a, ctx):
        return "a total time derivative added (the same equations of motion)"
    if "shift" in declared and _free_of_motion(b - a, ctx):
        return "a constant added (the quantity is defined up to one)"
    if "scale" in declared and _proportional(b, a, ctx):
        return "a constant factor (the quantity is defined up to one)"
    if "function" in declared and name is None and new_name is None:
        if _functionally_dependent(b, a, ctx):
            return "a function of the same conserved quantity"
        stated = [a, *_stated_integrals(ctx, path, parse)]
        if len(stated) > 1 and is_function_of(b, stated, ctx):
            return "a function of the conserved quantities the part states"
        if _proved_first_integral(ctx, b):
            return "another first integral (its time derivative proved zero)"
    if "direction" in declared and _only_component(ctx, path):
        return "the only nonzero component of a mode shape scaled (its direction is kept)"
    if "open" in declared:  # the mutant passed: it, too, was shown to be what is claimed
        return "a claim that holds on an open set (a map that is not canonical): a nearby " \
            "map was shown not to be one either"
    return ""


def _tensor_same(ctx: Context, old: str, new: str) -> str:
    """A tensor part's value or equation, old and new, at random rational instances of its
    generic objects (exact arithmetic): the same value, or the same equation times a
    constant factor."""

    def flat(x) -> list:
        return list(x) if isinstance(x, sp.MatrixBase) else [x]

    try:
        for branch in branches(ctx.part.data.get("for_all") or {})[:2]:
            for _ in range(2):
                table = branch_names(ctx, branch, rational_point(ctx.sampler,
                                                           generic_symbols(branch)))
                if old.count("=") == 1:
                    a = [x - y for x, y in zip(*map(flat, parse_tensor_equation(
                        old, table, ctx.bodies)), strict=True)]
                    b = [x - y for x, y in zip(*map(flat, parse_tensor_equation(
                        new, table, ctx.bodies)), strict=True)]
                    if not _proportional_lists(a, b):
                        return ""
                else:
                    a = flat(parse_tensor(old, table, ctx.bodies))
                    b = flat(parse_tensor(new, table, ctx.bodies))
                    if any(sp.nsimplify(x - y) != 0 for x, y in zip(a, b, strict=True)):
                        return ""
    except Exception:  # noqa: BLE001 - not shown to mean the same
        return ""
    return ("the same value (or equation up to a factor) at random rational instances of "
            "its generic objects")


def _proportional_lists(a: list, b: list) -> bool:
    """b = c·a for one constant c (both exact numbers at an instance; all zero counts)."""
    a = [sp.nsimplify(x) for x in a]
    b = [sp.nsimplify(y) for y in b]
    pivot = next((i for i, x in enumerate(a) if x != 0), None)
    if pivot is None:
        return all(y == 0 for y in b)
    c = b[pivot] / a[pivot]
    if not within_exact_reach(c, *a, *b):
        return False
    return c != 0 and all(sp.simplify(y - c * x) == 0 for x, y in zip(a, b, strict=True))


def _proved_first_integral(
ctx: Context, e: sp.Expr) -> bool:
    """SymPy proves d/dt e = 0 along the motion (accelerations from the equations)."""
    dyn = ctx.dyn
    acc = dict(zip(dyn.qdd, dyn.accelerations, strict=True))
    if not within_exact_reach(e):  # gmp would abort the process, not raise
        return False
    try:
        with time_limit(PROOF_SECONDS):
            return sp.simplify(ctx.system.dt(e).subs(acc)) == 0
    except Timeout:
        return False
    except Exception:  # noqa: BLE001 - SymPy can fail on odd input: then not shown
        return False


def _total_derivative(d: sp.Expr, ctx: Context) -> bool:
    """d/dt ∂D/∂q̇ − ∂D/∂q vanishes identically for every coordinate: D is a total
    derivative (a null Lagrangian), which changes no equation of motion."""
    sys = ctx.system
    if sys is None:
        return False
    return all(vanishes(sys.dt(sp.diff(d, v)) - sp.diff(d, q), ctx.sampler,
                        symbolic=False).ok for q, v in zip(sys.q, sys.qd, strict=True))


def _siblings(ctx: Context, path: tuple) -> list:
    """The values beside the leaf at `path` (a mode shape's other entries), or []."""
    parent = ctx.part.data
    for p in path[:-1]:
        parent = parent[p]
    if isinstance(parent, dict):
        return list(parent.values())
    if isinstance(parent, list):
        return list(parent)
    return []


def _asymptotically_equal(ctx: Context, a: sp.Expr, b: sp.Expr, path: tuple) -> bool:
    """Do a and b agree toward the part's limit to its stated order (their difference falls
    as fast as the book's error must)? Then both are equally right. A leaf of a vector (a
    mode shape) is measured against the whole vector, as the check measures its angle; a
    formula in the text's notation (`perturbation`) with its tables filled in."""

    if ctx.part.quantity == "perturbation":
        return _walked_equal(ctx, formula_difference(ctx, a, b))

    entries = [e for e in _siblings(ctx, path) if isinstance(e, str | int | float)]
    parsed = []
    if len(entries) > 1:
        try:
            parsed = [ctx.parse(str(e), path[:-1]) for e in entries]
        except Exception:  # noqa: BLE001 - not a vector of expressions
            parsed = []

    def error(pt) -> float:
        """|a − b| against the size of a (or of the vector it belongs to), at 50 digits:
        a difference beyond the claimed order is far below double precision there."""
        import mpmath

        with mpmath.workdps(50):
            try:
                va, vb = evaluate_mp(a, pt, 50), evaluate_mp(b, pt, 50)
                size = abs(va)
                if parsed:
                    size = mpmath.sqrt(mpmath.fsum(abs(evaluate_mp(e, pt, 50)) ** 2
                                                   for e in parsed))
            except (NotNumeric, ZeroDivisionError, ValueError, TypeError):
                return float("inf")
            return float(abs(va - vb) / max(size, mpmath.mpf(10) ** -300))

    return _walked_equal(ctx, error)


def _walked_equal(ctx: Context, error) -> bool:
    """The walk toward the limit passes on `error` (a walk that cannot resolve the claimed
    order, unsupported, shows nothing equal)."""
    try:
        return asymptotic(ctx, error, floor=1e-40).ok
    except UnsupportedError:
        return False


def _only_component(ctx: Context, path: tuple, parse: bool = True) -> bool:
    """Is the leaf at `path` the only nonzero entry of the mapping or list that holds it?
    (`parse` False: only literal zeros count as zero, for parts whose entries need the
    tensor parser.)"""
    parent = ctx.part.data
    for p in path[:-1]:
        parent = parent[p]
    items = parent.items() if isinstance(parent, dict) else \
        enumerate(parent) if isinstance(parent, list) else None
    if items is None:
        return False
    sub = path[:-1]
    for k, v in items:
        if k == path[-1]:
            continue
        if str(v).strip() in ("0", "0.0"):
            continue
        if not parse:
            return False
        try:
            e = ctx.parse(v, sub + (k,))
        except Exception:  # noqa: BLE001 - an entry the scalar parser cannot read
            return False
        if not vanishes(e, ctx.sampler, symbolic=False).ok:
            return False
    return True
