"""The checker: the book's answers pass, and wrong answers do not.

The mutation test takes every answer file in the tree (globbed at collection time, so new
problems are covered without editing this file), and for every part the checker passes (or
reports as an erratum) it derives wrong versions of the book's value and requires the checker
to fail each one. A mutant is skipped only when it is provably the same statement (SymPy
proves the two texts mean the same), never because the checker happened to accept it.
"""

from __future__ import annotations

import copy
import math
import os
import random
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import sympy as sp
from mutation_keys import per_key
from ruamel.yaml import YAML

from mechbook.core.timeout import Timeout, time_limit
from mechbook.engine.analysis import Analysis
from mechbook.errors import UnsupportedError
from mechbook.model.catalog import problem_path
from mechbook.model.problem import load_problem
from mechbook.model.tensorexpr import kind
from mechbook.verify.answers import AnswerKey, Part, load_answers
from mechbook.verify.checker import check_problem
from mechbook.verify.context import Context, split_named, strip_const

ROOT = Path(__file__).resolve().parents[1]
ANSWER_FILES = sorted((ROOT / "answers").glob("*/*.yaml"))
MAX_MUTANTS_PER_SLOT = 5
SIMPLIFY_SECONDS = 20  # proving a mutant equivalent; unproved mutants are checked
VERBOSE = bool(os.environ.get("MECHBOOK_MUTANTS_VERBOSE"))


def plain(data):
    """Plain Python data (ruamel's round-trip scalars are subclasses of int/float)."""
    if isinstance(data, dict):
        return {str(k): plain(v) for k, v in data.items()}
    if isinstance(data, list):
        return [plain(v) for v in data]
    if isinstance(data, bool) or data is None:
        return data
    if isinstance(data, int):
        return int(data)
    if isinstance(data, float):
        return float(data)
    return str(data)


def dump(data: dict, path: Path) -> Path:
    """Write plain data, keeping the order of keys (an abbreviation may use an earlier one)."""
    yaml = YAML(typ="rt")
    yaml.default_flow_style = False
    with open(path, "w", encoding="utf-8") as fh:
        yaml.dump(plain(data), fh)
    return path


def load_real(answer_file: Path) -> tuple[AnswerKey, Analysis]:
    key = load_answers(answer_file)
    problem = load_problem(problem_path(key.problem_id, ROOT))
    return key, Analysis(problem)


# ---- (a) the worked example passes ----------------------------------------------------------
def test_lim_2031_passes():
    key, analysis = load_real(ROOT / "answers" / "lim" / "2031.yaml")
    outcomes = check_problem(analysis, key)
    assert outcomes, "no parts"
    bad = [(o.part, o.status, o.detail) for o in outcomes if o.status != "pass"]
    assert not bad
    assert {o.part for o in outcomes} >= {"a-lagrangian", "a-eom", "b", "c", "c-frequency"}


def test_answer_key_for_another_problem_is_rejected(tmp_path):
    key, analysis = load_real(ROOT / "answers" / "lim" / "2031.yaml")
    data = copy.deepcopy(key.doc.data)
    data["problem"] = "lim-9999"
    other = load_answers(dump(data, tmp_path / "key.yaml"))
    with pytest.raises(Exception, match="lim-9999"):
        check_problem(analysis, other)


# ---- text surgery ---------------------------------------------------------------------------
OPERAND_END = re.compile(r"[A-Za-z0-9_.)\]]")


def _binary_ops(s: str) -> list[int]:
    """Positions of top-level binary + and - in an expression text."""
    out, depth = [], 0
    for i, ch in enumerate(s):
        if ch in "([":
            depth += 1
        elif ch in ")]":
            depth -= 1
        elif ch in "+-" and depth == 0:
            before = s[:i].rstrip()
            if not before or not OPERAND_END.match(before[-1]):
                continue  # unary
            if before[-1] in "eE" and len(before) >= 2 and before[-2].isdigit() \
                    and re.search(r"(^|[^A-Za-z_])[0-9.]+[eE]$", before):
                continue  # exponent of a float literal such as 1e-3
            out.append(i)
    return out


def flip_first_sign(s: str) -> str | None:
    ops = _binary_ops(s)
    if not ops:
        return None
    i = ops[0]
    return s[:i] + ("-" if s[i] == "+" else "+") + s[i + 1:]


def double_first_term(s: str) -> str | None:
    ops = _binary_ops(s)
    if not ops:
        return None
    return f"2*({s[:ops[0]].strip()}) {s[ops[0]:]}"


def split_equation(s: str) -> tuple[str, str] | None:
    idx = [i for i, ch in enumerate(s) if ch == "="
           and (i == 0 or s[i - 1] not in "<>=!") and (i + 1 >= len(s) or s[i + 1] != "=")]
    if len(idx) != 1:
        return None
    return s[:idx[0]].strip(), s[idx[0] + 1:].strip()


def swap_names(s: str, names: list[str]) -> Iterator[tuple[str, str]]:
    present = [n for n in names if re.search(rf"\b{re.escape(n)}\b", s)]
    pairs = [(a, b) for i, a in enumerate(present) for b in present[i + 1:]]
    for a, b in pairs[:2]:
        pattern = re.compile(rf"\b({re.escape(a)}|{re.escape(b)})\b")
        yield f"swap {a}<->{b}", pattern.sub(lambda m, a=a, b=b: b if m.group() == a else a, s)


def flip_relation(s: str) -> str | None:
    m = re.search(r"<=|>=|<|>", s)
    if not m:
        return None
    opposite = {"<=": ">=", ">=": "<=", "<": ">", ">": "<"}[m.group()]
    return s[:m.start()] + opposite + s[m.end():]


# ---- where the book's value can be changed, and how -----------------------------------------
@dataclass
class Slot:
    path: tuple  # inside the part's data
    kind: str


def get(data, path):
    for p in path:
        data = data[p]
    return data


def put(data, path, value):
    get(data, path[:-1])[path[-1]] = value


