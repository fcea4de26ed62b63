"""Plain-data records of a check run: outcomes of parts, cross-checks, derived results.

They cross process boundaries (a batch's workers send them to the parent) and are read back
from the store, so they hold only strings, numbers, lists, dicts and NumPy arrays — never
SymPy objects — and this module imports nothing heavy: the parent of a batch, and a warm
run answered from the store, never import the engine.
"""

from __future__ import annotations

import enum
import math
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np


class Status(enum.StrEnum):
    """An outcome: of an answer part, of a cross-check, or of one mode a cross-check
    measured. A `str` (its value) everywhere text is made of it: JSON, HDF5 (written as
    `str(status)`: h5py takes plain strings only), the table, f-strings."""

    PASS = "pass"
    FAIL = "fail"
    ERRATUM = "erratum"  # the book's value fails, the key's corrected value passes
    UNSUPPORTED = "unsupported"  # the engine cannot compute it yet; never a pass
    ERROR = "error"  # could not be evaluated (or the check could not run): counts as a fail
    NA = "n.a."  # a cross-check that does not apply, with the reason


# the outcomes of a part, and of a cross-check, in the order tables count them
STATUSES = (Status.PASS, Status.FAIL, Status.ERRATUM, Status.UNSUPPORTED, Status.ERROR)
CROSSCHECK_STATUSES = (Status.PASS, Status.FAIL, Status.NA, Status.ERROR)
# the outcomes (of a part or a cross-check) that count as a fail: `mechbook check` exits 1
FAILING = (Status.FAIL, Status.ERROR)


@dataclass(frozen=True)
class ProofPolicy:
    """The checker's trade of speed for certainty, chosen by the user.

    By default a comparison is decided numerically (30 digits at random admissible
    points); with `prove`, an expression that passed is also proved exactly where it can
    be (mechbook.verify.proof: canonical forms, then SymPy's simplify, a part's attempts
    sharing `seconds` of simplify). A verdict's method says which it got ('symbolic', or
    'numeric(…); unproved: why')."""

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
    status: Status
    method: str = ""
    detail: str = ""
    seconds: float = 0.0
    origin: str = "book"  # 'derived': no printed answer; the value is an independent derivation
    power: str = ""  # what the pass is worth: the smallest wrong answer it rejects, in words

    def __post_init__(self) -> None:
        self.status = Status(self.status)  # a stored or sent string read back

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass
class CrossCheck:
    """One independent cross-check and the answer parts it vouches for."""

    name: str
    kind: str  # "frequencies", "newton", "conserved", "inertia" or "none" (n.a.)
    system: str
    status: Status = Status.ERROR  # pass | fail | n.a. | error
    error: float = float("nan")  # largest relative error measured
    detail: str = ""
    parts: list[str] = field(default_factory=list)
    seconds: float = 0.0
    modes: list[dict] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.status = Status(self.status)  # a stored or sent string read back

    def as_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> CrossCheck:
        known = {k: data[k] for k in cls.__dataclass_fields__ if k in data}
        return cls(**known)

    @property
    def failed(self) -> bool:
        return self.status in FAILING

    def cell(self) -> str:
        """The table's cross-check column."""
        if self.status in (Status.PASS, Status.FAIL) and math.isfinite(self.error):
            return f"{self.status} {self.error:.0e}"
        return self.status


@dataclass
class Results:
    """A system's derived results as a reader sees them: text (SymPy's printing, which the
    safe parser reads back), arrays at the default parameter values, and notes on what is
    missing and why."""

    system: str
    text: dict[str, str] = field(default_factory=dict)
    arrays: dict[str, np.ndarray] = field(default_factory=dict)
    notes: dict[str, str] = field(default_factory=dict)
