"""CPU time limits (core/timeout.py): the sooner of nested limits governs, the outer one
survives an inner search that swallows its alarm, and nothing is left armed."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

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


def test_the_outer_limit_survives_an_inner_alarm_swallowed_inside_the_inner_limit():
    """CI hung 900 s in SymPy's integrate under validate (ci4, and again on 720c149): the
    inner 5 s one-shot limit fired, its Timeout was swallowed inside the integral (the
    inner limit not left), and the outer limit, whose timer is set again only when the
    inner one is left, was never armed: the timer stayed at zero for good."""
    start = cpu_time()
    swallowed = []
    with pytest.raises(Timeout):
        with hard_time_limit(0.6):
            with time_limit(0.2):
                try:
                    spin(5)
                except Timeout:  # the inner limit's alarm, swallowed where it landed
                    swallowed.append(cpu_time() - start)
                spin(5)  # and the search goes on, still inside the inner limit
    assert swallowed and swallowed[0] < 0.5
    assert cpu_time() - start < 2.0  # ended by the outer limit, not after the 5 s


def test_nothing_is_left_armed():
    with time_limit(1):
        with hard_time_limit(2):
            pass
    assert signal.getitimer(signal.ITIMER_VIRTUAL) == (0.0, 0.0)
    assert signal.getsignal(signal.SIGVTALRM) in (signal.SIG_DFL, 0)


# The two below run in a fresh interpreter: what they test is the state a process is left
# in, which the tests run before them in the same worker must not decide.
SPENT = """
import signal, sys
sys.path.insert(0, {tests!r})
from test_timeout import spin
from mechbook.core import timeout
from mechbook.core.timeout import Timeout, cpu_time, time_limit
{setup}
start = cpu_time()
try:
    with time_limit(0.3):
        spin(4)
except Timeout:
    used = cpu_time() - start
    print("timeout", used)
    sys.exit(0 if used < 1.5 and signal.getitimer(signal.ITIMER_VIRTUAL) == (0.0, 0.0) else 3)
print("no timeout")
sys.exit(2)
"""


def _fresh(setup: str) -> subprocess.CompletedProcess:
    code = SPENT.format(tests=str(Path(__file__).parent), setup=setup)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)


def test_a_limit_inside_a_spent_one_shot_limit_still_has_a_timer():
    """A search catches the outer one-shot limit's Timeout and goes on; a limit opened after
    that (an integral's 10 s) must still stop its block, not defer to the spent outer one
    (which would leave the block unbounded: a SymPy integral that never finished)."""
    setup = """
outer = time_limit(0.2)
outer.__enter__()
try:
    spin(3)
except Timeout:
    pass  # the outer limit's alarm, swallowed; the outer block goes on
"""
    res = _fresh(setup)
    assert res.returncode == 0, res.stdout + res.stderr


def test_an_entry_left_behind_does_not_disable_later_limits():
    """An expired entry without an alarm (as a signal between the bookkeeping and the
    block could leave) must not make every later limit of the process a no-op."""
    res = _fresh("timeout._ACTIVE.append((cpu_time() - 1.0, 0.0, object()))")
    assert res.returncode == 0, res.stdout + res.stderr


def test_an_entry_left_behind_that_has_not_run_out_does_not_govern():
    """An entry whose deadline is still ahead but that has no timer (nor our handler: the
    process's default) must not be deferred to: a new limit arms its own timer."""
    res = _fresh("timeout._ACTIVE.append((cpu_time() + 0.1, 0.0, object()))\n"
                 "assert signal.getsignal(signal.SIGVTALRM) in (signal.SIG_DFL, 0)")
    assert res.returncode == 0, res.stdout + res.stderr


def test_a_timer_of_ours_left_running_is_taken_over():
    """Our handler installed and the timer running with no limit open (left behind): the
    next limit takes the timer over instead of running without one."""
    res = _fresh("signal.signal(signal.SIGVTALRM, timeout._raise)\n"
                 "signal.setitimer(signal.ITIMER_VIRTUAL, 500.0)")
    assert res.returncode == 0, res.stdout + res.stderr
