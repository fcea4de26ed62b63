"""A batch of problem checks on a pool of worker processes, with limits and no losses.

The parent hands out problem ids (the longest first, by the durations stored from earlier
runs) to `jobs` worker processes and receives plain data back (mechbook/run.py). Each problem
has a wall-clock limit and a memory bound enforced from outside: a worker that exceeds
either is killed, the problem is reported as an error naming the limit and the stage it was
in (workers report their stage as they go), and a fresh worker takes its place; a worker is
also replaced after `max_tasks` problems, so memory SymPy caches do not grow without bound.
Results are handed to `on_done` as each problem finishes (the CLI stores them at once: the
parent is the store's only writer), and returned in the order the ids were given.

The same machinery runs other work under the same limits: `task` (a module-level function
of (item, base, options, stage), so workers can import it) replaces the problem check and
`failed` makes the result of an item stopped from outside; `mechbook simulate` and the fuzz
harness (tests/fuzz) use it that way.

Why not concurrent.futures or pebble: a per-task kill with the task's last stage, a memory
bound read from /proc, and stage messages streamed while a task runs are the point of this
module, and neither offers all three; the loop below is the whole of it.
"""

from __future__ import annotations

import gc
import importlib
import math
import multiprocessing as mp
import os
import signal
import time
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import Generic, TypeVar

from mechbook.app.options import DEFAULT_MEMORY_MB, DEFAULT_TIMEOUT
from mechbook.app.running.lifeline import die_with, sweep_stale_folders
from mechbook.app.running.quiet import install
from mechbook.app.running.run import ProblemRun, RunOptions, Stage, run_problem
from mechbook.app.running.serverstart import deferred_interrupt, start_server
from mechbook.errors import MechbookError, describe

ItemT = TypeVar("ItemT", bound=Hashable)  # what one task is given: a problem id, a request
OptionsT = TypeVar("OptionsT")  # what every task of a batch is handed (RunOptions: a check)
ResultT = TypeVar("ResultT")  # what a task returns: plain data (it crosses processes)
Task = Callable[[ItemT, Path, OptionsT, Stage], ResultT]  # (item, base, options, stage)
Failed = Callable[[ItemT, str, float, str], ResultT]  # (item, why, seconds, stage)

MAX_TASKS = 20  # problems per worker before it is replaced
POLL = 0.25  # seconds between checks of the limits


@dataclass(frozen=True)
class BatchOptions(Generic[OptionsT]):
    jobs: int = 0  # 0: one per core
    timeout: float = DEFAULT_TIMEOUT
    memory_mb: float = DEFAULT_MEMORY_MB
    max_tasks: int = MAX_TASKS
    run: OptionsT = RunOptions()  # handed to the task (RunOptions: the default task's)
    serial: bool = False  # in the calling process, no limits (debugging)

    def __post_init__(self):
        """Limits that are numbers: NaN compares false with everything, so a NaN time limit
        or memory bound would be none at all (the command line refuses it first)."""
        if not (self.timeout > 0) or math.isnan(self.memory_mb) or self.memory_mb < 0:
            raise MechbookError(f"batch limits must be numbers: timeout {self.timeout} s "
                                f"(> 0), memory {self.memory_mb} MB (>= 0; 0: no bound)")

    @property
    def workers(self) -> int:
        return self.jobs if self.jobs > 0 else (os.cpu_count() or 1)


def problem_task(pid: str, base: Path, options: RunOptions, stage: Stage) -> ProblemRun:
    """The default task: check one problem (mechbook.app.running.run)."""
    return run_problem(pid, base, options, stage=stage)


def problem_failed(pid: str, why: str, seconds: float, stage: str) -> ProblemRun:
    """The default result of a problem stopped from outside."""
    return ProblemRun(pid, error=why, seconds=seconds, stage=stage)


def _worker(conn: Connection, base: Path, options: object, task: Task, run_pid: int) -> None:
    """A worker's loop: receive an item, run the task on it, send stages and the result.
    It dies with the run (mechbook.app.running.lifeline), even one killed with -9."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C: the run stops its workers
    for ends in (signal.SIGTERM, signal.SIGHUP):  # the fork server's own ways to end: not ours
        if signal.getsignal(ends) is not signal.SIG_IGN:  # ignored by the run (nohup): kept so
            signal.signal(ends, signal.SIG_DFL)
    die_with(run_pid)
    install()  # a stray warning or unraisable exception: the debug log, not the terminal
    settle()
    while True:
        try:
            item = conn.recv()
        except (EOFError, KeyboardInterrupt):
            return
        if item is None:
            return
        try:
            try:
                result = task(item, base, options, lambda text, item=item:
                              conn.send(("stage", item, text)))
            except (BrokenPipeError, ConnectionResetError, EOFError):
                raise
            except Exception as exc:  # noqa: BLE001 - reported as the item's failure
                conn.send(("failed", item, f"the task failed: {describe(exc)}"))
                continue
            conn.send(("done", item, result))
        except (BrokenPipeError, ConnectionResetError, EOFError):
            return  # the parent is gone (killed): nobody to report to


@dataclass
class _Slot:
    process: mp.process.BaseProcess
    conn: Connection
    pid: Hashable | None = None  # the item (problem id) it is working on
    started: float = 0.0
    stage: str = ""
    tasks: int = 0


# the engine, imported once by the fork server the workers fork from (or by a serial run)
PRELOAD = ("mechbook.app.running.run", "mechbook.verify.checker", "mechbook.verify.quantities",
           "mechbook.crosscheck")
GC_THRESHOLDS = (10_000, 20, 100)  # young collections ~14 times rarer than Python's default


def pool_context():
    """The workers' context: a fork server that imported the engine once and settled."""
    sweep_stale_folders()  # what runs killed with their fork server left
    ctx = mp.get_context("forkserver")
    # ... and settles there (mechbook.app.running.frozen): the workers fork from a frozen heap;
    # mechbook.app.running.forkstart first: the server ignores Ctrl-C and removes its socket's
    # folder when it ends (even after its run was killed)
    ctx.set_forkserver_preload(["mechbook.app.running.forkstart", *PRELOAD,
                                "mechbook.app.running.frozen"])
    return ctx


