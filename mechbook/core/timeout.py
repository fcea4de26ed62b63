"""A wall-clock limit for SymPy calls that can run for ever (simplify, solve)."""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager


class Timeout(BaseException):
    """The guarded computation ran past its limit (a BaseException, so that SymPy's own
    `except Exception` clauses cannot swallow it)."""


@contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise Timeout inside the block after `seconds` (main thread, POSIX; else no limit)."""
    if seconds <= 0 or threading.current_thread() is not threading.main_thread() \
            or not hasattr(signal, "setitimer") or signal.getitimer(signal.ITIMER_REAL)[0] > 0:
        yield  # no timer here, or an outer limit is already running and governs
        return

    def _raise(signum, frame):
        raise Timeout(f"gave up after {seconds} s")

    previous = signal.signal(signal.SIGALRM, _raise)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def try_simplify(expr, seconds: float = 5.0):
    """simplify(expr), or expr unchanged if SymPy takes longer than `seconds`."""
    import sympy as sp

    try:
        with time_limit(seconds):
            return sp.simplify(expr)
    except Timeout:
        return expr
