"""Stability of a linearization with periodic coefficients, as the verdicts a part needs.

About a rest point of a driven system (a pivot moved up and down, a modulated stiffness)
M, C and K depend on t; the verdict is Floquet's (mechbook.numerics.floquet): the
multipliers of the monodromy over one period T, detected from the coefficients or given
by the part's `period:` (then verified at every point). One compiled integrator per linear
system serves every parameter point of a part and of the parts after it. Each point is
first put to the double-precision screen (mechbook.numerics.floquet_screen), which decides
only where every multiplier within its conservative error estimate gives the 113-bit
verdict; every other point is integrated in 113 bits (issue 42).
"""

from __future__ import annotations

from mechbook.core.words import plural
from mechbook.engine.linear import LinearSystem
from mechbook.engine.periodic import time_dependent
from mechbook.numerics.floquet import ARITHMETIC, RESOLVED, Floquet
from mechbook.numerics.floquet_screen import Screen
from mechbook.verify.context import Context

__all__ = ["FloquetVerdicts", "time_dependent"]


class FloquetVerdicts:
    """The Floquet verdict at parameter points, and the worst resolution met (for the
    pass's power)."""

    def __init__(self, ctx: Context, lin: LinearSystem):
        declared = ctx.part.data.get("period")
        text = None if declared is None else str(declared)

        def build() -> Floquet:
            if text is None:
                return Floquet.of(lin)
            flo = Floquet.of(lin, ctx.parse(text, ("period",)))
            flo.declared = True
            return flo

        self.floquet = ctx.analysis.reuse(("floquet", id(lin), text), build)
        self.screen = ctx.analysis.reuse(("floquet-screen", id(lin), text),
                                         lambda: Screen(self.floquet))
        self.worst = 0.0
        self.points = 0  # integrated in 113 bits
        self.screened = 0  # decided by the double-precision screen

    def stability(self, pt: dict) -> str:
        """'stable', 'unstable' or 'marginal' at `pt`: the screen's verdict where it is
        certain, else the 113-bit computation's."""
        quick = self.screen.verdict(pt)
        if quick is not None:
            self.screened += 1
            return quick
        got = self.floquet.multipliers(pt)
        self.points += 1
        self.worst = max(self.worst, got.resolution)
        verdict = got.verdict()
        self.screen.note(verdict)
        return verdict

    def classify(self, pt: dict, near: bool) -> bool | None:
        """The boundary comparison's classifier: True stable, False unstable, None marginal
        (every point is taken at the one, precise, arithmetic: `near` changes nothing)."""
        got = self.stability(pt)
        return None if got == "marginal" else got == "stable"

    def power(self) -> str:
        screened = (f"; {plural(self.screened, 'point')} decided in double precision, "
                    "where every multiplier within its (conservative, estimated) error "
                    "bound gives the 113-bit verdict"
                    if self.screened else "")
        if not self.points:
            return (f"the engine's verdicts from Floquet multipliers (the monodromy over one "
                    f"period T = {self.floquet.period}{screened})")
        return (f"the engine's verdicts from Floquet multipliers (the monodromy over one "
                f"period T = {self.floquet.period}, {ARITHMETIC}; Φ resolved to "
                f"{max(self.worst, 1e-36):.0e} by Liouville's determinant over its "
                f"condition at {plural(self.points, 'point')}, {RESOLVED:g} needed"
                f"{screened})")
