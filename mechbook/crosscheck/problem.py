"""Every cross-check of one problem: which run, for which answer parts, in what order.

Newton per system; per answer part, the checks its quantity's registration declares
(vouch.py), each the entry of its name in CROSSCHECKS: a first integral along a run, steady
motions and trajectories measured, the driven response, and the frequencies at the part's
point (points.py: one simulation per distinct point); then the frequencies about the
engine's own stable equilibria, and the declared bodies' inertia. Each check runs under the
one guard (guard.py): a fault in one never hides the others.

Adding a cross-check of a part: a module of mechbook/crosscheck with its function
`check(analysis, part, models) -> CrossCheck | None`, and one entry in CROSSCHECKS,
`"name": PartCheck("what it checks", each_part(check, "name"))`; a quantity's
registration then names it in `crosschecks=`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from mechbook.crosscheck.brackets import bracket_part, new_hamiltonian_part
from mechbook.crosscheck.conserved import conserved_part
from mechbook.crosscheck.frequencies import frequency_crosscheck
from mechbook.crosscheck.guard import guarded
from mechbook.crosscheck.inertia import inertia_crosschecks
from mechbook.crosscheck.newton import newton_crosscheck
from mechbook.crosscheck.partview import PartView
from mechbook.crosscheck.points import engine_linear_systems, numeric_key, point_label
from mechbook.crosscheck.response import response_part
from mechbook.crosscheck.scattering import scattering_crosscheck
from mechbook.crosscheck.simulated_motion import steady_crosscheck, trajectory_crosscheck
from mechbook.crosscheck.spectral import spectral_part
from mechbook.crosscheck.state_modes import state_frequency_crosscheck
from mechbook.crosscheck.vouch import crosschecks_of
from mechbook.engine.analysis import Analysis
from mechbook.records import CrossCheck, Status
from mechbook.verify.answers import AnswerKey, Part


def modes_check(analysis: Analysis, lin, values: dict, name: str, models: dict) -> CrossCheck:
    """The simulated-modes cross-check of a linear system: second order
    (mechbook.crosscheck.frequencies) or first order (mechbook.crosscheck.state_modes)."""
    if not lin.first_order:
        return frequency_crosscheck(analysis, lin, values, name, models)
    out = CrossCheck(name, "frequencies", lin.dyn.sys.full.name)
    with guarded(out):
        state_frequency_crosscheck(analysis, lin, values, out, models)
    return out


Runner = Callable[["_ProblemChecks", Part, "str | None", tuple[str, ...]], None]


@dataclass(frozen=True)
class PartCheck:
    """A cross-check an answer part's registration may name (`crosschecks=`): what it
    checks, and what runs it for a part, given the problem's checks so far, the part, its
    system and every name its registration declares (None: a name that changes what
    another check measures, which that check reads)."""

    doc: str
    run: Runner | None = None


def each_part(check: Callable[[Analysis, Part, dict], CrossCheck | None], what: str) -> Runner:
    """Run `check(analysis, part, models)` for each part that names it; list its result
    (None: nothing to check)."""
    def run(checks: _ProblemChecks, part: Part, system: str | None,
            vouch: tuple[str, ...]) -> None:
        checks.stage(f"cross-check {what}:{part.name}")
        x = check(checks.analysis, part, checks.models)
        if x is not None:
            checks.out.append(x)

    return run


def _shared_by(question: Callable[[Part, str | None], tuple], what: str,
               check: Callable[[Analysis, Part], CrossCheck]) -> Runner:
    """A simulation that parts asking the same `question(part, system)` share."""
    def run(checks: _ProblemChecks, part: Part, system: str | None,
            vouch: tuple[str, ...]) -> None:
        checks.shared(question(part, system), part, what, check)

    return run


def _newton(checks: _ProblemChecks, part: Part, system: str | None,
            vouch: tuple[str, ...]) -> None:
    """The part listed under its system's Newton check (run once per system, first)."""
    if system in checks.newton:
        checks.newton[system].parts.append(part.name)