FIELD_QUANTITIES = ("field_equation", "field_frequencies", "field_mode", "field_current")


def field_slots(q: str, val, root: tuple) -> Iterator[Slot]:
    """A field quantity's values: its PDE, each frequency, a mode's ω and φ, a current's ρ
    and each flux component."""
    if q == "field_equation":
        yield Slot(root, "equation")
    elif q == "field_frequencies":
        for i in range(len(val)):
            yield Slot(root + (i,), "value")
    elif q == "field_mode":
        yield Slot(root + ("frequency",), "value")
        yield Slot(root + ("shape",), "shape")
    else:
        yield Slot(root + ("density",), "value")
        for i in range(len(val["flux"])):
            yield Slot(root + ("flux", i), "flux")


def _field_same(ctx: Context, slot: Slot, old, new) -> bool:
    """A mode's shape times a constant, a flux plus a constant: the same mode, the same
    conservation law (∇·j is blind to a constant)."""
    names = ctx.quantity.names(ctx)
    try:
        a, b = ctx.parse(old, slot.path, names=names), ctx.parse(new, slot.path, names=names)
    except Exception:  # noqa: BLE001 - a mutant that does not parse is not the same
        return False
    field_names = {names[k] for k in names if k not in ctx.names}
    if slot.kind == "shape":
        return a != 0 and not (sp.simplify(b / a).free_symbols & field_names)
    return not (sp.simplify(b - a).free_symbols & field_names)


def slots(part: Part, ctx: Context, analysis: Analysis) -> Iterator[Slot]:
    q = part.quantity
    root = ("erratum", "corrected") if "erratum" in part.data else ("book",)
    val = get(part.data, root)
    if q in FUNCTIONAL:
        yield from functional_slots(q, val, root)
    elif q in FIELD_QUANTITIES:  # a field's: plain expressions, without a system
        yield from field_slots(q, val, root)
    elif ctx.tensor_mode:
        yield from tensor_slots(part, val, root)
    elif q == "lagrangian":
        yield Slot(root, "lagrangian")
    elif q == "eom":
        for i in range(len(val)):
            yield Slot(root + (i,), "equation")
    elif q == "adiabatic_invariant":  # a law "f = const": any function of f is the same law
        yield Slot(root, "conserved")
    elif q == "conserved":
        if isinstance(val, list):
            for i in range(len(val)):
                yield Slot(root + (i,), "conserved")
        else:
            yield Slot(root, "conserved")
    elif q == "equilibrium":
        if "at" in val:
            conds = analysis.equilibria(part.system).conditions
            live = set().union(*(c.free_symbols for c in conds))
            for k in val["at"]:
                if ctx.system.q[ctx.system.coord_names.index(k)] in live:
                    yield Slot(root + ("at", k), "point")
        for i in range(len(val.get("where", []))):
            yield Slot(root + ("where", i), "equation")
        if "stable" in part.data:
            yield Slot(("stable",), "flag")
    elif q == "stability_condition":
        yield Slot(root, "relation")
    elif q == "frequencies":
        for i in range(len(val)):
            yield Slot(root + (i,), "value")
    elif q == "period":
        yield Slot(root, "value")
    elif q == "normal_modes":
        for i, mode in enumerate(val):
            yield Slot(root + (i, "frequency"), "value")
            if len(mode.get("shape", {})) > 1 and not degenerate(ctx, mode["frequency"]):
                for c in mode["shape"]:
                    yield Slot(root + (i, "shape", c), "component")
    elif q == "normal_coordinates":
        for i, item in enumerate(val):
            if not degenerate(ctx, item.get("frequency")):
                yield Slot(root + (i, "coordinate"), "form")
            if "frequency" in item:
                yield Slot(root + (i, "frequency"), "value")
    elif q == "steady_state":
        for k in val:
            yield Slot(root + (k,), "function")
    elif q == "motion":
        kind = "function" if "initial" in part.data else "general_function"
        for k in val:
            yield Slot(root + (k,), kind)
    elif q == "mode_count":
        if isinstance(val, dict):  # {configuration: k, velocity: d}: each count apart
            for k in val:
                yield Slot(root + (k,), "count")
        else:
            yield Slot(root, "count")
    elif q == "canonical":
        if val.get("canonical", True) is False:  # an open claim: only the flag can be wrong
            yield Slot(root + ("canonical",), "flag")
            return
        for k in val["transformation"]:
            yield Slot(root + ("transformation", k), "value")
        for k in val.get("generating") or {}:
            yield Slot(root + ("generating", k), "generating")
        if "hamiltonian" in val:
            yield Slot(root + ("hamiltonian",), "value")
    elif q == "mode_node":
        for k in val:
            yield Slot(root + (k,), "value")
    elif q == "effective_potential":
        yield Slot(root, "potential")
    elif q == "expression":
        of = part.data.get("of")
        if of == "momenta":
            for k in val:
                yield Slot(root + (k,), "value")
        elif of in ("potential", "quadratic_potential"):
            yield Slot(root, "potential")
        else:
            yield Slot(root, "value")
    elif q == "constraint_force":
        yield Slot(root, "value")
    elif q == "phase_area":
        yield Slot(root, "value")
    elif q == "phase_region":
        for i in range(len(val)):
            yield Slot(root + (i,), "inequality")
    elif q == "simultaneous_diagonalization":
        yield Slot(root, "flag")
    elif q == "steady_motion":
        for group in ("at", "rates"):
            for k in val.get(group) or {}:
                yield Slot(root + (group, k), "steady")
    elif q == "stability":
        yield Slot(root, "relation" if re.search(r"[<>]", str(val)) else "verdict")
    elif q == "capture":
        yield Slot(root, "relation" if re.search(r"[<>]", str(val)) else "capture_verdict")
    elif q == "equilibrium_count":
        yield Slot(root, "count")
        if "stable" in part.data:
            yield Slot(("stable",), "flag")
    elif q == "characteristic_polynomial":
        yield Slot(root, "polynomial")
    elif q == "exponents":
        for i in range(len(val)):
            yield Slot(root + (i,), "exponent")
    elif q == "complex_modes":
        for i, mode in enumerate(val):
            yield Slot(root + (i, "exponent"), "exponent")
            if len(mode.get("shape", {})) > 1:
                for c in mode["shape"]:
                    yield Slot(root + (i, "shape", c), "component")
    elif q == "lyapunov":
        yield Slot(root, "exponent_sign" if val in ("positive", "zero", "negative") else "value")
    elif q == "poincare":  # the orbit's point and multipliers; its stability a flag
        yield from walk({k: v for k, v in val.items() if k != "stable"}, root)
        if "stable" in val:
            yield Slot(root + ("stable",), "flag")
    else:  # a quantity this test does not know yet: walk the value's structure
        yield from walk(val, root)


