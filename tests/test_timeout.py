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
