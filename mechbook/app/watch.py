"""`mechbook watch ID`: check a problem again each time its files are saved.

Writing a problem is a loop of edit, save, check. A fresh `mechbook check` process spends
most of its second importing SymPy, SciPy and the engine; here they are imported once and
the process stays, so a save is answered in about the time the check itself takes (a few
tenths of a second for a problem with one degree of freedom). The problem file, its answer
key and books.yaml are polled (their size, time and content hash: an editor's save that
changes nothing is not a change); each check runs in this process under a CPU time limit,
and its outcome is printed part by part, with the detail of every part that did not pass
and the notes (warnings) of the run. Nothing is written to the store.
"""

from __future__ import annotations

import hashlib
import resource
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from mechbook.app.console import STATUS_ORDER
from mechbook.errors import MechbookError
from mechbook.records import Status

POLL_SECONDS = 0.1


def _cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


@dataclass(frozen=True)
class WatchOptions:
    crosscheck: bool = True
    seconds: float = 120.0  # CPU time allowed per check
    poll: float = POLL_SECONDS
    runs: int = 0  # stop after this many checks (0: until interrupted; for tests)


def _signature(paths: list[Path]) -> tuple:
    """What a change is: a file's size, time and content (a touch alone is not one)."""
    out = []
    for path in paths:
        try:
            st = path.stat()
            out.append((st.st_size, st.st_mtime_ns, hashlib.sha256(path.read_bytes())
                        .hexdigest() if st.st_size < 1 << 20 else ""))
        except OSError:
            out.append(None)
    return tuple(out)


def _changed(old: tuple, new: tuple) -> bool:
    if old is None:
        return True
    return any((a is None) != (b is None) or (a and b and (a[0], a[2]) != (b[0], b[2]))
               for a, b in zip(old, new, strict=True))


def report_lines(run, seconds: float, cpu: float) -> list[str]:
    """The outcome of one check as lines: a summary, then each part that did not pass."""
    from collections import Counter

    if run.error:
        return [f"{run.pid}: {run.error}", f"  ({seconds:.2f} s, CPU {cpu:.2f} s)"]
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
    run (when `options.runs` stops it, or the user interrupts)."""
    from mechbook.app.run import RunOptions, run_problem
    from mechbook.core.timeout import Timeout, hard_time_limit
    from mechbook.model.catalog import answer_path, problem_path

    paths = [problem_path(pid, base), answer_path(pid, base), base / "books.yaml"]
    say(f"watching {', '.join(str(p.relative_to(base)) for p in paths[:2])} "
        "(Ctrl-C to stop)")
    import mechbook.crosscheck  # noqa: F401 - the engine, once: every save is answered warm
    import mechbook.verify.checker  # noqa: F401

    last = None
    done = 0
    stage = {"at": "loading"}

    def reached(text: str) -> None:
        stage["at"] = text

    try:
        while True:
            now = _signature(paths)
            if not _changed(last, now):
                time.sleep(options.poll)
                continue
            if last is not None:
                names = [str(p.relative_to(base)) for p, a, b in zip(paths, last, now,
                                                                      strict=True) if a != b]
                say(f"\n{', '.join(names)} changed: checking {pid} again")
            last = now
            if now[0] is None:
                say(f"{paths[0]}: no such file (yet)")
                continue
            start, cpu = time.perf_counter(), _cpu()
            stage["at"] = "loading"
            try:
                with hard_time_limit(options.seconds):
                    run = run_problem(pid, base, RunOptions(crosscheck=options.crosscheck),
                                      stage=reached)
            except Timeout:
                say(f"{pid}: gave up after {options.seconds:g} s of CPU time in "
                    f"{stage['at']}")
            except MechbookError as exc:
                say(f"{pid}: {exc}")
            else:
                for line in report_lines(run, time.perf_counter() - start, _cpu() - cpu):
                    say(line)
            done += 1
            if options.runs and done >= options.runs:
                return done
            say("waiting for a change ...")
    except KeyboardInterrupt:
        say("stopped watching")
    return done