FUNCTIONAL = ("euler_lagrange", "functional_integral", "extremal", "functional_value",
              "minimum")


def functional_slots(q: str, val, root: tuple) -> Iterator[Slot]:
    """A functional's parts: its equations, a first integral, the curve's expressions (not
    its parameter's name), a value, a verdict."""
    if q == "euler_lagrange":
        for i in range(len(val)):
            yield Slot(root + (i,), "fn_equation")
    elif q == "functional_integral":
        yield Slot(root, "fn_integral")
    elif q == "extremal":
        for k, v in val.items():
            if k == "multipliers":
                for m in v:
                    yield Slot(root + (k, m), "fn_curve")
            elif k != "parameter":
                yield Slot(root + (k,), "fn_curve")
    elif q == "functional_value":
        yield Slot(root, "fn_value")
    else:
        yield Slot(root, "fn_verdict")


def functional_mutants(slot: Slot, value, names: list[str]) -> Iterator[tuple[str, object]]:
    """Wrong versions of a functional part's value, none of which can mean the same."""
    s = str(value)
    if slot.kind == "fn_equation":
        lhs, rhs = split_equation(s)
        flipped = flip_first_sign(lhs)
        if flipped:
            yield "flip sign of a term", f"{flipped} = {rhs}"
        doubled = double_first_term(lhs)
        if doubled:
            yield "double a term", f"{doubled} = {rhs}"
        yield "add one", f"{lhs} + 1 = {rhs}"
    elif slot.kind == "fn_integral":  # a multiple would be a function of the integral
        body = strip_const(s)
        yield "add x", f"({body}) + x"
        yield "times (1 + x)", f"({body})*(1 + x)"
    elif slot.kind == "fn_curve":
        yield "double", f"2*({s})"
        yield "add one", f"({s}) + 1"
    elif slot.kind == "fn_value":
        yield from expression_mutants(s, names)
    else:
        yield "the other verdict", "not a minimum" if s == "minimum" else "minimum"


def walk(val, path: tuple) -> Iterator[Slot]:
    """Every leaf of a book value: strings (expression, equation or condition) and numbers."""
    if isinstance(val, dict):
        for k, v in val.items():
            yield from walk(v, path + (k,))
    elif isinstance(val, list):
        for i, v in enumerate(val):
            yield from walk(v, path + (i,))
    elif isinstance(val, bool):
        return
    elif isinstance(val, int) and path[-1] in ("book", "corrected"):
        yield Slot(path, "count")
    elif isinstance(val, str) and re.search(r"[<>]", val):
        yield Slot(path, "relation")
    elif isinstance(val, str) and split_equation(val) is not None:
        yield Slot(path, "equation")
    elif isinstance(val, (str, int, float)):
        yield Slot(path, "value")


def degenerate(ctx: Context, freq) -> bool:
    """Is `freq` a repeated engine frequency at the default parameters (then any vector of
    its eigenspace is a correct mode, and changing one component may not be wrong)?"""
    values = ctx.sampler.default()
    engine = ctx.linear().numeric_frequencies(values)
    if freq is None:  # no frequency given: is any engine frequency repeated?
        return any(sum(abs(e - w) <= 1e-6 * max(1.0, abs(w)) for e in engine) > 1
                   for w in engine)
    w = complex(sp.N(ctx.parse(freq, ("frequency",)).subs(values))).real
    return sum(abs(e - w) <= 1e-6 * max(1.0, abs(w)) for e in engine) > 1


def expression_mutants(s: str, names: list[str]) -> Iterator[tuple[str, str]]:
    yield "negate", f"-({s})"
    yield "double", f"2*({s})"
    flipped = flip_first_sign(s)
    if flipped:
        yield "flip sign of a term", flipped
    doubled = double_first_term(s)
    if doubled:
        yield "double a term", doubled
    yield from swap_names(s, names)
    yield "add one", f"({s}) + 1"


def equation_mutants(s: str, names: list[str], coordinate: str) -> Iterator[tuple[str, str]]:
    sides = split_equation(s)
    if sides is None:
        lhs, rhs = s, "0"
    else:
        lhs, rhs = sides
    for side, build in ((lhs, lambda x: f"{x} = {rhs}"), (rhs, lambda x: f"{lhs} = {x}")):
        flipped = flip_first_sign(side)
        if flipped:
            yield "flip sign of a term", build(flipped)
            break
    for side, build in ((lhs, lambda x: f"{x} = {rhs}"), (rhs, lambda x: f"{lhs} = {x}")):
        doubled = double_first_term(side)
        if doubled:
            yield "double a term", build(doubled)
            break
    if rhs.strip() != "0":
        yield "double right side", f"{lhs} = 2*({rhs})"
        yield "negate right side", f"{lhs} = -({rhs})"
    yield "add a term", f"{lhs} + {coordinate} = {rhs}"
    yield from swap_names(s, names)


