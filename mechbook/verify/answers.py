"""Answer keys: the book's answers, part by part, kept apart from the problem files.

An answer key names, for each part, the quantity it checks and the book's value, in the
problem's own symbols plus any symbols of its own (`symbols:`, e.g. integration constants or
the names of normal coordinates) and abbreviations (`abbreviations: {omega0: sqrt(g/l)}`).
A key is read against a table of quantities (the built-in one unless a caller passes its
own): its schema allows exactly that table's quantities and their keys.
"""

from __future__ import annotations

from pathlib import Path

from mechbook.model.input_limits import check_answer_counts
from mechbook.model.schema import validate
from mechbook.model.yamlio import load
from mechbook.verify.part import AnswerKey, Part
from mechbook.verify.registration import QuantityTable
from mechbook.verify.registry import answers_schema, default_quantities

__all__ = ["AnswerKey", "Part", "load_answers"]


def load_answers(path: str | Path, quantities: QuantityTable | None = None) -> AnswerKey:
    """The answer key at `path`, validated against the schema of `quantities` (default: the
    built-in table); SpecError (file:line) if it does not conform."""
    table = default_quantities() if quantities is None else quantities
    doc = load(path)
    validate(doc, answers_schema(table))
    check_answer_counts(doc)
    return AnswerKey(doc, table)
