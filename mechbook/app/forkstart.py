"""Imported first by the batch's fork server (mechbook.app.batch), before the engine.

Two things only the server itself can do:
- Ctrl-C is the run's business. The terminal sends SIGINT to every process of its group,
  and the server spends its first seconds importing the engine, where a KeyboardInterrupt
  would print a traceback; from here on it ignores SIGINT (Python's fork server does so
  itself only after its imports), and so do the workers it forks. The run stops them.
- Its socket's folder (`pymp-*` in the temporary directory) goes with it. The run that
  started the server removes that folder at its exit, unless it was killed (SIGKILL, or
  SIGTERM's default action): then the server, which ends when the run's end of its pipe
  closes, removes it on its way out; a SIGTERM or SIGHUP to the server itself (a whole
  process group ended) ends it the same way. Only a SIGKILL of the server as well leaves
  the folder: the next run removes it (mechbook.app.lifeline.sweep_stale_folders).
"""

from __future__ import annotations

import atexit
import os
import shutil
import signal


def _remove_socket_folder() -> None:
    from multiprocessing import forkserver

    address = getattr(forkserver._forkserver, "_forkserver_address", None)
    if not isinstance(address, str) or not address or address.startswith("\0"):
        return
    folder = os.path.dirname(address)
    if os.path.basename(folder).startswith("pymp-"):
        shutil.rmtree(folder, ignore_errors=True)


def _end(signum, frame):
    raise SystemExit(128 + signum)


signal.signal(signal.SIGINT, signal.SIG_IGN)
signal.signal(signal.SIGTERM, _end)
signal.signal(signal.SIGHUP, _end)
atexit.register(_remove_socket_folder)