def mutants(slot: Slot, value, names: list[str], coordinate: str) -> Iterator[tuple[str, object]]:
    if slot.kind == "count":
        yield "plus one", value + 1
        yield "minus one", value - 1
        return
    if slot.kind == "flag":
        yield "flip", not value
        return
    if slot.kind == "verdict":  # stable / unstable / marginal
        for other in ("stable", "unstable", "marginal"):
            if other != value:
                yield f"say {other}", other
        return
    if slot.kind == "exponent_sign":  # a Lyapunov exponent's claim: positive / zero / negative
        for other in ("positive", "zero", "negative"):
            if other != value:
                yield f"say {other}", other
        return
    if slot.kind == "capture_verdict":  # captured / scattered
        yield "the other verdict", "scattered" if value == "captured" else "captured"
        return
    s = str(value)
    if slot.kind in ("lagrangian", "value", "potential", "generating", "shape", "flux"):
        yield from expression_mutants(s, names)
    elif slot.kind == "steady":  # -rate (time reversal) and mirrored angles are steady too
        yield "double", f"2*({s})"
        yield "add a third", f"({s}) + 1/3"
        yield from swap_names(s, names)
    elif slot.kind == "point":
        yield "negate", f"-({s})"
        yield "double", f"2*({s})"
        yield "shift", f"({s}) + 1/3"
    elif slot.kind == "component":
        yield "double", f"2*({s})"
        yield "add one", f"({s}) + 1"
    elif slot.kind == "equation":
        yield from equation_mutants(s, names, coordinate)
    elif slot.kind == "conserved":  # a named one (`p_psi = ...`): its value is mutated
        name, body = split_named(s)
        head = f"{name} = " if name is not None else ""
        body = str(body).strip()
        yield "times (2 + coordinate)", f"{head}({body})*(2 + {coordinate})"
        doubled = double_first_term(body)
        if doubled:
            yield "double a term", head + doubled
        for label, swapped in swap_names(body, names):
            yield label, head + swapped
    elif slot.kind == "relation":
        flipped = flip_relation(s)
        if flipped:
            yield "flip comparison", flipped
        yield from swap_names(s, names)
    elif slot.kind == "inequality":  # one condition of a region: its boundary moves
        flipped = flip_relation(s)
        if flipped:
            yield "flip comparison", flipped
        flipped = flip_first_sign(s)
        if flipped:
            yield "flip sign of a term", flipped
        yield from swap_names(s, names)
    elif slot.kind == "form":
        doubled = double_first_term(s)
        if doubled:
            yield "double a term", doubled
        yield "add a coordinate", f"{s} + {coordinate}"
        yield from swap_names(s, names)
    elif slot.kind == "function":
        yield "double", f"2*({s})"
        yield "negate", f"-({s})"
        yield "add t**2", f"({s}) + t**2"
        yield from swap_names(s, names)
    elif slot.kind == "general_function":  # a general solution: any multiple is one too
        yield "add t**2", f"({s}) + t**2"
    elif slot.kind == "polynomial":  # a multiple has the same roots: change the roots
        flipped = flip_first_sign(s)
        if flipped:
            yield "flip sign of a term", flipped
        doubled = double_first_term(s)
        if doubled:
            yield "double a term", doubled
        yield "add one", f"({s}) + 1"
        yield from swap_names(s, names)
    elif slot.kind == "exponent":  # -p and conj(p) may be exponents too: scale instead
        yield "double", f"2*({s})"
        doubled = double_first_term(s)
        if doubled:
            yield "double a term", doubled
        yield "add a third", f"({s}) + 1/3"
        yield from swap_names(s, names)
    else:  # pragma: no cover
        raise AssertionError(slot.kind)


# ---- when is a mutant provably the same statement? ------------------------------------------
def _numerically_nonzero(expr) -> bool:
    """True when expr is certainly not identically zero: it evaluates (30 digits) to a
    clearly nonzero number at a random point. Cheap, and it settles most mutants at once."""
    symbols = sorted(expr.free_symbols, key=str)
    rng = random.Random(1234)
    for _ in range(3):
        point = {s: sp.Float(rng.uniform(0.3, 1.7), 30) for s in symbols}
        try:
            v = complex(sp.N(expr.subs(point), 30))
        except (TypeError, ValueError, ZeroDivisionError):
            continue
        if math.isfinite(abs(v)) and abs(v) > 1e-15:
            return True
    return False


def _zero(expr) -> bool:
    """expr simplifies to zero (proved by SymPy within a time limit; unproved means no)."""
    if _numerically_nonzero(expr):
        return False
    try:
        with time_limit(SIMPLIFY_SECONDS):
            return sp.simplify(expr) == 0
    except (Timeout, Exception):
        return False


def _free_of(expr, symbols) -> bool:
    """expr is provably a nonzero constant as far as `symbols` go."""
    if any(_numerically_nonzero(sp.diff(expr, s)) for s in symbols & expr.free_symbols):
        return False
    try:
        with time_limit(SIMPLIFY_SECONDS):
            expr = sp.simplify(expr)
    except (Timeout, Exception):
        return False
    return expr.is_finite is not False and expr != 0 and not (expr.free_symbols & symbols)


