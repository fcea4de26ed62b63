"""How to fix it: the nearest names, and what a common slip should have been.

An error that only says what is wrong leaves the author to guess; these helpers add the
likely fix to messages about unknown names, keys and quantities (`did you mean
'frequencies'?`), operators from other languages (`^` for a power) and YAML indentation.
Pure text: nothing here imports SymPy.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable

MAX_LISTED = 12  # a list of allowed names longer than this is not printed whole


def nearest(name: str, candidates: Iterable[str], n: int = 3) -> list[str]:
    """The candidates closest to `name`: difflib's ratio at least 0.6 and within 0.1 of the
    best (so 'thetta' gives 'theta', not also 'thetadot'), or equal but for case."""
    pool = sorted({str(c) for c in candidates if str(c) != name})
    scored = sorted(((difflib.SequenceMatcher(None, name, c).ratio(), c) for c in pool),
                    reverse=True)
    scored = [(r, c) for r, c in scored if r >= 0.6]
    found = [c for r, c in scored if r >= scored[0][0] - 0.1][:n] if scored else []
    found += [c for c in pool if c.lower() == name.lower() and c not in found]
    return found[:n]


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """"did you mean 'x'?" (or 'x' or 'y'), or '' when no candidate is close."""
    close = nearest(name, candidates)
    if not close:
        return ""
    quoted = [repr(c) for c in close]
    said = quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " or " + quoted[-1]
    return f"did you mean {said}?"


def allowed(candidates: Iterable[str], what: str = "allowed") -> str:
    """'allowed: a, b, c' for a short list; for a long one only how many there are."""
    names = sorted({str(c) for c in candidates})
    if len(names) <= MAX_LISTED:
        return f"{what}: {', '.join(names)}"
    return f"{len(names)} are {what} (docs/schema.md, docs/answers.md list them)"


OPERATOR_HINTS = {
    "BitXor": "'^' is not a power here: write '**' (omega**2)",
    "BitAnd": "'&': join comparisons with 'and'",
    "BitOr": "'|': join comparisons with 'or'",
    "MatMult": "'@': write '*' for a product",
    "FloorDiv": "'//': write '/' for a quotient",
    "Mod": "'%': there are no remainders here",
    "Not": "'not': state the comparison itself ('a >= b', not 'not a < b')",
    "Eq": "'==': write 'lhs = rhs' for an equation, or compare with '<', '>', '!='",
}


def operator_hint(op: str) -> str:
    """The message for a Python operator the safe parser does not take, with the fix."""
    hint = OPERATOR_HINTS.get(op)
    return f"{op} is not allowed" + (f" ({hint})" if hint else "")


INDENT_HINT = ("check the indentation: the keys of one mapping start in the same column, "
               "each nested entry further right than its parent, with spaces (a tab is "
               "not indentation)")
_INDENT_SIGNS = ("expected <block end>", "mapping values are not allowed",
                 "could not find expected ':'", "did not find expected key",
                 "did not find expected '-' indicator", "while parsing a block")


def yaml_hint(message: str) -> str:
    """A YAML syntax error's message, with the usual cause when it is one of indentation."""
    if any(sign in message for sign in _INDENT_SIGNS):
        return f"{message} ({INDENT_HINT})"
    return message
