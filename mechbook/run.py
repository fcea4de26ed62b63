"""A check run over many problems: load, derive, check, store; with progress reporting."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from .analysis import Analysis
from .answers import load_answers
from .catalog import answer_path, problem_path
from .checker import Outcome, check_problem
from .crosscheck import CrossCheck, crosscheck_problem
from .derive import Results, derive
from .errors import MechbookError, UnsupportedError
from .fingerprint import file_sha256
from .problem import load_problem
from .store import ProblemRecord, cached_crosschecks, cached_outcomes


@dataclass
class ProblemRun:
    pid: str
    outcomes: list[Outcome] = field(default_factory=list)
    results: list[Results] = field(default_factory=list)
    error: str | None = None
    seconds: float = 0.0
    record: ProblemRecord | None = None
    cached: bool = False
    crosschecks: list[CrossCheck] = field(default_factory=list)


def run_problem(pid: str, base: Path, simplify: bool = True,
                cache: Path | None = None, crosscheck: bool = True) -> ProblemRun:
    """Check one problem; with `cache`, reuse stored outcomes whose content hashes match.
    With `crosscheck`, also run the independent cross-checks (mechbook/crosscheck.py)."""
    start = time.perf_counter()
    run = ProblemRun(pid)
    try:
        problem = load_problem(problem_path(pid, base))
        apath = answer_path(pid, base)
        if not apath.exists():
            raise MechbookError(f"{apath}: no answer key for {pid}")
        key = load_answers(apath)
        answers_sha = file_sha256(apath)
        if cache is not None:
            stored = cached_outcomes(pid, problem.sha256, answers_sha, cache)
            crossed = cached_crosschecks(pid, cache) if crosscheck else []
            if stored is not None and (crossed or not crosscheck):
                run.outcomes, run.cached = stored, True
                run.crosschecks = [CrossCheck.from_dict(d) for d in crossed]
                run.seconds = time.perf_counter() - start
                return run
        analysis = Analysis(problem, simplify)
        run.outcomes = check_problem(analysis, key)
        for name in problem.systems:
            try:
                run.results.append(derive(analysis, name))
            except UnsupportedError as exc:
                res = Results(name)
                res.notes["derive"] = f"unsupported: {exc.capability}"
                run.results.append(res)
        if crosscheck:
            run.crosschecks = crosscheck_problem(analysis, key)
        run.seconds = time.perf_counter() - start
        run.record = ProblemRecord(problem, run.results, run.outcomes, run.seconds, answers_sha,
                                   [c.as_dict() for c in run.crosschecks])
    except MechbookError as exc:
        run.error = str(exc)
        run.seconds = time.perf_counter() - start
    return run


def run_many(ids: list[str], base: Path, simplify: bool = True,
             progress: Callable[[int, int, ProblemRun], None] | None = None,
             cache: Path | None = None, crosscheck: bool = True) -> list[ProblemRun]:
    runs = []
    for i, pid in enumerate(ids, 1):
        run = run_problem(pid, base, simplify, cache, crosscheck)
        runs.append(run)
        if progress:
            progress(i, len(ids), run)
    return runs
