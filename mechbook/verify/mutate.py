"""Small wrong answers: a book value with one number or one parameter moved by 1 + δ.

A checker is only as good as the wrong answers it rejects. To measure that power, every
answer part's value is perturbed slightly, one place at a time: each number and each
occurrence of a parameter (or answer symbol, or abbreviation) in an expression, equation or
relation is multiplied by 1 + δ (exact rationals, so the 30-digit comparison sees exactly
the intended change), and the whole value is shifted by δ times its size (an additive
constant moved). Integers (counts), flags and verdict words have no small change: their
nearest wrong value (±1, the other flag, another word) stands in. The mutants are text,
spliced into the part's data where the original was, so they go through the same parser
and checker as the book's own value (bench/power.py, tests/test_power.py).
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from dataclasses import dataclass
from fractions import Fraction

from mechbook.model.expr import FUNCTIONS, split_single_equals
from mechbook.verify.compare import value_and_scale
from mechbook.verify.context import strip_const

# verdicts given as words, each group the words one value may be instead of another
WORD_GROUPS = (("stable", "unstable", "marginal"), ("captured", "scattered"))
WORDS = tuple(w for group in WORD_GROUPS for w in group)
COUNTS = ("equilibrium_count", "mode_count", "secular_growth")  # integers that are counts


@dataclass(frozen=True)
class Mutant:
    path: tuple  # where in the part's data the changed leaf is
    label: str  # what was changed, for messages
    value: object  # the new leaf (text, or an int/bool for discrete values)
    kind: str  # 'number' · 'parameter' · 'shift' · 'discrete'
    token: str = ""  # the number or name scaled ('' for a shift or a discrete change)


def factor(delta: Fraction) -> str:
    """1 + δ as exact text, e.g. '(101/100)'."""
    f = 1 + Fraction(delta)
    return f"({f.numerator}/{f.denominator})"


def leaves(value, path: tuple) -> Iterator[tuple[tuple, object]]:
    """Every leaf of a book value (strings, numbers, flags) with its path."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from leaves(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from leaves(v, path + (i,))
    else:
        yield path, value


def _byte_offsets(text: str) -> list[int]:
    """Byte offset of each line's start (ast columns are UTF-8 byte offsets)."""
    starts, pos = [0], 0
    for line in text.encode().split(b"\n")[:-1]:
        pos += len(line) + 1
        starts.append(pos)
    return starts