def same_meaning(ctx: Context, slot: Slot, part_data: dict, old, new) -> bool:
    if str(old) == str(new):
        return True
    if slot.kind in ("count", "flag", "verdict", "exponent_sign", "capture_verdict"):
        return False
    if slot.kind == "relation":  # the same condition once parsed (factors reordered), or
        # the same up to moving terms (e.g. a symmetric one with names swapped)
        try:
            a = ctx.parse(old, slot.path, relation=True)
            b = ctx.parse(new, slot.path, relation=True)
        except Exception:  # noqa: BLE001 - a mutant that does not parse is not the same
            return False
        if a == b:
            return True
        return (isinstance(a, sp.core.relational.Relational) and type(a) is type(b)
                and _zero((a.lhs - a.rhs) - (b.lhs - b.rhs)))
    if slot.kind == "steady":  # another true steady motion (a symmetry: -rate, -angle, ...)
        return _also_steady(ctx, slot, part_data, new)
    if slot.kind == "conserved":
        sys = ctx.system
        motion = set(sys.q + sys.qd + sys.qdd) | {sys.t}
        name, old_value = split_named(str(old))
        new_name, new_value = split_named(str(new))
        a, b = ctx.parse(old_value, slot.path), ctx.parse(new_value, slot.path)
        if name is not None:  # a named quantity: only its own value (the energy up to a
            # constant) means the same
            return name == new_name and (_zero(a - b) or (
                name in ("E", "h", "energy", "jacobi") and _free_of(b - a, motion)))
        return _free_of(b - a, motion) or _zero(a - b) or (a != 0 and _free_of(b / a, motion))
    extra = ctx.quantity.names
    if slot.kind == "generating":  # a generating function is defined up to a constant
        names = extra(ctx)
        d = ctx.parse(new, slot.path, names=names) - ctx.parse(old, slot.path, names=names)
        return d.free_symbols <= set(ctx.sampler.base)
    if extra is not None:  # the quantity's own names (a polynomial's variable, W0(j), ...)
        names = extra(ctx)
        equation = slot.kind == "equation"  # a field's PDE: the same times a constant
        a = ctx.parse(old, slot.path, names=names, equation=equation)
        b = ctx.parse(new, slot.path, names=names, equation=equation)
        if equation and a != 0:
            own = {names[k] for k in names if k not in ctx.names}
            return not (sp.simplify(b / a).free_symbols & own)
        return _zero(b - a)
    sys = ctx.system
    motion = set(sys.q + sys.qd + sys.qdd) | {sys.t}
    sub = slot.path
    if slot.kind == "inequality":  # the same condition once parsed (e.g. m*g and g*m)
        return ctx.parse(old, sub, relation=True) == ctx.parse(new, sub, relation=True)
    if slot.kind == "equation":
        a = ctx.parse(old, sub, equation=True)
        b = ctx.parse(new, sub, equation=True)
        return _zero(a - b) or (a != 0 and _free_of(b / a, motion))
    if slot.kind == "form":

        a, b = ctx.parse(old, sub), ctx.parse(new, sub)
        return a != 0 and _free_of(b / a, motion)
    if slot.kind == "component":
        mode_path, comp = slot.path[:-1], slot.path[-1]
        shape = get(part_data, mode_path)
        names = sys.coord_names
        u = [ctx.parse(shape.get(c, 0), sub) for c in names]
        v = [ctx.parse(new if c == comp else shape.get(c, 0), sub) for c in names]
        return all(_zero(u[i] * v[j] - u[j] * v[i])
                   for i in range(len(u)) for j in range(i + 1, len(u)))
    a, b = ctx.parse(old, sub), ctx.parse(new, sub)
    if slot.kind == "lagrangian":
        d = b - a
        return all(_zero(sys.dt(sp.diff(d, qd)) - sp.diff(d, q))
                   for q, qd in zip(sys.q, sys.qd, strict=True))
    if slot.kind == "potential":
        return all(_zero(sp.diff(b - a, q)) for q in sys.q)
    if ctx.quantity.name == "poincare" and "at" in slot.path and \
            slot.path[-1] in sys.coord_names:  # an orbit's angle: the same modulo 2π
        turns = (b - a) / (2 * sp.pi)
        return turns.is_integer is True or _zero(b - a)
    return _zero(b - a)


def _also_steady(ctx: Context, slot: Slot, part_data: dict, new) -> bool:
    """The mutated uniform motion provably solves the equations too (SymPy simplifies every
    residual to zero): a symmetric copy of the book's steady motion, not a wrong one."""
    from mechbook.engine.steady import steady_residuals

    book = copy.deepcopy(get(part_data, slot.path[:-2]))
    book[slot.path[-2]][slot.path[-1]] = new
    sys = ctx.system

    def coords(group):
        return {sys.q[sys.coord_names.index(k)]: ctx.parse(v, slot.path)
                for k, v in (book.get(group) or {}).items()}

    residuals = steady_residuals(ctx.dyn, coords("rates"), coords("at"))
    return all(_zero(r) for r in residuals)


# ---- tensor and body quantities (mechbook/verify/quantities/tensors.py) ----------------------
def tensor_slots(part: Part, val, root: tuple) -> Iterator[Slot]:
    """Values (components, eigenvalues, a solution), principal axes (value and direction)
    and statements (identities, an ellipsoid's equation) of a tensor part."""
    q = part.quantity
    if q in ("identity", "inertia_ellipsoid"):
        for i, _ in enumerate(val if isinstance(val, list) else [val]):
            yield Slot(root + ((i,) if isinstance(val, list) else ()), "tequation")
    elif q == "principal_axes":
        for i, entry in enumerate(val):
            yield Slot(root + (i, "value"), "tvalue")
            key = "axis" if "axis" in entry else "plane"
            direction = entry[key]
            if isinstance(direction, list):
                for j in range(len(direction)):
                    yield Slot(root + (i, key, j), "tdirection")
            else:
                yield Slot(root + (i, key), "tdirection")
    else:  # components, eigenvalues, solves: every leaf of the value
        for slot in walk(val, root):
            yield Slot(slot.path, "tvalue")


def _tensor_names(ctx: Context) -> dict:
    """The part's names at one random rational instance (numbers: building a statement
    from the generic objects can take minutes), cached on the context."""
    if not hasattr(ctx, "_mutation_names"):
        from mechbook.verify.instances import branches, generic_symbols, rational_point
        from mechbook.verify.quantities.tensors import branch_names

        branch = branches(ctx.part.data.get("for_all") or {})[0]
        point = rational_point(ctx.sampler, generic_symbols(branch))
        ctx._mutation_names = branch_names(ctx, branch, point)
    return ctx._mutation_names


def _tparse(ctx: Context, text, names: dict):
    from mechbook.model.tensorexpr import parse_tensor

    return parse_tensor(text, names, ctx.bodies)


def _scalar_names(ctx: Context, names: list[str]) -> list[str]:
    table = _tensor_names(ctx)
    return [n for n in names if n in table and not isinstance(table[n], sp.MatrixBase)]


