"""Time limits for SymPy calls that can run for ever (simplify, solve), in CPU seconds.

The limits count the CPU time of this process (ITIMER_VIRTUAL), not the wall clock: a
search given 3 s gets 3 s of work whether the machine is idle or busy with other jobs, so
what the engine finds within its limits does not depend on the machine's load (it still
depends on the machine's speed). The wall-clock limit a user sets (`mechbook check
--timeout`) is enforced from outside, by the batch.
"""

from __future__ import annotations

import math
import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

try:
    import resource
except ImportError:  # not POSIX: no limits (see _usable), process_time as the clock
    resource = None

_TIMER = getattr(signal, "ITIMER_VIRTUAL", None)
_SIGNAL = getattr(signal, "SIGVTALRM", None)


class Timeout(BaseException):
    """The guarded computation ran past its limit (a BaseException, so that SymPy's own
    `except Exception` clauses cannot swallow it)."""


def cpu_time() -> float:
    """The clock the limits count: user CPU seconds of this process (what ITIMER_VIRTUAL
    counts; process_time would add system time and run ahead of the timer)."""
    if resource is None:
        return time.process_time()
    return resource.getrusage(resource.RUSAGE_SELF).ru_utime


# The limits now running, outermost first: (deadline in CPU seconds, repeat interval).
_ACTIVE: list[tuple[float, float, object]] = []


def _raise(signum, frame):
    """The alarm: a Timeout. A one-shot limit's alarm spends that limit, so it is taken out
    here and the timer handed to the limit outside it (at once if that one has run out
    too): a search that swallows the Timeout and goes on inside the spent limit still
    meets the outer one. Handed over only when the limit was left, the outer one was never
    armed: CI hung 900 s in SymPy's integrate under `validate`'s 15 s limit."""
    if _ACTIVE and _ACTIVE[-1][1] == 0 and signal.getitimer(_TIMER)[0] == 0:
        _ACTIVE.pop()
        if _ACTIVE:
            _arm(*_ACTIVE[-1][:2])
    raise Timeout("gave up: CPU time limit")


def _usable() -> bool:
    """A limit can be set: POSIX, main thread, and the timer not held by someone else (a
    timer left running with our own handler installed is ours, left behind: taken over)."""
    if _TIMER is None or threading.current_thread() is not threading.main_thread():
        return False
    return (bool(_ACTIVE) or signal.getitimer(_TIMER)[0] == 0
            or signal.getsignal(_SIGNAL) is _raise)


def _arm(deadline: float, interval: float) -> None:
    """The timer set for a limit (our handler first: the default action of the signal would
    end the process)."""
    if signal.getsignal(_SIGNAL) is not _raise:
        signal.signal(_SIGNAL, _raise)
    signal.setitimer(_TIMER, max(deadline - cpu_time(), 1e-3), interval)


@contextmanager
def _limit(seconds: float, interval: float) -> Iterator[None]:
    """Nested limits: the inner one counts while it is the sooner; when it is left, the
    outer one's timer is set again to what remains of it (at once if it has run out, so
    an inner `except Timeout` that swallowed the outer's alarm does not outlive it).

    A limit that has run out with its alarm spent (a one-shot limit whose Timeout a search
    caught and went on, or an entry a signal at the wrong moment left behind) no longer
    governs: it is dropped, so a new limit inside it has a timer of its own. Without that,
    every later limit of the process deferred to it and none was armed: an integral that
    SymPy never finishes ran unbounded. For the same reason a new limit defers to an outer
    one only while the outer one's alarm is set (the timer running, our handler
    installed); otherwise it arms its own. The bookkeeping is undone even when an outer
    alarm held back during it is delivered as it ends."""
    if math.isnan(seconds):  # NaN compares false with everything: it would be no limit
        raise ValueError("a time limit of NaN seconds")
    if seconds <= 0 or math.isinf(seconds) or not _usable():  # 0 or infinite: no limit
        yield
        return
    entry, previous = None, None
    try:
        with _quiet():  # the bookkeeping is not interrupted by an outer limit's alarm
            _drop_spent()
            deadline = cpu_time() + seconds
            if not _governed(deadline):
                entry = (deadline, interval, object())  # told apart by identity when left
                previous = _install()
                _ACTIVE.append(entry)
                _arm(deadline, interval)
        # (an outer alarm held back above is delivered here: the entry is taken out below)
        yield  # without an entry: an outer limit runs out first, its alarm set, governs
    finally:
        if entry is not None:
            _leave(entry, previous)


def _leave(entry: tuple, previous) -> None:
    """Take a limit out; the timer goes back to the one outside it, or off (and the
    handler that was there before back) when it was the last."""
    with _quiet():
        if any(e is entry for e in _ACTIVE):
            _ACTIVE[:] = [e for e in _ACTIVE if e is not entry]
        if _ACTIVE:
            _arm(*_ACTIVE[-1][:2])
        else:
            signal.setitimer(_TIMER, 0)
            if previous is not None:
                signal.signal(_SIGNAL, previous)


def _governed(deadline: float) -> bool:
    """An outer limit runs out no later than `deadline` and its alarm is set (the timer
    running, our handler installed): a new limit need not be armed. Whatever else (an
    entry left behind without a timer or a handler) does not govern."""
    return bool(_ACTIVE) and _ACTIVE[-1][0] <= deadline \
        and signal.getitimer(_TIMER)[0] > 0 and signal.getsignal(_SIGNAL) is _raise


def _install():
    """Our handler installed; what was there before if it was not ours (to put back when
    the last limit is left), else None."""
    if signal.getsignal(_SIGNAL) is _raise:
        return None
    return signal.signal(_SIGNAL, _raise)


def _drop_spent() -> None:
    """Drop the innermost limit if its alarm is spent, and give the timer back to the one
    outside it (which fires at once if it has run out meanwhile).

    Spent means no alarm pending while the limit is open: every limit arms the timer on
    entry and leaving an inner limit re-arms the outer one, so a one-shot timer at zero has
    fired (a repeating one never is). The timer, not the deadline, says so: ITIMER_VIRTUAL
    and getrusage account CPU time apart, and the alarm can come a little before the
    deadline as cpu_time() reads it; compared with the deadline, such a limit was kept and
    a new limit inside it deferred to it, with no timer armed."""
    if _ACTIVE and signal.getitimer(_TIMER)[0] == 0:
        _ACTIVE.pop()
        if _ACTIVE:
            _arm(*_ACTIVE[-1][:2])


@contextmanager
def _quiet() -> Iterator[None]:
    """The timer's signal held back (delivered on leaving, if it came meanwhile)."""
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {_SIGNAL})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def time_limit(seconds: float):
    """Raise Timeout inside the block after `seconds` of CPU time (main thread, POSIX;
    else no limit). Limits nest: the sooner one governs."""
    return _limit(seconds, 0.0)


def hard_time_limit(seconds: float):
    """Raise Timeout in the block after `seconds` of CPU time, and again every 0.2 s until
    it is left.

    `time_limit` fires once, and the engine's searches catch a Timeout as their own limit
    and go on with the next strategy: the equilibrium search of lim-2057/planar ran for 130 s
    that way before giving up. The repeated alarm ends such a search within `seconds`."""
    return _limit(seconds, 0.2)


def try_simplify(expr, seconds: float = 5.0):
    """simplify(expr), or expr unchanged if SymPy takes longer than `seconds`."""
    import sympy as sp

    try:
        with time_limit(seconds):
            return sp.simplify(expr)
    except Timeout:
        return expr
