"""Worker processes die with the run that started them, even when it is killed with -9.

A killed parent runs no cleanup, so each worker watches for it itself, two ways:
- the kernel's parent-death signal (Linux prctl PR_SET_PDEATHSIG): SIGKILL as soon as the
  worker's parent exits (for a forkserver worker that is the fork server, which exits when
  the run's end of its pipe closes);
- a watchdog thread on the run's own process (a pidfd, which cannot be fooled by a reused
  process id; polling where there is none), which kills the worker when the run is gone.
Either suffices; both together cover a parent that is not the run (the fork server) and a
platform without prctl.

What a run killed with its whole process group leaves behind is cleared by the next run:
the folder of the fork server's socket (`pymp-*` in the temporary directory), which a run
marks as its own (`sweep_stale_folders`).
"""

from __future__ import annotations

import ctypes
import os
import select
import shutil
import signal
import stat
import tempfile
import threading
import time

PR_SET_PDEATHSIG = 1
POLL = 0.5  # seconds between looks at the parent where there is no pidfd


def die_with(run_pid: int) -> None:
    """Call first in a worker: it is killed when its parent or the process `run_pid` (the
    run that owns it) exits."""
    _parent_death_signal()
    try:
        fd = os.pidfd_open(run_pid)
    except ProcessLookupError:
        _die()
    except (OSError, AttributeError):  # no pidfd here: poll
        threading.Thread(target=_poll, args=(run_pid,), daemon=True,
                         name="mechbook-lifeline").start()
    else:
        threading.Thread(target=_wait, args=(fd,), daemon=True,
                         name="mechbook-lifeline").start()
    if not _alive(run_pid):  # it died before the watch began
        _die()


def _parent_death_signal() -> None:
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):  # not Linux: the watchdog alone
        pass


def _wait(fd: int) -> None:
    select.select([fd], [], [])  # readable when the process has exited
    _die()


def _poll(pid: int) -> None:
    while _alive(pid):
        time.sleep(POLL)
    _die()


def _alive(pid: int) -> bool:
    """Running (a process that has exited but is not yet reaped, a zombie, is not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            return fh.read().rsplit(b")", 1)[1].split()[0] != b"Z"
    except (OSError, IndexError):
        return True


def _die() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


MARK = "mechbook-run-"  # a run's mark in its multiprocessing folder: MARK + its process id


def sweep_stale_folders() -> None:
    """Mark this run's multiprocessing folder (`pymp-*`, where the fork server's socket
    lives) as the run's, and remove the folders of earlier runs that were killed with
    their fork server (their mark names a process that is gone). Only folders of this
    user's runs, marked by them, that are real folders (not links) are removed."""
    from multiprocessing import util

    try:
        mine = util.get_temp_dir()
        os.makedirs(mine, mode=0o700, exist_ok=True)  # removed under this process: made again
        open(os.path.join(mine, f"{MARK}{os.getpid()}"), "a").close()
    except OSError:
        return
    top = tempfile.gettempdir()
    try:
        names = [n for n in os.listdir(top) if n.startswith("pymp-")]
    except OSError:
        return
    for name in names:
        folder = os.path.join(top, name)
        try:
            info = os.lstat(folder)
            if folder == mine or not stat.S_ISDIR(info.st_mode) or info.st_uid != os.getuid():
                continue
            marks = os.listdir(folder)
        except OSError:
            continue
        if _abandoned(marks):
            shutil.rmtree(folder, ignore_errors=True)


def _abandoned(marks: list[str]) -> bool:
    """Whether a folder with these names in it is a run's whose runs are all gone."""
    pids = [m[len(MARK):] for m in marks if m.startswith(MARK)]
    return bool(pids) and all(p.isdigit() and not _alive(int(p)) for p in pids)


def remove_if_abandoned(folder: str, wait: float = 2.0) -> None:
    """Remove the multiprocessing folder `folder` once the runs that marked it are gone,
    waiting up to `wait` seconds for them (the fork server calls it as it ends: a signal to
    the whole process group reaches the server and its run at once, and the run may take
    a moment to die; a run that lives on keeps its folder)."""
    end = time.monotonic() + wait
    while True:
        try:
            info = os.lstat(folder)
            if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.getuid():
                return
            if _abandoned(os.listdir(folder)):
                shutil.rmtree(folder, ignore_errors=True)
                return
        except OSError:
            return
        if time.monotonic() > end:
            return
        time.sleep(0.05)