def kill_pool(pool) -> None:
    """Stop a concurrent.futures process pool at once: its workers killed, its queue dropped
    (shutdown alone would wait for every task queued; its workers ignore Ctrl-C).

    A worker killed while it wrote a result leaves part of a message in the result pipe,
    and the pool's manager thread would wait for the rest for ever: this process holds
    the pipe's write end too, so no end of file comes, and the interpreter's exit joins
    that thread (an interrupted sweep hung after its last line). Once the workers are
    dead, this end is closed as well: the thread reads an end of file, finds the pool
    broken and ends."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    writer = getattr(getattr(pool, "_result_queue", None), "_writer", None)  # shutdown drops it
    kill = getattr(pool, "kill_workers", None)  # Python 3.14
    if kill is not None:
        kill()
    else:
        for process in processes:
            process.kill()
    for process in processes:
        process.join(timeout=5)  # SIGKILL: at once, unless the machine is stalled
    pool.shutdown(wait=False, cancel_futures=True)
    if writer is not None and not writer.closed:
        writer.close()


def settle(preload: bool = False) -> None:
    """Keep the garbage collector off what was imported: the objects alive now (the
    engine's modules: SymPy, SciPy, NumPy, mechbook; with `preload`, PRELOAD imported
    first) are frozen out of its reach after a last collection, once per process (a
    process that already froze, or was forked from the settled fork server, only sets the
    thresholds), and young collections come rarer. Why: every full collection walks all
    live container objects, and the imported modules' were most of them: a serial check
    of the 158 problems spent 55.3 s of CPU, 49.1 s with this. For processes of
    mechbook's own only (the batch's workers, `mechbook check --serial`): the Python API
    leaves the caller's collector be."""
    if preload:
        for name in PRELOAD:
            importlib.import_module(name)
    if not gc.get_freeze_count():  # a worker forked from the settled fork server: done
        gc.collect()  # garbage now would be frozen with the rest, never to be collected
        gc.freeze()
    gc.set_threshold(*GC_THRESHOLDS)


def _cannot_start(exc: OSError) -> str:
    """Why worker processes could not be started, and what to do."""
    import tempfile

    why = exc.strerror or str(exc)
    return (f"cannot start worker processes ({why}): their fork server needs a socket in "
            f"the temporary directory {tempfile.gettempdir()}, which must exist, be writable "
            "and have a short path (a socket's path is at most 107 bytes): set TMPDIR to "
            "one, or use --serial")


def rss_mb(os_pid: int) -> float:
    """Resident memory of a process in MB (0 if it cannot be read)."""
    try:
        with open(f"/proc/{os_pid}/statm") as fh:
            return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
    except (OSError, ValueError, IndexError):
        return 0.0