def tensor_mutants(ctx: Context, slot: Slot, value, names: list[str]) \
        -> Iterator[tuple[str, object]]:
    """Wrong versions of a tensor part's value, of the right kind (a scalar stays a
    scalar, a tensor a tensor), so that a mutant is a wrong statement, never a malformed
    one."""
    table = _tensor_names(ctx)
    scalars = _scalar_names(ctx, names)
    if slot.kind == "tequation":
        from mechbook.model.tensorexpr import parse_tensor_equation

        sides = split_equation(str(value))
        lhs, rhs = sides
        left, _ = parse_tensor_equation(str(value), _with_xyz(ctx, table), ctx.bodies)
        zero = {"scalar": "1", "vector": "[1, 2, 3]", "tensor": "unit()"}[kind(left)]
        for side, build in ((lhs, lambda x: f"{x} = {rhs}"), (rhs, lambda x: f"{lhs} = {x}")):
            flipped = flip_first_sign(side)
            if flipped:
                yield "flip sign of a term", build(flipped)
                break
        for side, build in ((lhs, lambda x: f"{x} = {rhs}"), (rhs, lambda x: f"{lhs} = {x}")):
            doubled = double_first_term(side)
            if doubled:
                yield "double a term", build(doubled)
                break
        yield "double right side", f"{lhs} = 2*({rhs})"
        yield "add to the left side", f"{lhs} + {zero} = {rhs}"
        yield from swap_names(str(value), scalars)
        return
    old = _tparse(ctx, value, _with_xyz(ctx, table))
    what = kind(old)
    s = str(value)
    if slot.kind == "tdirection":  # a component of an axis, or a whole axis
        if what == "scalar":
            yield "double", f"2*({s})"
            yield "add one", f"({s}) + 1"
        else:
            yield "add a vector", f"({s}) + [1, 2, 3]"
        return
    if what == "scalar":
        yield from expression_mutants(s, scalars)
    elif what == "vector":
        yield "negate", f"-({s})"
        yield "add a vector", f"({s}) + [1, 2, 3]"
    else:
        yield "negate", f"-({s})"
        yield "double", f"2*({s})"
        yield "add the unit tensor", f"({s}) + unit()"


def _with_xyz(ctx: Context, table: dict) -> dict:
    """An ellipsoid's equation also names x, y, z."""
    if ctx.part.quantity != "inertia_ellipsoid":
        return table
    out = dict(table)
    out.update({c: sp.Symbol(c, real=True) for c in "xyz" if c not in out})
    return out


def _flat(value) -> list:
    return list(value) if isinstance(value, sp.MatrixBase) else [value]


def tensor_same_meaning(ctx: Context, slot: Slot, old, new) -> bool:
    """The mutant says the same thing: the same value; the same direction (an axis given
    up to scale); the same equation up to a constant factor."""
    if str(old) == str(new):
        return True
    table = _with_xyz(ctx, _tensor_names(ctx))
    if slot.kind == "tequation":
        from mechbook.model.tensorexpr import parse_tensor_equation

        b = [x - y for x, y in zip(*map(_flat, parse_tensor_equation(str(new), table,
                                                                     ctx.bodies)),
                                   strict=True)]
        if ctx.part.quantity == "identity":  # the original holds identically: so must this
            if any(_numerically_nonzero(y) for y in b):  # cheap, and settles most mutants
                return False
            return all(_zero(y) for y in b)
        a = [x - y for x, y in zip(*map(_flat, parse_tensor_equation(str(old), table,
                                                                     ctx.bodies)),
                                   strict=True)]
        if all(_zero(x - y) for x, y in zip(a, b, strict=True)):
            return True
        nonzero = [i for i, x in enumerate(a) if not _zero(x)]
        if not nonzero:
            return all(_zero(y) for y in b)
        ratio = b[nonzero[0]] / a[nonzero[0]]
        every = set().union(*(e.free_symbols for e in a + b))
        return _free_of(ratio, every) and all(_zero(y - ratio * x)
                                              for x, y in zip(a, b, strict=True))
    if slot.kind == "tdirection" and isinstance(slot.path[-1], int):
        entry = get(ctx.part.data, slot.path[:-1])
        u = [_tparse(ctx, x, table) for x in entry]
        v = [_tparse(ctx, new if j == slot.path[-1] else x, table) for j, x in enumerate(entry)]
        return all(_zero(u[i] * v[j] - u[j] * v[i]) for i in range(3) for j in range(i + 1, 3))
    a, b = _flat(_tparse(ctx, old, table)), _flat(_tparse(ctx, new, table))
    if any(_numerically_nonzero(y - x) for x, y in zip(a, b, strict=True)) and \
            slot.kind != "tdirection":
        return False
    if slot.kind == "tdirection":
        return all(_zero(a[i] * b[j] - a[j] * b[i]) for i in range(3) for j in range(i + 1, 3))
    return all(_zero(y - x) for x, y in zip(a, b, strict=True))


# ---- (b) the mutation test ------------------------------------------------------------------
RESOLVED_BY = "resolution b = "  # how a `lyapunov` sign claim's unsupported names its run


def rejected(slot: Slot, got) -> bool:
    """Whether a mutant was rejected: it failed. A Lyapunov sign claim the run cannot
    resolve (an exponent below its resolution b = 8/T is neither shown nor excluded) ends
    `unsupported`, never `fail`: that counts only where the detail states the resolution it
    was judged at. A mutant never passes."""
    if got.status == "fail":
        return True
    return (slot.kind == "exponent_sign" and got.status == "unsupported"
            and RESOLVED_BY in got.detail)


