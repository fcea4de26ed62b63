"""Starting the batch's fork server (and multiprocessing's resource tracker) so that no
signal sent while they start can leave them half there, or be lost.

The fork server is spawned with SIGINT, SIGTERM and SIGHUP blocked (a blocked mask and the
signals pending on it survive exec): one sent while its interpreter starts waits until
mechbook.app.running.forkstart, the first module it imports, can deal with it. Ctrl-C then
is dropped (the server ignores SIGINT: the run stops it), and SIGTERM or SIGHUP end it and
remove its socket's folder (a group SIGHUP once killed it outright and left the folder,
issue 42). This process holds the three for the spawn only (and notes a Ctrl-C another of
its threads took), and gets a Ctrl-C that came meanwhile as soon as the spawn is done:
until 8d0ecdc it ignored SIGINT for the spawn instead, and a Ctrl-C in that window was
lost (`check` ran on to the end). The resource tracker is started first, as it comes: its
own start blocks SIGINT and SIGTERM, it ignores both, and it ends on a hangup.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager

SERVER_ENDS = (signal.SIGTERM, signal.SIGHUP)  # blocked in the fork server until it can end
HELD = (signal.SIGINT, *SERVER_ENDS)  # blocked for the server's spawn


def start_server() -> None:
    """Start the fork server (and multiprocessing's resource tracker) if it is not running,
    with the signals held as the module docstring says (a Ctrl-C during the spawn is
    raised here as KeyboardInterrupt once the server is started)."""
    from multiprocessing import forkserver, resource_tracker

    resource_tracker.ensure_running()
    # held in this thread's mask, but another thread of the process may take the signal
    # (a process-directed signal goes to any thread not blocking it): Python's handler
    # then runs here all the same, so it only notes the Ctrl-C until the spawn is done
    with deferred_interrupt():
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, HELD)  # the server inherits it
        try:
            forkserver.ensure_running()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)


@contextmanager
def deferred_interrupt() -> Iterator[None]:
    """Ctrl-C held back until the block ends (then raised): for the moments a process is
    being started, when an interrupt would leave one started but not yet recorded, to run
    on without its run or fail on the terminal. A run that ignores SIGINT (a background
    job) goes on ignoring it; off the main thread nothing changes (no handler there)."""
    import threading

    if threading.current_thread() is not threading.main_thread() \
            or signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        yield
        return
    pending: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: pending.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous if previous is not None else signal.SIG_DFL)
    if pending:
        raise KeyboardInterrupt
