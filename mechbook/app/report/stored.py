"""The results a check stored, read back as SymPy objects for the report.

A check stores what it derived as text in SymPy's printing (mechbook.engine.derive.computed):
expressions, and lists, matrices and mappings of them. The report reads them back instead
of deriving them again. The containers are split here (brackets, braces, commas and colons
at the top level, outside parentheses); every leaf goes through the safe parser
(mechbook.model.expr), never `eval` or `sympify`: the store is a file like any other. A
name the problem does not declare (an answer's symbol, a multiplier) is read as a plain
symbol: the text is only shown.
"""

from __future__ import annotations

from collections.abc import Mapping

import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.expr import CONSTANTS, FUNCTIONS, parse

# what stored text reads back as: an expression, or lists and dicts of them
Stored = sp.Basic | list["Stored"] | dict[sp.Basic, "Stored"]

MAX_TEXT = 20_000  # characters of one stored result read back (longer: not typeset)


class _Names(dict):
    """The problem's names, and any other identifier as a real symbol (only for showing)."""

    def __contains__(self, key: object) -> bool:
        return dict.__contains__(self, key) or (isinstance(key, str) and key.isidentifier()
                                                and key not in FUNCTIONS
                                                and key not in CONSTANTS)

    def __missing__(self, key: str) -> sp.Symbol:
        sym = sp.Symbol(key, real=True)
        self[key] = sym
        return sym


def names_for(known: Mapping[str, sp.Basic]) -> _Names:
    """A name table for reading stored text: `known` (a system's names) first."""
    return _Names(known)


def read(text: str, names: Mapping[str, sp.Basic]) -> Stored:
    """The stored `text` as SymPy objects: an expression, or lists and dicts of them (a
    matrix is a list of rows). ExpressionError when it cannot be read (too long, or not
    what a check writes)."""
    if len(text) > MAX_TEXT:
        raise ExpressionError(f"too long to show ({len(text)} characters)")
    table = names if isinstance(names, _Names) else names_for(names)
    return _read(text.strip(), table)


def _read(text: str, names: _Names) -> Stored:
    if text.startswith("[") and text.endswith("]") and _closes_at_end(text):
        return [_read(item, names) for item in _split(text[1:-1], ",")]
    if text.startswith("{") and text.endswith("}") and _closes_at_end(text):
        out = {}
        for item in _split(text[1:-1], ","):
            key, _, value = _partition(item)
            out[_read(key, names)] = _read(value, names)
        return out
    if text in ("True", "False"):
        return sp.true if text == "True" else sp.false
    return parse(text, names)


def _closes_at_end(text: str) -> bool:
    """Whether the bracket opening `text` closes at its last character."""
    depth = 0
    for i, ch in enumerate(text):
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
            if depth == 0 and i != len(text) - 1:
                return False
    return depth == 0


def _split(text: str, sep: str) -> list[str]:
    """`text` split at `sep` outside any brackets; empty text gives []."""
    out, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == sep and depth == 0:
            out.append(text[start:i].strip())
            start = i + 1
    last = text[start:].strip()
    if last or out:
        out.append(last)
    return [item for item in out if item]


def _partition(item: str) -> tuple[str, str, str]:
    depth = 0
    for i, ch in enumerate(item):
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == ":" and depth == 0:
            return item[:i].strip(), ":", item[i + 1:].strip()
    raise ExpressionError(f"expected 'name: value' in {item[:60]!r}")


def matrix(value: Stored) -> sp.Matrix:
    """A stored matrix (a list of rows) as a SymPy Matrix."""
    if isinstance(value, list) and value and all(isinstance(r, list) for r in value):
        return sp.Matrix(value)
    if isinstance(value, list):
        return sp.Matrix(value)
    return sp.Matrix([[value]])