# A sample of six keys runs in every tier (the quick one too); every other key is `slow` and
# `mutation` (tests/mutation_keys.py: `make test-mutation`).
@pytest.mark.parametrize("answer_file", per_key(ANSWER_FILES))
def test_mutated_answers_fail(answer_file: Path, tmp_path: Path, repo_analysis):
    key = load_answers(answer_file)
    analysis = repo_analysis(key.problem_id)
    originals = check_problem(analysis, key)
    names = sorted(analysis.problem.parameters) + sorted(
        key.doc.data.get("abbreviations") or {})
    survivors: list[str] = []
    tried = 0
    checked_parts = 0
    for part, outcome in zip(key.parts, originals, strict=True):
        if "unsupported" in part.data or outcome.status not in ("pass", "erratum"):
            continue
        erratum = "erratum" in part.data
        try:
            ctx = Context(analysis, part)
            part_slots = list(slots(part, ctx, analysis))
        except UnsupportedError:
            continue
        checked_parts += 1
        coordinate = ctx.system.coord_names[0] if ctx.system is not None else ""
        if part.quantity in FIELD_QUANTITIES:  # a term added to a PDE: the field itself
            coordinate = analysis.built.field().name
        for slot in part_slots:
            old = get(part.data, slot.path)
            count = 0
            tensor = ctx.tensor_mode and part.quantity not in FIELD_QUANTITIES
            made = (functional_mutants(slot, old, names) if slot.kind.startswith("fn_")
                    else tensor_mutants(ctx, slot, old, names) if tensor else
                    mutants(slot, old, names, coordinate if slot.kind not in
                            ("shape", "flux") else ""))
            for label, new in made:
                if count >= MAX_MUTANTS_PER_SLOT:
                    break
                if "limit" in part.data and label == "add one" and str(old) != "0":
                    continue  # a lower-order term does not change an asymptotic formula
                if "estimate" in part.data and label in ("add one", "add the unit tensor"):
                    continue  # below the book's precision at its scale (moments ~ 1e37)
                if slot.kind in ("shape", "flux") and _field_same(ctx, slot, old, new):
                    continue
                if (str(old) == str(new) if slot.kind.startswith("fn_") else
                        tensor_same_meaning(ctx, slot, old, new) if tensor else
                        same_meaning(ctx, slot, part.data, old, new)):
                    continue
                count += 1
                tried += 1
                data = copy.deepcopy(part.data)
                put(data, slot.path, new)
                doc = copy.deepcopy(key.doc.data)
                doc["parts"] = [data]
                mutant_key = load_answers(dump(doc, tmp_path / f"mutant{tried}.yaml"))
                got = check_problem(analysis, mutant_key)[0]
                if VERBOSE:
                    print(f"{part.name} {slot.path} {label}: {new!r} -> {got.status}")
                ok = got.status != "erratum" if erratum else rejected(slot, got)
                if not ok:
                    where = "/".join(str(p) for p in slot.path)
                    survivors.append(f"{part.name} [{part.quantity}] {where}: {label}: "
                                     f"{old!r} -> {new!r}: {got.status} {got.method} "
                                     f"{got.detail[:200]}")
    if checked_parts:
        assert tried > 0, "no mutant was generated for any checked part"
    assert not survivors, (f"{len(survivors)} of {tried} mutants were not failed:\n  "
                           + "\n  ".join(survivors))


def test_nonreal_book_frequency_fails(tmp_path, hoop_analysis):
    """At the default values (b=0.5, omega=6) 1 - g**2/(omega**2*b**4) < 0: the book's
    frequency is imaginary, match_multiset compares NaN (always False) and passes it."""
    key = load_answers(ROOT / "answers" / "lim" / "2031.yaml")
    doc = copy.deepcopy(key.doc.data)
    part = next(p for p in doc["parts"] if p["quantity"] == "frequencies")
    part["book"] = ["b*sqrt(1 - g**2/(omega**2*b**4))"]
    doc["parts"] = [part]
    out = check_problem(hoop_analysis, load_answers(dump(doc, tmp_path / "nan.yaml")))[0]
    assert out.status == "fail"


def test_match_multiset_nan_documented():
    from mechbook.verify.compare import match_multiset
    assert match_multiset([1.0], [2.0])[0] is False
    assert match_multiset([1.0, 2.0], [2.0, 1.0])[0] is True


def test_match_multiset_rejects_nan():
    from mechbook.verify.compare import match_multiset
    assert match_multiset([float("nan")], [5.0])[0] is False


def test_wrong_equilibrium_point_with_stable_fails(tmp_path, hoop_analysis):
    """Bead on the hoop: theta = pi/2 is not an equilibrium. With `stable: true` the check
    linearizes there before looking at its own failed residual, so the part comes out
    'unsupported' instead of 'fail'."""
    key = load_answers(ROOT / "answers" / "lim" / "2031.yaml")
    doc = copy.deepcopy(key.doc.data)
    doc["parts"] = [{"part": "wrong", "cite": "test", "quantity": "equilibrium",
                     "book": {"at": {"theta": "pi/2"}}, "stable": True}]
    out = check_problem(hoop_analysis, load_answers(dump(doc, tmp_path / "eq.yaml")))[0]
    assert out.status == "fail", (out.status, out.detail)


def test_wrong_equilibrium_point_without_stable_fails(tmp_path, hoop_analysis):
    key = load_answers(ROOT / "answers" / "lim" / "2031.yaml")
    doc = copy.deepcopy(key.doc.data)
    doc["parts"] = [{"part": "wrong", "cite": "test", "quantity": "equilibrium",
                     "book": {"at": {"theta": "pi/2"}}},
                    {"part": "right", "cite": "test", "quantity": "equilibrium",
                     "book": {"at": {"theta": "pi"}}}]
    out = check_problem(hoop_analysis, load_answers(dump(doc, tmp_path / "eq.yaml")))
    assert [o.status for o in out] == ["fail", "pass"]


def _part_of(pid: str, name: str, **changes) -> dict:
    key = load_answers(ROOT / "answers" / pid.split("-")[0] / f"{pid.split('-', 1)[1]}.yaml")
    doc = copy.deepcopy(key.doc.data)
    part = next(p for p in doc["parts"] if p["part"] == name)
    part.update(changes)
    doc["parts"] = [part]
    return doc


@pytest.fixture(scope="module")
def vessel_analysis(repo_analysis) -> Analysis:
    return repo_analysis("lim-2040")


