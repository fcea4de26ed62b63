"""`mechbook watch ID`: check a problem again each time its files are saved.

Writing a problem is a loop of edit, save, check. A fresh `mechbook check` process spends
most of its second importing SymPy, SciPy and the engine; here a worker process of the batch
machinery (mechbook.app.running.batch), forked from a server that imported them once, checks every
save and stays for the next one, so a save is answered in about the time the check itself
takes (a few tenths of a second for a problem with one degree of freedom). Each check has
the limits of `mechbook check`: a wall-clock time limit and a memory bound, enforced from
outside (a check past either is stopped, said so with its stage, and a fresh worker waits
for the next save).

The problem file, its answer key and books.yaml are polled: their size, time and content
hash (an editor's save that changes nothing is not a change). Only a regular file of at most
the size a problem file may have is read; a FIFO, a device, a link to /dev/zero or an
oversized file is noticed by its kind and size, never read, and the check then says what is
wrong with it. Each outcome is printed part by part, with the detail of every part that did
not pass and the notes (warnings) of the run. Nothing is written to the store.
"""

from __future__ import annotations

import hashlib
import os
import resource
import stat
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from mechbook.app.bounded import Unreadable, read_regular
from mechbook.app.options import DEFAULT_MEMORY_MB, DEFAULT_TIMEOUT
from mechbook.app.output.console import STATUS_ORDER
from mechbook.app.running.batch import Batch, BatchOptions
from mechbook.app.running.run import ProblemRun, RunOptions, run_problem
from mechbook.errors import MechbookError
from mechbook.model.ids import split_id
from mechbook.model.input_limits import MAX_FILE_BYTES
from mechbook.records import Status

POLL_SECONDS = 0.1


def _cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


@dataclass(frozen=True)
class WatchOptions:
    crosscheck: bool = True
    timeout: float = DEFAULT_TIMEOUT  # wall-clock seconds per check, as `mechbook check`
    memory_mb: float = DEFAULT_MEMORY_MB  # resident memory per check (0: no bound)
    poll: float = POLL_SECONDS
    runs: int = 0  # stop after this many checks (0: until interrupted; for tests)


def files_signature(paths: list[Path]) -> tuple:
    """What a change is: a file's kind, size, time and content (a touch alone is not one).
    Only a regular file of at most the size a problem file may have is read."""
    out = []
    for path in paths:
        try:
            st = path.stat()
        except OSError:
            out.append(None)
            continue
        if not stat.S_ISREG(st.st_mode) or st.st_size > MAX_FILE_BYTES:
            out.append((st.st_size, st.st_mtime_ns, f"mode {st.st_mode:o}"))
            continue
        try:
            digest = hashlib.sha256(read_regular(path, MAX_FILE_BYTES)).hexdigest()
        except Unreadable as exc:
            digest = exc.reason
        out.append((st.st_size, st.st_mtime_ns, digest))
    return tuple(out)


def _changed(old: tuple, new: tuple) -> bool:
    if old is None:
        return True
    return any((a is None) != (b is None) or (a and b and (a[0], a[2]) != (b[0], b[2]))
               for a, b in zip(old, new, strict=True))


def check_in_worker(pid: str, base: Path, options, stage) -> tuple:
    """The batch task: one check (mechbook.app.running.run), and the CPU time it took here."""
    cpu = _cpu()
    run = run_problem(pid, base, options, stage=stage)
    return run, _cpu() - cpu


def check_stopped(pid: str, why: str, seconds: float, stage: str) -> tuple:
    """The batch's result for a check stopped from outside (a limit, a dead worker)."""
    return ProblemRun(pid, error=why, seconds=seconds, stage=stage), None


def report_lines(run, seconds: float, cpu: float | None) -> list[str]:
    """The outcome of one check as lines: a summary, then each part that did not pass."""
    from collections import Counter

    if run.error:
        spent = f"{seconds:.2f} s" + (f", CPU {cpu:.2f} s" if cpu is not None else "")
        return [f"{run.pid}: {run.error}", f"  ({spent})"]
    counts = Counter(o.status for o in run.outcomes)
    summary = ", ".join(f"{counts[s]} {s}" for s in STATUS_ORDER if counts[s]) or "no parts"
    lines = [f"{run.pid}: {summary}  (checked in {seconds:.2f} s, CPU {cpu:.2f} s)"]
    for o in run.outcomes:
        if o.status != Status.PASS:
            lines.append(f"  {o.part:<16} {o.quantity:<20} {o.status:<12} "
                         f"{(o.method + ' ' + o.detail).strip()}")
    for x in run.crosschecks:
        if x.failed:
            lines.append(f"  cross-check {x.name}: {x.status} {x.detail}")
    lines += [f"  note: {n}" for n in run.notes]
    return lines


def watch(pid: str, base: Path, say: Callable[[str], None],
          options: WatchOptions = WatchOptions()) -> int:
    """Check `pid` now and after every change of its files; returns the number of checks
    run when `options.runs` stops it. Ctrl-C says "stopped watching" and is raised again
    (KeyboardInterrupt), so that the command ends with 130 as every command does."""
    book, number = split_id(pid)
    paths = [base / "problems" / book / f"{number}.yaml",
             base / "answers" / book / f"{number}.yaml", base / "books.yaml"]
    say(f"watching {', '.join(str(p.relative_to(base)) for p in paths[:2])} "
        "(Ctrl-C to stop)")
    limits = BatchOptions(jobs=1, timeout=options.timeout, memory_mb=options.memory_mb,
                          run=RunOptions(crosscheck=options.crosscheck))
    last = None
    done = 0
    try:
        with Batch(base, limits, task=check_in_worker, failed=check_stopped) as batch:
            while True:
                now = files_signature(paths)
                if not _changed(last, now):
                    time.sleep(options.poll)
                    continue
                if last is not None:
                    names = [str(p.relative_to(base)) for p, a, b in zip(paths, last, now,
                                                                          strict=True)
                             if a != b]
                    say(f"\n{', '.join(names)} changed: checking {pid} again")
                last = now
                if now[0] is None and not os.path.lexists(paths[0]):
                    say(f"{paths[0]}: no such file (yet)")
                    continue
                start = time.perf_counter()
                try:
                    run, cpu = batch.run([pid])[0]
                except MechbookError as exc:
                    say(f"{pid}: {exc}")
                else:
                    for line in report_lines(run, time.perf_counter() - start, cpu):
                        say(line)
                done += 1
                if options.runs and done >= options.runs:
                    return done
                say("waiting for a change ...")
    except KeyboardInterrupt:
        say("stopped watching")
        raise  # the command line's status for an interrupt, 130 (mechbook.app.cli)
    return done
