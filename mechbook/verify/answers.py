"""Answer keys: the book's answers, part by part, kept apart from the problem files.

An answer key names, for each part, the quantity it checks and the book's value, in the
problem's own symbols plus any symbols of its own (`symbols:`, e.g. integration constants or
the names of normal coordinates) and abbreviations (`abbreviations: {omega0: sqrt(g/l)}`).
"""

from __future__ import annotations

from pathlib import Path

import sympy as sp

from mechbook.model.input_limits import check_answer_counts
from mechbook.model.schema import validate
from mechbook.model.yamlio import Document, load
from mechbook.verify.part import Part
from mechbook.verify.registry import answers_schema  # importing it registers the quantities

__all__ = ["AnswerKey", "Part", "load_answers"]


class AnswerKey:
    def __init__(self, doc: Document):
        self.doc = doc
        self.file = doc.file
        data = doc.data
        self.problem_id: str = data["problem"]
        self.symbols: dict[str, sp.Symbol] = {}
        self.symbol_values: dict[sp.Symbol, float] = {}
        for name, spec in (data.get("symbols") or {}).items():
            spec = spec or {}
            positive = spec.get("positive", True)
            sym = sp.Symbol(name, positive=True) if positive else sp.Symbol(name, real=True)
            self.symbols[name] = sym
            self.symbol_values[sym] = float(spec.get("value", 1.0))
        self.parts = [Part(self, i, p) for i, p in enumerate(data["parts"])]
        seen = set()
        for p in self.parts:
            if p.name in seen:
                raise p.error(("part",), f"part {p.name!r} appears twice")
            seen.add(p.name)


def load_answers(path: str | Path) -> AnswerKey:
    doc = load(path)
    validate(doc, answers_schema())
    check_answer_counts(doc)
    return AnswerKey(doc)
