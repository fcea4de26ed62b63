"""Checking one problem: load, check its parts, cross-check, and return plain data.

`run_problem` is what a batch worker runs (mechbook/batch.py); everything it returns is plain
data (no SymPy objects), so it crosses process boundaries, and it reports the stage it is in
through `stage`, so a problem stopped by the time limit says where it was.

Nothing is derived that no part asks for: the checks pull what they need from a lazy
`Analysis` (unsimplified: simplification is for a human reader, `mechbook solve`), and the
store keeps what the run happened to derive, as text (`derive.computed`). Trouble in a stage
no part asked for (the engine's own equilibria, loose cross-checks, the stored summary) is
reported beside the parts and never takes them down.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from mechbook.app.fingerprint import file_sha256
from mechbook.app.running.quiet import warnings_as_notes
from mechbook.app.store import ProblemRecord, cached
from mechbook.errors import FAULTS, MechbookError, describe
from mechbook.model.catalog import answer_path, problem_path
from mechbook.records import NUMERIC, Outcome, ProofPolicy, Status

if TYPE_CHECKING:
    from mechbook.model.problem import Problem

Stage = Callable[[str], None]


def _quiet(_: str) -> None:
    pass


@dataclass
class ProblemRun:
    """The outcome of checking one problem, as plain data."""

    pid: str
    outcomes: list[Outcome] = field(default_factory=list)
    error: str | None = None
    seconds: float = 0.0
    record: ProblemRecord | None = None
    cached: bool = False
    crosschecks: list = field(default_factory=list)  # CrossCheck
    notes: list[str] = field(default_factory=list)  # trouble beside the parts
    stage: str = ""  # the last stage reached (for a problem stopped from outside)
    debug: list[str] = field(default_factory=list)  # tracebacks of unexpected errors (-v)


@dataclass(frozen=True)
class RunOptions:
    """How a batch checks its problems (the same for every problem of the batch)."""

    crosscheck: bool = True
    policy: ProofPolicy = NUMERIC


def run_problem(pid: str, base: Path, options: RunOptions = RunOptions(),
                stage: Stage = _quiet, problem: Problem | None = None) -> ProblemRun:
    """Check one problem against its answer key (and cross-check it), from scratch.
    `problem`: the problem file already loaded (the Python API's), checked by an Analysis
    of its own, so what the run stores is what this check derived."""
    start = time.perf_counter()
    run = ProblemRun(pid)
    reached = [""]

    def staged(text: str) -> None:
        reached[0] = text
        stage(text)

    # a NumPy or SymPy warning becomes a note naming the stage (the part) it arose in
    with _tracebacks(run.debug), warnings_as_notes(run.notes, lambda: reached[0]):
        _check(run, pid, base, options, staged, start, problem)
    run.seconds = time.perf_counter() - start
    return run


class _Collect(logging.Handler):
    def __init__(self, into: list[str]):
        super().__init__(logging.DEBUG)
        self.into = into

    def emit(self, record: logging.LogRecord) -> None:
        self.into.append(self.format(record))


@contextmanager
def _tracebacks(into: list[str]) -> Iterator[None]:
    """Collect the tracebacks of unexpected errors (mechbook.errors.describe logs them) into
    `into`: they travel with the run's plain data and `check -v` prints them; the details
    keep only the message."""
    logger = logging.getLogger(FAULTS)
    handler = _Collect(into)
    saved = logger.level, logger.propagate
    logger.addHandler(handler)
    logger.setLevel(logging.DEBUG)
    logger.propagate = False
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(saved[0])
        logger.propagate = saved[1]


def _check(run: ProblemRun, pid: str, base: Path, options: RunOptions, stage: Stage,
           start: float, loaded: Problem | None = None) -> None:
    # the engine and the checks, imported here only: a warm `mechbook check` answers from
    # the store (cached_runs) without loading them (docs/performance.md, warm check)
    from mechbook.app.authoring.validate import validated_parts
    from mechbook.crosscheck import crosscheck_problem
    from mechbook.engine.analysis import Analysis
    from mechbook.engine.derive import computed
    from mechbook.model.problem import load_problem
    from mechbook.verify.answers import load_answers
    from mechbook.verify.checker import check_problem, require_same_problem

    try:
        stage("loading")
        problem = loaded if loaded is not None else load_problem(problem_path(pid, base))
        apath = answer_path(pid, base)
        if not apath.exists():
            raise MechbookError(f"{apath}: no answer key for {pid}")
        key = load_answers(apath)
        require_same_problem(key, problem.id)  # before its parts are read in the problem
        analysis = Analysis(problem)
        stage("validating")  # a malformed file is refused whole: nothing is stored for it
        faults = validated_parts(problem, key, analysis, apath)  # under validate's limit
        if faults:  # each malformed part says where; the others are not checked
            run.outcomes = [Outcome(problem.id, p.name, p.quantity, p.data["cite"], Status.ERROR,
                                    detail=faults[p.name], origin=p.data.get("origin", "book"))
                            for p in key.parts if p.name in faults]
            run.notes.append("the answer key is malformed: its other parts were not checked "
                             "and nothing was stored")
            return
        run.outcomes = check_problem(analysis, key, options.policy, stage)
        if options.crosscheck:
            stage("cross-checks")
            run.crosschecks = crosscheck_problem(analysis, key, stage)
        stage("storing the derived results")
        try:
            results = computed(analysis)
        except Exception as exc:  # noqa: BLE001 - the summary must not take down the parts
            results = []
            run.notes.append(f"derived results not stored: {describe(exc)}")
        run.seconds = time.perf_counter() - start
        run.record = ProblemRecord.of(problem, results, run.outcomes, run.seconds,
                                      file_sha256(apath),
                                      [c.as_dict() for c in run.crosschecks])
    except MechbookError as exc:
        run.error = str(exc)
    except Exception as exc:  # noqa: BLE001 - one problem's fault must not end the batch
        run.error = describe(exc)


def cached_runs(ids: list[str], base: Path, store: Path,
                crosscheck: bool = True) -> dict[str, ProblemRun]:
    """The problems whose stored results are still valid (problem file, answer key and
    engine unchanged): answered from the store without loading the engine."""
    wanted = {}
    for pid in ids:
        try:
            ppath, apath = problem_path(pid, base), answer_path(pid, base)
            if ppath.exists() and apath.exists():
                wanted[pid] = (file_sha256(ppath), file_sha256(apath))
        except MechbookError:
            continue  # not a cache hit: the check itself reports what is wrong
    out = {}
    for pid, hit in cached(wanted, store, crosscheck).items():
        out[pid] = ProblemRun(pid, hit.outcomes, seconds=hit.duration, cached=True,
                              crosschecks=hit.crosschecks)
    return out