def _modes(checks: _ProblemChecks, part: Part, system: str | None,
           vouch: tuple[str, ...]) -> None:
    checks.modes(part, system, vouch)


def _steady_question(part: Part, system: str | None) -> tuple:
    data = part.data
    return (system, "steady", repr(data.get("about")), data.get("unknown"),
            repr(data.get("hold")), repr(data.get("assume")), repr(data.get("estimate")))


def _trajectory_question(part: Part, system: str | None) -> tuple:
    data = part.data
    return (system, part.quantity, repr(data.get("initial")), data.get("coordinate"),
            data.get("rate"))


def _orbit_question(part: Part, system: str | None) -> tuple:
    data = part.data
    return (system, "orbit", repr(data.get("impact_parameter")), repr(data.get("energy")),
            repr(data.get("hard_core")), data.get("coordinate"), repr(data.get("assume")),
            repr(data.get("restrict")))


_conserved = each_part(conserved_part, "conserved")

# every name a registration's `crosschecks=` may hold, run for a part in this order (a check
# two names lead to, once)
CROSSCHECKS: dict[str, PartCheck] = {
    "newton": PartCheck("the system's equations against Newton's and Euler's laws "
                        "(newton.py)", _newton),
    "first_integrals": PartCheck("the named first integrals constant along a run "
                                 "(conserved.py)", _conserved),
    "energy_integral": PartCheck("the part's energy function or Hamiltonian constant along "
                                 "a run", _conserved),
    "steady": PartCheck("each steady rate kept by a simulation of the full equations "
                        "(motion.py)", _shared_by(_steady_question, "steady", steady_crosscheck)),
    "trajectory": PartCheck("the turning points of the level set measured by integration "
                            "(motion.py)",
                            _shared_by(_trajectory_question, "measured", trajectory_crosscheck)),
    "trajectory_period": PartCheck("with `trajectory`: the period measured too"),
    "trajectory_advance": PartCheck("with `trajectory`: a coordinate's advance per period "
                                    "measured too"),
    "modes": PartCheck("the frequencies at the part's point measured by simulation "
                       "(frequencies.py)", _modes),
    "response": PartCheck("with `modes`: the steady amplitude measured from the driven "
                          "motion (response.py)"),
    "bracket_flow": PartCheck("a bracket with H against the rate of change along a run, from "
                              "Lagrange's equations (brackets.py)",
                              each_part(bracket_part, "bracket_flow")),
    "new_hamiltonian": PartCheck("a canonical map's new variables moving by the book's K "
                                 "along a run, from Lagrange's equations (brackets.py)",
                                 each_part(new_hamiltonian_part, "new_hamiltonian")),
    "scattering": PartCheck("the orbit from infinity integrated far out and its asymptote "
                            "fitted: deflection and closest approach (scattering.py)",
                            _shared_by(_orbit_question, "asymptote", scattering_crosscheck)),
    "spectral": PartCheck("a field's frequencies by a spectral discretization that does "
                          "not separate (spectral.py)", each_part(spectral_part, "spectral")),
}


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
        """The checks that vouch for one answer part: those its registration names."""
        system = part.system or self.only
        vouch = crosschecks_of(part.quantity)  # the names its registration declares
        ran: list[Runner] = []
        for name, check in CROSSCHECKS.items():
            if name in vouch and check.run is not None and check.run not in ran:
                ran.append(check.run)
                check.run(self, part, system, vouch)

    def shared(self, tag: tuple, part: Part, what: str,
               check: Callable[[Analysis, Part], CrossCheck]) -> None:
        """A simulation that parts asking the same question share."""
        if tag in self.measured:
            self.measured[tag].parts.append(part.name)
            return
        self.stage(f"cross-check {what}:{part.name}")
        self.measured[tag] = check(self.analysis, part)
        self.out.append(self.measured[tag])

    def modes(self, part: Part, sname: str | None, vouch: tuple[str, ...]) -> None:
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
            self.freq[tag] = modes_check(self.analysis, lin, values,
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
                    self.freq[tag] = modes_check(self.analysis, lin, values,
                                                          f"modes:{name}@{label}", self.models)
