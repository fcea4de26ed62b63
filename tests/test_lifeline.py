"""Issue 21: workers die with their parent. After `kill -9` of a run, no process of it (its
workers, the fork server, the resource tracker) is alive within 2 s; before, a worker went on
computing at 100 % CPU for minutes. Real processes, real SIGKILL."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from hostile import ROOT

pytestmark = pytest.mark.slow  # kills real worker-spawning runs

GRACE = 2.0  # seconds the issue allows


def _session(sid: int) -> list[tuple[int, str]]:
    """Live (not zombie) processes of session `sid`, with their command lines."""
    out = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as fh:
                fields = fh.read().rsplit(b")", 1)[1].split()
            if int(fields[3]) == sid and fields[0] != b"Z":
                with open(f"/proc/{entry}/cmdline", "rb") as fh:
                    out.append((int(entry), fh.read().replace(b"\0", b" ").decode()[:120]))
        except (OSError, IndexError, ValueError):
            continue
    return out


def _kill_and_watch(proc: subprocess.Popen, workers: int,
                    into: float = 1.0) -> list[tuple[int, str]]:
    """Wait until the run has its workers, `into` seconds more, SIGKILL it, and return what
    of its session is still alive GRACE seconds later (cleaning up after the test)."""
    deadline = time.monotonic() + 120
    while len(_session(proc.pid)) < workers + 3 and time.monotonic() < deadline:
        time.sleep(0.2)
    assert len(_session(proc.pid)) >= workers + 3, _session(proc.pid)  # + run, server, tracker
    time.sleep(into)  # into the work
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    end = time.monotonic() + GRACE
    while _session(proc.pid) and time.monotonic() < end:
        time.sleep(0.05)
    left = _session(proc.pid)
    for pid, _ in left:
        os.kill(pid, signal.SIGKILL)
    return left


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs /proc")
def test_kill_9_of_check_leaves_no_process_of_the_run(tmp_path):
    """`mechbook check -j 2` killed with -9 while its two workers compute: the whole session
    is gone within 2 s. The two problems spend most of their time in one long stage (a
    cross-check of about 6 s each, after 1-3 s of others): a worker without its lifeline
    would finish that stage first, long after the 2 s."""
    for book, num in (("lim", "2057"), ("symon", "09-07")):
        for folder in ("problems", "answers"):
            (tmp_path / folder / book).mkdir(parents=True, exist_ok=True)
            shutil.copy(ROOT / folder / book / f"{num}.yaml", tmp_path / folder / book)
    shutil.copy(ROOT / "books.yaml", tmp_path)
    proc = subprocess.Popen([sys.executable, "-m", "mechbook", "check", "-j", "2", "--fresh",
                             "--store", str(tmp_path / "s.h5")], cwd=tmp_path,
                            start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    assert _kill_and_watch(proc, 2, into=3.5) == []


SPINNER = textwrap.dedent("""\
    import sys
    sys.path.insert(0, {tests!r})
    from pathlib import Path
    from mechbook.app.running.batch import Batch, BatchOptions
    import test_lifeline
    Batch(Path("."), BatchOptions(jobs=2, timeout=600, memory_mb=0),
          task=test_lifeline.spin).run(["a", "b", "c"])
""")


def spin(item, base, options, stage):
    """A task that computes for ever (pure Python, holding the GIL between switches)."""
    stage("spinning")
    x = 0
    while True:
        x = (x * 31 + 7) % 1_000_003


def test_kill_9_of_a_batch_with_spinning_workers(tmp_path):
    """The batch machinery alone (what check, simulate and the fuzzer run on), with tasks
    that never end: killed with -9, nothing of it is left within 2 s."""
    script = SPINNER.format(tests=str(ROOT / "tests"))
    proc = subprocess.Popen([sys.executable, "-c", script], cwd=tmp_path,
                            start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    assert _kill_and_watch(proc, 2) == []


def test_a_worker_started_after_its_run_died_does_not_run(tmp_path):
    """die_with on a process already gone kills the caller at once."""
    script = textwrap.dedent("""\
        import os, subprocess, sys, time
        from mechbook.app.running.lifeline import die_with
        gone = subprocess.Popen([sys.executable, "-c", "pass"]); gone.wait()
        die_with(gone.pid)
        time.sleep(30)
        print("still alive")
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=20)
    assert done.returncode == -signal.SIGKILL
    assert "still alive" not in done.stdout
