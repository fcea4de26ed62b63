"""One part of an answer key, as plain data: a module of its own so that the checks'
context imports it without the key loader (which imports every check)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import sympy as sp

from mechbook.errors import ExpressionError
from mechbook.model.expr import parse, parse_equation
from mechbook.model.tensorexpr import parse_tensor
from mechbook.verify.registration import QUANTITIES

if TYPE_CHECKING:
    from mechbook.verify.answers import AnswerKey


@dataclass
class Part:
    """One part of an answer key: its data, names and parsing (plain data, under the checks)."""

    key: AnswerKey
    index: int
    data: dict
    _unavailable: dict = field(default_factory=dict, repr=False)  # abbreviation -> why

    @property
    def name(self) -> str:
        return self.data["part"]

    @property
    def quantity(self) -> str:
        return self.data["quantity"]

    @property
    def system(self) -> str | None:
        return self.data.get("system")

    @property
    def path(self) -> tuple:
        return ("parts", self.index)

    def error(self, sub: tuple, message: str):
        return self.key.doc.error(self.path + sub, message)

    def names(self, base: dict, tensor: bool = False,
              bodies: dict | None = None) -> dict[str, sp.Basic]:
        """The names this part may use: `base` (a system's, or the problem's declared
        ones), the key's symbols and its abbreviations (tensor expressions, which may name
        the problem's `bodies`, if `tensor`)."""
        names = dict(base)
        for sym in self.key.symbols:
            if sym in names:
                raise self.key.doc.error(("symbols", sym), f"{sym!r} is already a name of the "
                                         "problem (a parameter, coordinate or rate)")
        names.update(self.key.symbols)
        for abbr, text in (self.key.doc.data.get("abbreviations") or {}).items():
            if abbr in names:
                raise self.key.doc.error(("abbreviations", abbr), f"{abbr!r} is already a name")
            try:
                names[abbr] = parse_tensor(text, names, bodies or {}) if tensor \
                    else parse(text, names)
            except ExpressionError as exc:
                # An abbreviation may belong to another of the problem's systems (it names
                # that system's coordinates): it is simply not available in this one, and a
                # part that uses it here is told why (the first abbreviation of a chain that
                # failed, with its own reason).
                used = re.search(r"unknown name '(\w+)'", str(exc))
                self._unavailable[abbr] = self._unavailable.get(used.group(1) if used else "",
                                                                str(exc))
        return names

    def parse(self, text, sub: tuple, names: dict, equation: bool = False,
              relation: bool = False) -> sp.Basic:
        known = QUANTITIES.get(self.quantity)
        complex_ok = bool(known and known.complex_values)  # exponents, complex modes
        try:
            if equation:
                return parse_equation(text, names, complex_ok)
            return parse(text, names, relation, complex_ok)
        except ExpressionError as exc:
            message = str(exc)
            for abbr, why in self._unavailable.items():
                if f"unknown name {abbr!r}" in message:
                    message += f" (abbreviation {abbr!r} does not parse here: {why})"
            raise self.error(sub, message) from None
