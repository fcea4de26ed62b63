"""Strings made safe for each output: HDF5, JSON, XML and a terminal.

Text from problem files is validated when it is read (mechbook.model.input_limits.check_text: no
NUL, no lone surrogate, no control character but tab and newline), so these functions change
nothing a valid file holds. They are the second line: a store written by an older version,
an exception's message, or a value that reached an output by another road can still never
crash a write (HDF5 refuses NUL, UTF-8 refuses surrogates), make an XML document malformed,
or send escape sequences to a terminal.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mechbook.app.bounded import JSON

# C0 and C1 controls but tab and newline, DEL, and the bidirectional overrides and isolates
# (they reorder what a terminal shows)
_TERMINAL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")
# what XML 1.0 does not allow in a document at all
_XML = re.compile(r"[^\x09\x0a\x0d\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")
_SURROGATE = re.compile(r"[\ud800-\udfff]")


def _escape(match: re.Match) -> str:
    code = ord(match.group())
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def unicode_safe(text: str) -> str:
    """`text` with lone surrogates written as `\\udxxx` (they cannot be encoded as UTF-8)."""
    return _SURROGATE.sub(_escape, text)


def storable(text: str) -> str:
    """`text` as an HDF5 string can hold it: no NUL, no lone surrogate."""
    return unicode_safe(text).replace("\x00", "\\x00")


def for_terminal(text: str) -> str:
    """`text` to print: control characters (escape sequences) and bidi overrides shown as
    escapes, lone surrogates too; tabs and newlines kept."""
    return _TERMINAL.sub(_escape, unicode_safe(str(text)))


def for_xml(text: str) -> str:
    """`text` as XML 1.0 can hold it: characters it forbids written as escapes."""
    return _XML.sub(_escape, str(text))


def json_safe(value: JSON) -> JSON:
    """A JSON-able value with every string made encodable (lone surrogates escaped)."""
    if isinstance(value, str):
        return unicode_safe(value)
    if isinstance(value, dict):
        return {json_safe(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v) for v in value]
    return value
