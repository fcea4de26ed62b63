"""Plain-data records of a check run: outcomes of parts, cross-checks, derived results.

They cross process boundaries (a batch's workers send them to the parent) and are read back
from the store, so they hold only strings, numbers, lists, dicts and NumPy arrays — never
SymPy objects — and this module imports nothing heavy: the parent of a batch, and a warm
run answered from the store, never import the engine.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

STATUSES = ("pass", "fail", "erratum", "unsupported", "error")


@dataclass(frozen=True)
class ProofPolicy:
    """The checker's trade of speed for certainty, chosen by the user.

    By default a comparison is decided numerically (30 digits at random admissible
    points); with `prove`, an expression that passed is also handed to SymPy's simplify
    for a symbolic proof, each attempt limited to `seconds`. A verdict's method says
    which it got ('symbolic' or 'numeric(…)')."""

    prove: bool = False
    seconds: float = 10.0


NUMERIC = ProofPolicy()


@dataclass
class Outcome:
    """One answer part's verdict: pass · fail · erratum (the book's value fails, the key's
    corrected value passes) · unsupported (the engine cannot compute it yet; never a pass)
    · error (the part could not be evaluated; counts as a fail)."""

    problem: str
    part: str
    quantity: str
    cite: str
    status: str
    method: str = ""
    detail: str = ""
    seconds: float = 0.0
    origin: str = "book"  # 'derived': no printed answer; the value is an independent derivation
    power: str = ""  # what the pass is worth: the smallest wrong answer it rejects, in words

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass
class CrossCheck:
    """One independent cross-check and the answer parts it vouches for."""

    name: str
    kind: str  # "frequencies", "newton", "conserved", "inertia" or "none" (n.a.)
    system: str
    status: str = "error"  # pass | fail | n.a. | error
    error: float = float("nan")  # largest relative error measured
    detail: str = ""
    parts: list[str] = field(default_factory=list)
    seconds: float = 0.0
    modes: list[dict] = field(default_factory=list)

    def as_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> CrossCheck:
        known = {k: data[k] for k in cls.__dataclass_fields__ if k in data}
        return cls(**known)

    @property
    def failed(self) -> bool:
        return self.status in ("fail", "error")

    def cell(self) -> str:
        """The table's cross-check column."""
        if self.status in ("pass", "fail") and math.isfinite(self.error):
            return f"{self.status} {self.error:.0e}"
        return self.status


@dataclass
class Results:
    """A system's derived results as a reader sees them: text (SymPy's printing, which the
    safe parser reads back), arrays at the default parameter values, and notes on what is
    missing and why."""

    system: str
    text: dict[str, str] = field(default_factory=dict)
    arrays: dict[str, Any] = field(default_factory=dict)  # NumPy arrays
    notes: dict[str, str] = field(default_factory=dict)
