"""Which cross-checks vouch for a part: the names its quantity's registration declares
(each a name of mechbook.crosscheck.problem.CROSSCHECKS, which says what runs it)."""

from __future__ import annotations

from mechbook.verify.registry import default_quantities


def crosschecks_of(quantity: str) -> tuple[str, ...]:
    """The cross-checks the registration of `quantity` declares (none for an unknown one)."""
    entry = default_quantities().get(quantity)
    return entry.crosschecks if entry is not None else ()
