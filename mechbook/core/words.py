"""Counts in words: "1 problem", "2 problems", one rule for every message and table.

Each stage's messages count things (problems, parts, points, modes); a count printed with a
fixed plural ("1 problems", "numeric(1 points)") reads as a mistake, so they all say it here.
"""

from __future__ import annotations


def plural(n: int, word: str, many: str | None = None) -> str:
    """`n` and `word`, in the plural unless `n` is 1 (`many`, or `word` + 's').

    Example: plural(1, "point") -> "1 point"; plural(3, "point") -> "3 points";
    plural(2, "body", "bodies") -> "2 bodies". Large counts keep their digits as given
    (`n` is formatted with `format(n)`; pass a string such as f"{n:,}" for separators).
    """
    one = (n == 1) if not isinstance(n, str) else n.replace(",", "") == "1"
    return f"{n} {word if one else (many or word + 's')}"


def duration(seconds: float) -> str:
    """A duration as a reader says it: two figures, whole seconds past ten, minutes past
    one (never "0.536591 s").

    Example: duration(0.536591) -> "0.54 s"; duration(7.518) -> "7.5 s";
    duration(42.4) -> "42 s"; duration(125) -> "2 min 05 s"; duration(0.003) -> "3 ms".
    """
    s = float(seconds)
    if s != s or s < 0:
        return "unknown"
    if s < 0.01:
        return f"{max(s * 1000, 0.0):.2g} ms"
    if s < 10:
        return f"{s:.2g} s"
    if s < 59.5:
        return f"{s:.0f} s"
    minutes, rest = divmod(round(s), 60)
    return f"{minutes} min {rest:02d} s"
