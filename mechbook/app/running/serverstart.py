"""Starting the batch's fork server (and multiprocessing's resource tracker) so that no
signal sent while they start can leave them half there.

Ctrl-C: SIGINT is ignored from the new processes' first instruction (SIG_IGN survives
exec), so a Ctrl-C while their interpreters start (before mechbook.app.running.forkstart
is imported) cannot kill them with a "Fatal Python error" on the terminal; this process
ignores it only for the instant of the spawn. SIGTERM and SIGHUP are blocked for the
server's spawn (a blocked mask survives exec too): one sent while its interpreter starts
waits until forkstart can end it and remove its socket's folder (a group SIGHUP then
killed it outright and left the folder, issue 42). The resource tracker is started first,
with those two as they were (its own start blocks SIGINT and SIGTERM, and it ends on a
hangup).
"""

from __future__ import annotations

import signal

SERVER_ENDS = (signal.SIGTERM, signal.SIGHUP)  # blocked in the fork server until it can end


def start_server() -> None:
    """Start the fork server (and multiprocessing's resource tracker) if it is not running,
    with the signals held as the module docstring says."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        _spawn_server()
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        _spawn_server()
    finally:
        signal.signal(signal.SIGINT, previous if previous is not None else signal.SIG_DFL)


def _spawn_server() -> None:
    """The resource tracker as it comes, then the fork server with SERVER_ENDS blocked."""
    from multiprocessing import forkserver, resource_tracker

    resource_tracker.ensure_running()
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, SERVER_ENDS)
    try:
        forkserver.ensure_running()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
