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

SERVER_ENDS = (signal.SIGTERM, signal.SIGHUP)  # blocked in the fork server until it can end
HELD = (signal.SIGINT, *SERVER_ENDS)  # blocked for the server's spawn


def start_server() -> None:
    """Start the fork server (and multiprocessing's resource tracker) if it is not running,
    with the signals held as the module docstring says (a Ctrl-C during the spawn is
    raised here as KeyboardInterrupt once the server is started)."""
    import threading
    from multiprocessing import forkserver, resource_tracker

    resource_tracker.ensure_running()
    if threading.current_thread() is not threading.main_thread() \
            or signal.getsignal(signal.SIGINT) is signal.SIG_IGN:  # a background job's
        _spawn(forkserver)
        return
    # held in this thread's mask, but another thread of the process may take the signal
    # (a process-directed signal goes to any thread not blocking it): Python's handler
    # then runs here all the same, so it only notes the Ctrl-C until the spawn is done
    pending: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: pending.append(signum))
    try:
        _spawn(forkserver)
    finally:
        signal.signal(signal.SIGINT, previous if previous is not None else signal.SIG_DFL)
    if pending:
        raise KeyboardInterrupt


def _spawn(forkserver) -> None:
    """The fork server spawned with HELD blocked (the new process inherits the mask)."""
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, HELD)
    try:
        forkserver.ensure_running()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
