"""The one guard of every cross-check: what its outcome is when its work raises.

    with guarded(record):
        ...  # the check's work, which sets record.status, .error, .detail

* finished: the outcome the work set;
* UnsupportedError: n.a. — the check does not apply here; the detail is the missing
  capability (after `reason`, when given). Where the check cannot be said not to apply
  (the inertia of a declared body, the search for the engine's own equilibria, reading a
  part's driving frequency), `unsupported=Status.ERROR` makes it an error;
* any other exception: error — the check itself could not run (it counts as a fail), and a
  fault here never hides the other checks. The detail is `mechbook.errors.describe`: a
  MechbookError's own message, anything else as its type and message (its traceback goes
  to the debug log, `mechbook check -v`).

A time limit (`mechbook.core.timeout.Timeout`, a BaseException) passes through. The
record's `seconds` is the time spent in the block.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager

from mechbook.errors import UnsupportedError, describe
from mechbook.records import CrossCheck, Status


@contextmanager
def guarded(out: CrossCheck, *, reason: str = "",
            unsupported: Status = Status.NA) -> Iterator[CrossCheck]:
    """Run a cross-check's work on `out`, deciding n.a. vs error as the module says."""
    start = time.perf_counter()
    try:
        yield out
    except UnsupportedError as exc:
        out.status = unsupported
        out.detail = reason + exc.capability if unsupported is Status.NA else describe(exc)
    except Exception as exc:  # noqa: BLE001 - reported, never hidden
        out.status, out.detail = Status.ERROR, describe(exc)
    finally:
        out.seconds = time.perf_counter() - start
