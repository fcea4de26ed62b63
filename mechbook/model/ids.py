"""Problem ids `<book>-<number>`: the one grammar every id is checked against.

A book id is a lower-case letter, then lower-case letters and digits (at most 40 in all); the
number is letters and digits with single '.', '_' or '-' between them (at most 80
characters), joined by the first '-'. Nothing in an id can name a path outside the tree: no
'/', no '..', nothing absolute. The problem schema's `id` pattern, books.yaml's examples,
the catalog's file paths and a problem file's own id all use this grammar (mechbook.model
.schema fills the pattern in from here), so an id is accepted or refused the same way
everywhere.
"""

from __future__ import annotations

import re

from mechbook.errors import MalformedIdError

BOOK = r"[a-z][a-z0-9]{0,39}"
# The length limit is a lookahead that ends where the id's characters end, not at `\Z`: the
# pattern is copied into the problem schema, and editors' validators (ECMA-262 regexes, as
# JSON Schema specifies) know no `\Z`.
NUMBER = r"(?=[A-Za-z0-9._-]{1,80}(?![A-Za-z0-9._-]))[A-Za-z0-9]+(?:[._-][A-Za-z0-9]+)*"
PATTERN = rf"({BOOK})-({NUMBER})"
ID = re.compile(PATTERN)
EXAMPLES = "e.g. lim-2031 or symon-09-12"


def split_id(pid: object) -> tuple[str, str]:
    """'lim-2031' -> ('lim', '2031'); 'symon-09-12' -> ('symon', '09-12'); MechbookError
    for anything that is not a well-formed id."""
    m = ID.fullmatch(pid) if isinstance(pid, str) else None
    if m is None:
        raise MalformedIdError(f"bad problem id {pid!r} (expected <book>-<number>, {EXAMPLES}: "
                            "a book of lower-case letters and digits, a number of letters "
                            "and digits with single '.', '_' or '-' between them)")
    return m.group(1), m.group(2)


def check_id(pid: object) -> str:
    """`pid` if it is a well-formed problem id; MechbookError otherwise."""
    split_id(pid)
    return pid  # type: ignore[return-value]
