"""Time limits for SymPy calls that can run for ever (simplify, solve), in CPU seconds.

The limits count the CPU time of this process (ITIMER_VIRTUAL), not the wall clock: a
search given 3 s gets 3 s of work whether the machine is idle or busy with other jobs, so
what the engine finds within its limits does not depend on the machine's load (it still
depends on the machine's speed). The wall-clock limit a user sets (`mechbook check
--timeout`) is enforced from outside, by the batch.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

_TIMER = getattr(signal, "ITIMER_VIRTUAL", None)
_SIGNAL = getattr(signal, "SIGVTALRM", None)


class Timeout(BaseException):
    """The guarded computation ran past its limit (a BaseException, so that SymPy's own
    `except Exception` clauses cannot swallow it)."""


def cpu_time() -> float:
    """The clock the limits count: CPU seconds of this process."""
    return time.process_time()


def _unavailable() -> bool:
    return (_TIMER is None or threading.current_thread() is not threading.main_thread()
            or signal.getitimer(_TIMER)[0] > 0)


@contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise Timeout inside the block after `seconds` of CPU time (main thread, POSIX;
    else no limit). An outer limit already running governs."""
    if seconds <= 0 or _unavailable():
        yield
        return

    def _raise(signum, frame):
        raise Timeout(f"gave up after {seconds} s")

    previous = signal.signal(_SIGNAL, _raise)
    signal.setitimer(_TIMER, seconds)
    try:
        yield
    finally:
        signal.setitimer(_TIMER, 0)
        signal.signal(_SIGNAL, previous)


@contextmanager
def hard_time_limit(seconds: float) -> Iterator[None]:
    """Raise Timeout in the block after `seconds` of CPU time, and again every 0.2 s until
    it is left.

    `time_limit` fires once, and the engine's searches catch a Timeout as their own limit
    and go on with the next strategy: the equilibrium search of lim-2057/planar ran for 130 s
    that way before giving up. The repeated alarm ends such a search within `seconds`. An
    outer limit already running governs (as with time_limit)."""
    if seconds <= 0 or _unavailable():
        yield
        return

    def _raise(signum, frame):
        raise Timeout(f"gave up after {seconds} s")

    previous = signal.signal(_SIGNAL, _raise)
    signal.setitimer(_TIMER, seconds, 0.2)
    try:
        yield
    finally:
        signal.setitimer(_TIMER, 0)
        signal.signal(_SIGNAL, previous)


def try_simplify(expr, seconds: float = 5.0):
    """simplify(expr), or expr unchanged if SymPy takes longer than `seconds`."""
    import sympy as sp

    try:
        with time_limit(seconds):
            return sp.simplify(expr)
    except Timeout:
        return expr
