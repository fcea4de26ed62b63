"""Imported first by the batch's fork server (mechbook.app.running.batch), before the engine.

Three things only the server itself can do:
- Ctrl-C is the run's business. The terminal sends SIGINT to every process of its group,
  and the server spends its first seconds importing the engine, where a KeyboardInterrupt
  would print a traceback; from here on it ignores SIGINT (Python's fork server does so
  itself only after its imports), and so do the workers it forks. The run stops them.
- Its socket's folder (`pymp-*` in the temporary directory) goes with it. The run that
  started the server removes that folder at its exit, unless it was killed (SIGKILL, or
  SIGTERM's default action): then the server, which ends when the run's end of its pipe
  closes, removes it on its way out, once the run that marked the folder is gone; a
  SIGTERM or SIGHUP to the server itself (a whole process group ended) ends it the same
  way, also while it still imports the engine: the run starts it with both signals
  blocked, so that one sent before this module is imported waits for the handler below,
  and its socket's path is read from its open descriptors, before Python's fork server
  names it. Only a SIGKILL of the server as well leaves the folder: the next run removes it
  (mechbook.app.running.lifeline.sweep_stale_folders).
- A signal its run ignores, the server and its workers ignore too. A run started under
  `nohup` (or by a runner that ignores SIGHUP) hands the server SIGHUP ignored, as SIG_IGN
  survives exec; ending the server and the workers on a hangup the run itself ignores left
  the run alive with every problem in work failed ("the worker process died"), a new fork
  server importing the engine again, and the rest of the book checked on, well past the
  minute a killed run is given to end (issue 42's flake of test_interrupts).
"""

from __future__ import annotations

import atexit
import os
import signal

from mechbook.app.running.lifeline import remove_if_abandoned

_SERVER = os.getpid()  # the fork server; its workers inherit this module, and never end by
# way of atexit (they leave with os._exit), but a removal is the server's alone all the same


def _listening_address() -> str | None:
    """The path of the Unix socket this server listens on, read from its open descriptors:
    Python's fork server names it (`_forkserver_address`) only after its preload, of which
    this module is the first, and a signal while the engine is imported must find the
    folder too (a group SIGHUP or SIGTERM then left it: issue 42)."""
    import socket

    try:
        fds = sorted(int(n) for n in os.listdir("/proc/self/fd"))
    except OSError:
        fds = list(range(3, 256))
    for fd in fds:
        try:
            copy = os.dup(fd)
        except OSError:
            continue
        try:
            sock = socket.socket(fileno=copy)
        except OSError:  # not a socket
            os.close(copy)
            continue
        with sock:
            try:
                name = sock.getsockname() if sock.family == socket.AF_UNIX else None
            except OSError:
                name = None
        if isinstance(name, str) and os.path.basename(os.path.dirname(name)).startswith("pymp-"):
            return name
    return None


def _remove_socket_folder() -> None:
    """The folder of this server's socket, if the run that started it is gone (a server
    that ends while its run lives, say by a SIGTERM of its own, leaves it to the run)."""
    from multiprocessing import forkserver

    address = getattr(forkserver._forkserver, "_forkserver_address", None) or _ADDRESS
    if os.getpid() != _SERVER or not isinstance(address, str) or not address \
            or address.startswith("\0"):
        return
    folder = os.path.dirname(address)
    if os.path.basename(folder).startswith("pymp-"):
        remove_if_abandoned(folder)


ENDS = (signal.SIGTERM, signal.SIGHUP)  # the signals that end the server (and its run)


def _end(signum, frame):
    """SIGTERM or SIGHUP: the server ends by way of atexit (which removes its folder); a
    worker forked from it that has not yet set its own handlers dies as by default (its run
    terminates it as it exits), never raising inside the fork's own bookkeeping."""
    if os.getpid() != _SERVER:
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)
        return
    raise SystemExit(128 + signum)


_ADDRESS = _listening_address()
signal.signal(signal.SIGINT, signal.SIG_IGN)
for _ends in ENDS:
    if signal.getsignal(_ends) is not signal.SIG_IGN:  # ignored: as its run does (nohup)
        signal.signal(_ends, _end)
atexit.register(_remove_socket_folder)
# blocked by the run for the start-up (mechbook.app.running.serverstart): a Ctrl-C sent
# meanwhile is dropped now, a SIGTERM or SIGHUP ends the server now
signal.pthread_sigmask(signal.SIG_UNBLOCK, (signal.SIGINT, *ENDS))