@pytest.mark.parametrize("name", ["a-energy", "b"])
def test_wrong_steady_rate_is_a_fail(tmp_path, vessel_analysis, name):
    """A steady motion the book names at a wrong rate is the book's error: a fail, never
    'unsupported' (the engine can tell that it is not a steady motion)."""
    right = check_problem(vessel_analysis, load_answers(
        dump(_part_of("lim-2040", name), tmp_path / "right.yaml")))[0]
    assert right.status == "pass", right.detail
    wrong = check_problem(vessel_analysis, load_answers(dump(
        _part_of("lim-2040", name, steady={"theta": "2*omega"}), tmp_path / "wrong.yaml")))[0]
    assert wrong.status == "fail"
    assert "not an equilibrium" in wrong.detail


def test_value_at_a_state(tmp_path, vessel_analysis):
    """`at:` evaluates a function of the state at given coordinates and velocities."""
    doc = _part_of("lim-2040", "a-energy")
    del doc["parts"][0]["steady"], doc["parts"][0]["about"]
    doc["parts"][0]["at"] = {"r": "r0", "rdot": 0, "thetadot": "omega"}
    out = check_problem(vessel_analysis, load_answers(dump(doc, tmp_path / "at.yaml")))[0]
    assert out.status == "pass", out.detail
    doc["parts"][0]["at"] = {"r": "r0", "rdot": 0, "thetadot": "2*omega"}
    out = check_problem(vessel_analysis, load_answers(dump(doc, tmp_path / "at2.yaml")))[0]
    assert out.status == "fail"
    doc["parts"][0]["at"] = {"r": "r0"}
    out = check_problem(vessel_analysis, load_answers(dump(doc, tmp_path / "at3.yaml")))[0]
    assert out.status == "error" and "unknown" in out.detail


# ---- (c) errata -----------------------------------------------------------------------------
def _erratum_key(tmp_path: Path, book: str, corrected: str) -> AnswerKey:
    key = load_answers(ROOT / "answers" / "lim" / "2031.yaml")
    doc = copy.deepcopy(key.doc.data)
    doc["parts"] = [{
        "part": "c-frequency",
        "cite": "a test erratum",
        "quantity": "frequencies",
        "assume": ["omega > Omega"],
        "about": {"theta": "acos(-g/(b*omega**2))"},
        "book": [book],
        "erratum": {"corrected": [corrected],
                    "derivation": "the test says so, at some length, for the schema"},
    }]
    return load_answers(dump(doc, tmp_path / "erratum.yaml"))


RIGHT = "omega*sqrt(1 - g**2/(b**2*omega**4))"
WRONG = "omega*sqrt(1 + g**2/(b**2*omega**4))"


@pytest.fixture(scope="module")
def hoop_analysis(repo_analysis) -> Analysis:
    return repo_analysis("lim-2031")


def test_erratum_whose_book_value_agrees_is_a_fail(tmp_path, hoop_analysis):
    out = check_problem(hoop_analysis, _erratum_key(tmp_path, RIGHT, RIGHT))[0]
    assert out.status == "fail"
    assert "agrees" in out.detail


def test_erratum_with_wrong_book_and_right_correction(tmp_path, hoop_analysis):
    out = check_problem(hoop_analysis, _erratum_key(tmp_path, WRONG, RIGHT))[0]
    assert out.status == "erratum"


def test_erratum_whose_correction_is_wrong_too_is_a_fail(tmp_path, hoop_analysis):
    out = check_problem(hoop_analysis, _erratum_key(tmp_path, WRONG, f"2*{RIGHT}"))[0]
    assert out.status == "fail"
    assert "corrected value fails" in out.detail


def test_unsupported_part_is_never_a_pass(tmp_path, hoop_analysis):
    key = load_answers(ROOT / "answers" / "lim" / "2031.yaml")
    doc = copy.deepcopy(key.doc.data)
    doc["parts"] = [dict(doc["parts"][0], unsupported="not done yet, for the test")]
    out = check_problem(hoop_analysis, load_answers(dump(doc, tmp_path / "u.yaml")))[0]
    assert out.status == "unsupported"


def test_text_surgery_helpers():
    assert flip_first_sign("a + b - c") == "a - b - c"
    assert flip_first_sign("-a - b") == "-a + b"
    assert flip_first_sign("x**-2 + 1e-3") == "x**-2 - 1e-3"
    assert flip_first_sign("(a + b)*c") is None
    assert double_first_term("a*b + c") == "2*(a*b) + c"
    assert split_equation("a = b") == ("a", "b")
    assert split_equation("a <= b") is None
    assert flip_relation("omega < Omega") == "omega > Omega"
    assert list(swap_names("m*b + b2", ["b", "m"])) == [("swap b<->m", "b*m + b2")]
    leaves = list(walk({"x": ["a = b", "c < d", 2], "y": "q"}, ("book",)))
    assert [(sl.path, sl.kind) for sl in leaves] == [
        (("book", "x", 0), "equation"), (("book", "x", 1), "relation"),
        (("book", "x", 2), "value"), (("book", "y"), "value")]


def test_a_mutant_counts_as_rejected_only_where_it_failed_or_its_claim_is_unresolved():
    """The harness's rule: `fail` rejects; `unsupported` rejects only an `exponent_sign`
    mutant whose detail states the resolution it was judged at; a pass never does."""
    from types import SimpleNamespace as Outcome
    sign, value = Slot(("book",), "exponent_sign"), Slot(("book",), "value")
    unresolved = ("the run resolves no exponent above the resolution b = 0.008 (λ = 0.001, "
                  "spread 0.0009, T = 1000); a positive exponent ... is not excluded")
    assert rejected(sign, Outcome(status="fail", detail=""))
    assert rejected(value, Outcome(status="fail", detail=""))
    assert rejected(sign, Outcome(status="unsupported", detail=unresolved))
    assert not rejected(sign, Outcome(status="unsupported", detail="the integration failed"))
    assert not rejected(value, Outcome(status="unsupported", detail=unresolved))
    for slot in (sign, value):
        assert not rejected(slot, Outcome(status="pass", detail=unresolved))
