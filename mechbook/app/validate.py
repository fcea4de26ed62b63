"""`mechbook validate`: a file is checked against its schema and every expression parsed,
without deriving anything."""

from __future__ import annotations

from pathlib import Path

from mechbook.engine.analysis import Analysis
from mechbook.errors import MechbookError
from mechbook.model.catalog import problem_path, root
from mechbook.model.problem import load_problem
from mechbook.model.system import system_of
from mechbook.model.yamlio import load
from mechbook.verify.answers import load_answers
from mechbook.verify.context import Context, strip_const
from mechbook.verify.registry import quantities


def validate_file(path: str | Path) -> str:
    """Validate a problem or an answer file; return a one-line summary or raise SpecError."""
    path = Path(path)
    doc = load(path)
    if isinstance(doc.data, dict) and "parts" in doc.data:
        return _validate_answers(path)
    problem = load_problem(path)
    for name in problem.systems:
        system_of(problem, name)
    return f"{path}: problem {problem.id} is valid ({len(problem.systems)} system(s))"


def _validate_answers(path: Path) -> str:
    key = load_answers(path)
    try:
        base = root(path.parent)
    except MechbookError:
        base = path.resolve().parents[2]
    problem = load_problem(problem_path(key.problem_id, base))
    analysis = Analysis(problem)
    for part in key.parts:
        ctx = Context(analysis, part)
        q = quantities()[part.quantity]
        names = q.names(ctx) if q.names else ctx.names
        for field in ("book", "about", "initial", "released", "region", "time"):
            if field == "book" and part.data.get("book") in q.literals:
                continue
            if field in part.data:
                _walk(ctx, part.data[field], (field,), names if field == "book" else ctx.names)
        if "erratum" in part.data:
            _walk(ctx, part.data["erratum"]["corrected"], ("erratum", "corrected"), names)
    return f"{path}: answer key for {key.problem_id} is valid ({len(key.parts)} parts)"


def _walk(ctx: Context, value, sub: tuple, names: dict) -> None:
    if isinstance(value, dict):
        for k, v in value.items():
            _walk(ctx, v, sub + (k,), names)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            _walk(ctx, v, sub + (i,), names)
    elif isinstance(value, str):
        value = strip_const(value)  # a first integral may be written "... = constant"
        if "<" in value or ">" in value:
            ctx.part.parse(value, sub, names, relation=True)
        else:
            ctx.part.parse(value, sub, names, equation=True)
