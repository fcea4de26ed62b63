"""`mechbook validate`: a file is checked against its schema and every expression parsed,
without deriving anything. This module orchestrates (which file, its problem, the time
limit); whether a key is well formed is decided by mechbook.verify.wellformed.

A problem file needs only the model (YAML, schema, the safe parser, the systems built from
their declarations), so the engine and the answer quantities are imported only for an answer
key, whose expressions are parsed in their part's context: an author's validation answers in
well under a second.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from mechbook.core.timeout import Timeout, hard_time_limit
from mechbook.core.words import plural
from mechbook.errors import MechbookError, SpecError
from mechbook.model.built import Built
from mechbook.model.catalog import problem_path, root
from mechbook.model.physical import check_physical
from mechbook.model.problem import Problem, load_problem
from mechbook.model.yamlio import load

if TYPE_CHECKING:
    from mechbook.engine.analysis import Analysis
    from mechbook.verify.answers import AnswerKey

BUILD_SECONDS = 15.0  # CPU; `validate` runs in the caller's process, so it bounds itself


def validate_file(path: str | Path) -> str:
    """Validate a problem or an answer file; return a one-line summary or raise SpecError."""
    path = Path(path)
    doc = load(path)
    if isinstance(doc.data, dict) and "parts" in doc.data:
        return _validate_answers(path)
    problem = load_problem(path)
    with build_limit(path):
        built = build_systems(problem)
    decl = built.declared()
    return (f"{path}: problem {problem.id} is valid ({len(problem.systems)} system(s), "
            f"{len(decl.vectors)} vector(s), {len(decl.tensors)} tensor(s), "
            f"{len(decl.bodies)} body(ies))")


def _validate_answers(path: Path) -> str:
    # the engine and the quantities: imported only for an answer key (start-up of validate)
    from mechbook.engine.analysis import Analysis
    from mechbook.verify.answers import load_answers
    from mechbook.verify.wellformed import validate_key

    key = load_answers(path)
    try:
        base = root(path.parent)
    except MechbookError:
        base = path.resolve().parents[2]
    try:
        ppath = problem_path(key.problem_id, base)
    except MechbookError as exc:
        raise key.doc.error(("problem",), str(exc)) from None
    try:
        problem = load_problem(ppath)
        with build_limit(ppath, path):  # its problem's systems are built on the way
            faults = validate_key(Analysis(problem), key)
            if faults:  # the first malformed part, at its file:line
                raise next(iter(faults.values()))
    except SpecError as exc:
        if exc.file is None or Path(exc.file).resolve() != ppath.resolve():
            raise
        err = SpecError(f"its problem file is invalid: {exc}", str(path))
        err.problem_file = str(ppath)  # the command line says so once per file
        raise err from None
    return f"{path}: answer key for {key.problem_id} is valid ({plural(len(key.parts), 'part')})"


@contextmanager
def build_limit(path: str | Path, key: str | Path | None = None) -> Iterator[None]:
    """BUILD_SECONDS of CPU time for building a problem's systems (and parsing its answer
    key's expressions, with `key`): past it, a SpecError naming the file."""
    try:
        with hard_time_limit(BUILD_SECONDS):
            yield
    except Timeout:
        raise _too_slow(path, key) from None


def _too_slow(path: str | Path, key: str | Path | None) -> SpecError:
    if key is None:
        return SpecError(f"building the problem's systems took more than {BUILD_SECONDS:g} s "
                         "of CPU time (the book's problems take under 1 s): an expression is "
                         "too large or too deep for the engine", str(path))
    return SpecError(f"checking the answer key's expressions (and building its problem "
                     f"{Path(path).name}) took more than {BUILD_SECONDS:g} s of CPU time (the "
                     "book's take under 1 s): an expression is too large or too deep for the "
                     "engine", str(key))


def validated_parts(problem: Problem, key: AnswerKey, analysis: Analysis,
                    key_path: str | Path) -> dict[str, str]:
    """What `mechbook check` validates before any part (every system built, every part's
    names and expressions: mechbook.verify.wellformed.validate_key, {part name: its fault}),
    under the limit `validate` has for the same work:
    a problem that `validate` refuses in BUILD_SECONDS is refused by the check as soon, not
    after its whole --timeout. SpecError (naming the file it was in) past the limit."""
    from mechbook.verify.wellformed import validate_key  # the quantities: only for a key

    blame: list = [problem.doc.file, None]
    try:
        with hard_time_limit(BUILD_SECONDS):
            build_systems(problem, analysis.built)  # kept for the check's parts
            blame[1] = key_path
            return {name: str(fault) for name, fault in validate_key(analysis, key).items()}
    except Timeout:
        raise _too_slow(*blame) from None


def build_systems(problem: Problem, built: Built | None = None) -> Built:
    """Build every system of a problem (each expression parsed) and refuse one that is not
    physical (a mass not positive, a kinetic energy not positive definite); SpecError on
    the first fault. The systems are kept by `built` (an Analysis's, for its check), or by
    a new Built, returned."""
    built = built if built is not None else Built(problem)
    for name in problem.systems:
        check_physical(built.system(name))
    return built
