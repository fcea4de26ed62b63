"""Every cross-check of one problem: which run, for which answer parts, in what order.

Newton per system; per answer part, the checks its quantity's registration declares
(vouch.py): a first integral along a run, steady motions and trajectories measured, the
driven response, and the frequencies at the part's point (points.py: one simulation per
distinct point); then the frequencies about the engine's own stable equilibria, and the
declared bodies' inertia. Each check runs under the one guard (guard.py): a fault in one
never hides the others.
"""

from __future__ import annotations

from collections.abc import Callable

from mechbook.crosscheck.conserved import conserved_part
from mechbook.crosscheck.frequencies import frequency_crosscheck
from mechbook.crosscheck.guard import guarded
from mechbook.crosscheck.inertia import inertia_crosschecks
from mechbook.crosscheck.newton import newton_crosscheck
from mechbook.crosscheck.partview import PartView
from mechbook.crosscheck.points import engine_linear_systems, numeric_key, point_label
from mechbook.crosscheck.response import response_part
from mechbook.crosscheck.simulated_motion import steady_crosscheck, trajectory_crosscheck
from mechbook.crosscheck.state_modes import state_frequency_crosscheck
from mechbook.crosscheck.vouch import crosschecks_of
from mechbook.engine.analysis import Analysis
from mechbook.records import CrossCheck, Status
from mechbook.verify.answers import AnswerKey, Part


def _modes_check(analysis: Analysis, lin, values: dict, name: str, models: dict) -> CrossCheck:
    """The simulated-modes cross-check of a linear system: second order
    (mechbook.crosscheck.frequencies) or first order (mechbook.crosscheck.state_modes)."""
    if not lin.first_order:
        return frequency_crosscheck(analysis, lin, values, name, models)
    out = CrossCheck(name, "frequencies", lin.dyn.sys.full.name)
    with guarded(out):
        state_frequency_crosscheck(analysis, lin, values, out, models)
    return out


def crosscheck_problem(analysis: Analysis, key: AnswerKey | None = None,
                       stage: Callable[[str], None] = lambda text: None) -> list[CrossCheck]:
    """Every cross-check of a problem: Newton per system, frequencies per linear system the
    answer key refers to and per stable equilibrium the engine derives. `stage` is told
    which check is running (a batch reports it if the problem runs out of time)."""
    run = _ProblemChecks(analysis, stage)
    run.newton_per_system()
    for part in (key.parts if key else []):
        if "unsupported" not in part.data:
            run.part(part)
    run.engine_equilibria()
    stage("cross-check: declared bodies")
    return run.out + list(run.newton.values()) + list(run.freq.values()) \
        + inertia_crosschecks(analysis, key)


class _ProblemChecks:
    """The cross-checks of one problem as they accumulate: those of the parts (`out`), one
    Newton check per system, one frequency check per distinct point (`freq`, keyed as
    points.numeric_key makes them), and the simulations shared by parts (`measured`)."""

    def __init__(self, analysis: Analysis, stage: Callable[[str], None]):
        self.analysis, self.stage = analysis, stage
        problem = analysis.problem
        self.systems = list(problem.systems)
        self.only = self.systems[0] if len(self.systems) == 1 else None
        self.params = set(problem.values())
        self.out: list[CrossCheck] = []
        self.newton: dict[str, CrossCheck] = {}
        self.freq: dict[tuple, CrossCheck] = {}
        self.measured: dict[tuple, CrossCheck] = {}
        self.models: dict = {}  # compiled nonlinear models, shared by the simulations

    def newton_per_system(self) -> None:
        for name in self.systems:
            self.stage(f"cross-check newton:{name}")
            x = CrossCheck(f"newton:{name}", "newton", name)
            with guarded(x, unsupported=Status.ERROR):  # the system could not be built
                x = newton_crosscheck(self.analysis, name)
            self.newton[name] = x

    def part(self, part: Part) -> None:
        """The checks that vouch for one answer part."""
        sname = part.system or self.only
        vouch = crosschecks_of(part.quantity)  # the names its registration declares
        if "newton" in vouch and sname in self.newton:
            self.newton[sname].parts.append(part.name)
        if "first_integrals" in vouch or "energy_integral" in vouch:
            self.stage(f"cross-check conserved:{part.name}")
            x = conserved_part(self.analysis, part, self.models)
            if x is not None:
                self.out.append(x)
        if "steady" in vouch:
            tag = (sname, "steady", repr(part.data.get("about")), part.data.get("unknown"),
                   repr(part.data.get("hold")), repr(part.data.get("assume")),
                   repr(part.data.get("estimate")))
            self._shared(tag, part, "steady", steady_crosscheck)
        if "trajectory" in vouch:
            tag = (sname, part.quantity, repr(part.data.get("initial")),
                   part.data.get("coordinate"), part.data.get("rate"))
            self._shared(tag, part, "measured", trajectory_crosscheck)
        if "modes" in vouch:
            self._modes(part, sname, vouch)

    def _shared(self, tag: tuple, part: Part, what: str,
                check: Callable[[Analysis, Part], CrossCheck]) -> None:
        """A simulation that parts asking the same question share."""
        if tag in self.measured:
            self.measured[tag].parts.append(part.name)
            return
        self.stage(f"cross-check {what}:{part.name}")
        self.measured[tag] = check(self.analysis, part)
        self.out.append(self.measured[tag])

    def _modes(self, part: Part, sname: str | None, vouch: tuple[str, ...]) -> None:
        """The frequencies at the part's point (and the driven response there)."""
        x = CrossCheck(f"modes:{sname}", "frequencies", sname or "", parts=[part.name])
        values = None
        with guarded(x, reason="no linear system: "):  # the part's own check reports it too
            view = PartView(self.analysis, part)
            lin = view.linear()
            values = view.values()
        if values is None:  # n.a. or error, with the reason
            self.freq[(sname, str(x.status), part.name)] = x
            return
        if "response" in vouch:
            self.stage(f"cross-check response:{part.name}")
            self.out.append(response_part(self.analysis, view, lin, values, self.models))
        label = point_label(lin)
        tag = (sname, *numeric_key(lin, values, self.params))
        if tag not in self.freq:
            self.stage(f"cross-check modes:{sname}@{label}")
            self.freq[tag] = _modes_check(self.analysis, lin, values,
                                                  f"modes:{sname}@{label}", self.models)
        self.freq[tag].parts.append(part.name)

    def engine_equilibria(self) -> None:
        """The frequencies about the engine's own stable equilibria not checked yet."""
        problem = self.analysis.problem
        for name in self.systems:
            self.stage(f"cross-check: the engine's own equilibria of {name}")
            x = CrossCheck(f"modes:{name}", "frequencies", name)
            found = None
            with guarded(x, unsupported=Status.ERROR):  # reported, never hidden
                found = engine_linear_systems(self.analysis, name, self.freq)
            if found is None:
                self.freq[(name, "engine-error")] = x
                continue
            for lin, label in found:
                values = dict(problem.values())
                tag = (name, *numeric_key(lin, values, self.params))
                if tag not in self.freq:
                    self.stage(f"cross-check modes:{name}@{label}")
                    self.freq[tag] = _modes_check(self.analysis, lin, values,
                                                          f"modes:{name}@{label}", self.models)
