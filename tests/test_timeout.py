"""CPU time limits (core/timeout.py): the sooner of nested limits governs, the outer one
survives an inner search that swallows its alarm, and nothing is left armed."""

from __future__ import annotations

import signal

import pytest

from mechbook.core.timeout import Timeout, cpu_time, hard_time_limit, time_limit


def spin(seconds: float) -> None:
    """Busy for `seconds` of user CPU time (reading the clock rarely: a loop of system
    calls would spend its time in the kernel, which the limits do not count)."""
    start = cpu_time()
    while cpu_time() - start < seconds:
        x = 0
        for i in range(20000):
            x += i * i


def test_an_inner_limit_shorter_than_the_outer_one_governs():
    start = cpu_time()
    with hard_time_limit(5):
        with pytest.raises(Timeout):
            with time_limit(0.2):
                spin(3)
        inner = cpu_time() - start
        spin(0.3)  # the outer limit is still running, with what remains of it
    assert 0.15 < inner < 1.0, inner


@pytest.mark.slow
def test_the_outer_limit_survives_an_inner_search_that_swallows_its_alarm():
    for inner in (0.1, 10):  # shorter than the outer limit, and longer
        start = cpu_time()
        with pytest.raises(Timeout):
            with hard_time_limit(0.5):
                try:
                    with time_limit(inner):
                        spin(1.5)
                except Timeout:
                    pass  # an engine search giving up and going on
                spin(5)
        assert cpu_time() - start < 2.0, inner  # 0.5 s, the repeat at 0.2 s, slack


def test_nothing_is_left_armed():
    with time_limit(1):
        with hard_time_limit(2):
            pass
    assert signal.getitimer(signal.ITIMER_VIRTUAL) == (0.0, 0.0)
    assert signal.getsignal(signal.SIGVTALRM) in (signal.SIG_DFL, 0)


def test_a_limit_inside_a_spent_one_shot_limit_still_has_a_timer():
    """A search catches the outer one-shot limit's Timeout and goes on; a limit opened after
    that (an integral's 10 s) must still stop its block, not defer to the spent outer one
    (which would leave the block unbounded: a SymPy integral that never finished)."""
    with time_limit(0.2):
        try:
            spin(3)
        except Timeout:
            pass  # the outer limit's alarm, swallowed
        start = cpu_time()
        with pytest.raises(Timeout):
            with time_limit(0.3):
                spin(4)
        assert cpu_time() - start < 1.5
    assert signal.getitimer(signal.ITIMER_VIRTUAL) == (0.0, 0.0)
    assert signal.getsignal(signal.SIGVTALRM) in (signal.SIG_DFL, 0)


def test_an_entry_left_behind_does_not_disable_later_limits():
    """An expired entry without an alarm (as a signal between the bookkeeping and the
    block could leave) must not make every later limit of the process a no-op."""
    from mechbook.core import timeout

    timeout._ACTIVE.append((cpu_time() - 1.0, 0.0, object()))
    try:
        start = cpu_time()
        with pytest.raises(Timeout):
            with time_limit(0.3):
                spin(4)
        assert cpu_time() - start < 1.5
    finally:
        timeout._ACTIVE.clear()
        signal.setitimer(signal.ITIMER_VIRTUAL, 0)
        signal.signal(signal.SIGVTALRM, signal.SIG_DFL)