class Batch(Generic[ItemT, OptionsT, ResultT]):
    """Check many problems on worker processes; see the module docstring."""

    def __init__(self, base: Path, options: BatchOptions[OptionsT] = BatchOptions(),
                 on_done: Callable[[ResultT], None] | None = None,
                 on_start: Callable[[ItemT], None] | None = None,
                 task: Task[ItemT, OptionsT, ResultT] = problem_task,
                 failed: Failed[ItemT, ResultT] = problem_failed):
        self.base = base
        self.options = options
        self.on_done = on_done or (lambda run: None)
        self.on_start = on_start or (lambda pid: None)
        self.task = task
        self.failed = failed
        self._ctx = pool_context()
        self._slots: list[_Slot] = []
        self._kept = False  # inside `with`: idle workers stay for the next run
        self.stopped = False

    def __enter__(self) -> Batch:
        """Keep the workers between runs (`mechbook watch`: each save is checked by a
        worker that has checked before); they are retired when the block ends."""
        self._kept = True
        return self

    def __exit__(self, *exc) -> None:
        self._kept = False
        self._retire_all()

    def _retire_all(self) -> None:
        for slot in self._slots:
            self._retire(slot, kill=slot.pid is not None)
        self._slots = []

    def stop(self) -> None:
        """Hand out no more items and end the run (an `on_done` may call it: `check -x`);
        items still running are stopped, and `run` returns the results it has."""
        self.stopped = True

    def _spawn(self) -> _Slot:
        parent, child = self._ctx.Pipe()
        proc = self._ctx.Process(target=_worker, daemon=True,
                                 args=(child, self.base, self.options.run, self.task,
                                       os.getpid()))
        try:
            start_server()
            with deferred_interrupt():  # started and recorded, or not started at all
                proc.start()
        except OSError as exc:  # the fork server's socket cannot be made or reached
            parent.close()
            raise MechbookError(_cannot_start(exc)) from None
        finally:
            child.close()
        return _Slot(proc, parent)

    def _retire(self, slot: _Slot, kill: bool = False) -> None:
        if kill:
            slot.process.kill()
        else:
            try:
                slot.conn.send(None)
            except (OSError, BrokenPipeError):
                slot.process.kill()
        slot.process.join(timeout=5)
        if slot.process.is_alive():
            slot.process.kill()
            slot.process.join()
        slot.conn.close()

    def run(self, ids: list[ItemT]) -> list[ResultT]:
        """Run the task on `ids` (distinct; in the order given: put the longest first);
        results in that order (those finished, after `stop`)."""
        if self.options.serial:
            return self._serial(ids)
        todo = list(ids)
        done: dict[ItemT, ResultT] = {}
        finished = False
        try:
            want = min(self.options.workers, len(todo))
            self._slots += [self._spawn() for _ in range(want - len(self._slots))]
            while len(done) < len(ids) and not self.stopped:
                self._assign(todo)
                self._collect(done)
            finished = not self.stopped  # stopped: what still runs is stopped
        finally:
            if not (finished and self._kept):
                self._retire_all()
        return [done[pid] for pid in ids if pid in done]

    def _serial(self, ids: list[ItemT]) -> list[ResultT]:
        """In this process, one after another: no limits, but a debugger can follow."""
        out = []
        for pid in ids:
            if self.stopped:
                break
            self.on_start(pid)
            run = self.task(pid, self.base, self.options.run, lambda text: None)
            self.on_done(run)
            out.append(run)
        return out

    def _assign(self, todo: list[ItemT]) -> None:
        for i, slot in enumerate(self._slots):
            if slot.pid is not None or not todo:
                continue
            if slot.tasks >= self.options.max_tasks:
                self._retire(slot)
                slot = self._slots[i] = self._spawn()
            slot.pid, slot.started, slot.stage = todo.pop(0), time.monotonic(), "starting"
            slot.tasks += 1
            slot.conn.send(slot.pid)
            self.on_start(slot.pid)

    def _collect(self, done: dict[ItemT, ResultT]) -> None:
        busy = [s for s in self._slots if s.pid is not None]
        ready = wait([s.conn for s in busy] + [s.process.sentinel for s in busy], POLL)
        for slot in busy:
            if slot.conn in ready or slot.process.sentinel in ready:
                self._read(slot, done)
        now = time.monotonic()
        for slot in self._slots:
            if slot.pid is None:
                continue
            why = None
            if now - slot.started > self.options.timeout:
                why = f"exceeded the time limit of {self.options.timeout:g} s"
            elif self.options.memory_mb and rss_mb(slot.process.pid) > self.options.memory_mb:
                why = f"exceeded the memory bound of {self.options.memory_mb:g} MB"
            if why:
                self._fail(slot, done, f"{why} while in stage: {slot.stage}")

    def _read(self, slot: _Slot, done: dict[ItemT, ResultT]) -> None:
        finished = None
        try:
            while slot.conn.poll():
                kind, pid, payload = slot.conn.recv()
                if kind == "stage":
                    slot.stage = payload
                elif kind == "done":
                    slot.pid = None
                    done[pid] = finished = payload
                    break
                elif kind == "failed":  # the task raised: its message, the worker lives on
                    slot.pid = None
                    done[pid] = finished = self.failed(pid, payload,
                                                       time.monotonic() - slot.started,
                                                       slot.stage)
                    break
        except (EOFError, OSError):  # the worker's pipe only: a dead worker is judged below
            pass
        if finished is not None:
            self.on_done(finished)  # outside the pipe's handler: its errors are its own
            return
        if slot.pid is not None and not slot.process.is_alive():
            code = slot.process.exitcode
            how = f"signal {-code}" if code is not None and code < 0 else f"exit code {code}"
            self._fail(slot, done, f"the worker process died ({how}) while in stage: "
                       f"{slot.stage}")

    def _fail(self, slot: _Slot, done: dict[ItemT, ResultT], why: str) -> None:
        pid = slot.pid
        run = self.failed(pid, why, time.monotonic() - slot.started, slot.stage)
        self._retire(slot, kill=True)
        i = self._slots.index(slot)
        self._slots[i] = self._spawn()
        done[pid] = run
        self.on_done(run)