def _sites(text: str, names: set[str]) -> list[tuple[int, int, str, str]]:
    """(start, end, kind, token) in bytes of every number and every name in `names`
    in one expression or relation; [] if the text does not parse."""
    try:
        tree = ast.parse(text, mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return []
    lines = _byte_offsets(text)
    out = []
    indices = _index_arguments(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, int | float) \
                and not isinstance(node.value, bool):
            if id(node) in indices:
                continue  # W0(1), entry(J, 1, 3), diff(f, x, 2): an index, not a value
            kind = "number"
        elif isinstance(node, ast.Name) and node.id in names:
            kind = "parameter"
        else:
            continue
        a = lines[node.lineno - 1] + node.col_offset
        b = lines[node.end_lineno - 1] + node.end_col_offset
        out.append((a, b, kind, text.encode()[a:b].decode()))
    # a parenthesised call such as f(x)(y) cannot occur; sites never overlap
    return sorted(out)


def _index_arguments(tree: ast.AST) -> set[int]:
    """ids of the whole-number literals passed straight to a call that is not a function of
    real values (a table of the text's notation, a tensor's entry, a derivative's order)."""

    values = set(FUNCTIONS) - {"diff"}
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and not (isinstance(node.func, ast.Name)
                                               and node.func.id in values):
            for arg in node.args:
                if isinstance(arg, ast.Constant) and isinstance(arg.value, int) \
                        and not isinstance(arg.value, bool):
                    out.add(id(arg))
    return out


def text_mutants(
text: str, names: set[str], delta: Fraction
                 ) -> Iterator[tuple[str, str, str, str]]:
    """(kind, label, new text, token) for each number and named parameter of `text` scaled
    by 1 + δ; equations 'lhs = rhs' are mutated on each side, a trailing '= const' kept."""
    pieces = split_single_equals(text)
    if len(pieces) > 2:
        return
    offset = 0
    for k, piece in enumerate(pieces):
        stripped = piece.strip()
        lead = len(piece) - len(piece.lstrip())
        if stripped in ("const", "constant") and k == len(pieces) - 1:
            break
        raw = stripped.encode()
        for a, b, kind, token in _sites(stripped, names):
            if kind == "number" and float(token) == 0:
                continue  # 0·(1 + δ) is 0: no change
            new = raw[:a].decode() + f"({token}*{factor(delta)})" + raw[b:].decode()
            whole = pieces[:k] + [piece[:lead] + new + piece[lead + len(stripped):]] + \
                pieces[k + 1:]
            yield kind, f"{token}×(1+{float(delta):g}) at column {offset + lead + a + 1}", \
                "=".join(whole), token
        offset += len(piece) + 1


def shifted(text: str, size: Fraction, delta: Fraction) -> str | None:
    """The value moved by δ·size: added to an expression, to an equation's right side, to
    the right side of a relation's last comparison; None for what it cannot shift."""
    amount = Fraction(delta) * size
    if amount == 0:
        return None
    add = f" + ({amount.numerator}/{amount.denominator})"
    pieces = split_single_equals(text)
    if len(pieces) == 2:
        rhs = pieces[1].strip()
        if rhs in ("const", "constant"):
            return f"({pieces[0].strip()}){add} = {rhs}"
        return f"{pieces[0]}= ({rhs}){add}"
    if len(pieces) != 1:
        return None
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return None
    body = tree.body
    if isinstance(body, ast.Compare):
        raw = text.strip().encode()
        last = body.comparators[-1]
        lines = _byte_offsets(text.strip())
        a = lines[last.lineno - 1] + last.col_offset
        b = lines[last.end_lineno - 1] + last.end_col_offset
        return (raw[:a] + b"(" + raw[a:b] + b")" + add.encode() + raw[b:]).decode()
    if isinstance(body, ast.BoolOp):
        return None  # several relations: each has its own numbers and parameters
    return f"({text.strip()}){add}"


def discrete(value) -> Iterator[tuple[str, object]]:
    """The nearest wrong values of a value without a small change."""
    if isinstance(value, bool):
        yield "flag flipped", not value
    elif isinstance(value, int):
        yield "count + 1", value + 1
        if value > 0:
            yield "count - 1", value - 1
    elif isinstance(value, str) and value in WORDS:
        group = next(g for g in WORD_GROUPS if value in g)
        for w in group:
            if w != value:
                yield f"{value} -> {w}", w


def part_mutants(value, root: tuple, names: set[str], delta: Fraction,
                 sizes: dict | None = None, counts: bool = False) -> Iterator[Mutant]:
    """Every small mutant of a part's value at `root` (('book',) or the erratum's
    ('erratum', 'corrected')): each number and parameter occurrence scaled by 1 + δ, each
    leaf shifted by δ·size (sizes: path -> |value| at the default point, where known),
    and the nearest wrong value of a discrete leaf (`counts`: integers are counts)."""
    for path, leaf in leaves(value, root):
        if isinstance(leaf, bool) or (isinstance(leaf, int) and counts) or \
                (isinstance(leaf, str) and leaf in WORDS):
            for label, new in discrete(leaf):
                yield Mutant(path, label, new, "discrete")
            continue
        if isinstance(leaf, int | float):
            leaf = repr(leaf)
        if not isinstance(leaf, str):
            continue
        for kind, label, new, token in text_mutants(leaf, names, delta):
            yield Mutant(path, label, new, kind, token)

        size = (sizes or {}).get(path)
        if size:
            new = shifted(leaf, size, delta)
            if new is not None:
                yield Mutant(path, f"shifted by {float(delta):g}×{float(size):.3g}", new,
                             "shift")


def shift_sizes(ctx, value, root: tuple) -> dict:
    """|leaf| at the default point (3 significant digits, exact) for the shift mutants: an
    expression's value, an equation's cancellation scale, a relation's last right side.
    (Imports only what every tree since 00b0b7e has: bench/power.py loads this module by
    path to measure an earlier tree with the same mutants.)"""
    import sympy as sp


    point = ctx.sampler.default()
    out = {}
    for path, leaf in leaves(value, root):
        if isinstance(leaf, bool) or not isinstance(leaf, str | int | float):
            continue
        if isinstance(leaf, str) and leaf in WORDS:
            continue
        text = str(leaf)
        try:
            if any(c in text for c in "<>"):
                expr = ctx.parse(text, path, relation=True)
                rels = sorted(expr.atoms(sp.core.relational.Relational), key=str)
                expr = rels[-1].rhs if rels else None
            elif len(split_single_equals(text)) == 2:
                expr = ctx.parse(strip_const(text), path, equation=True)
            else:
                expr = ctx.parse(text, path)
        except Exception:  # noqa: BLE001 - e.g. a leaf that names an operator, not a value
            continue
        if expr is None or not isinstance(expr, sp.Basic):
            continue
        free = {s: 0.5 for s in expr.free_symbols if s not in point}  # motion variables
        v, scale = value_and_scale(expr, {**point, **free})
        size = abs(v) if abs(v) > 1e-12 * max(scale, 1e-300) else scale
        if size == size and 0 < size < 1e30:
            out[path] = Fraction(f"{size:.3g}")
    return out
