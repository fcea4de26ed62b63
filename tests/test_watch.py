"""`mechbook watch`: a save is answered by a check in the same, warm process.

A real `mechbook watch lim-2031` runs in a scratch tree; the answer key is edited (a wrong
critical speed), then put back. Each save must be followed by a check that reports the
change (a fail, then all pass). What a recheck costs, against issue 23's target of one CPU
second, is measured by bench/watch_recheck.py and printed here, not asserted: CI never gates
on time (an absolute bound failed at 1.06 s under load, and a bound relative to the first
check too, which the fork server's imports make as cheap as a recheck). Ctrl-C ends it
without a traceback.
"""

from __future__ import annotations

import contextlib
import os
import queue
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CHECKED = re.compile(r"checked in ([0-9.]+) s, CPU ([0-9.]+) s")


def _tree(tmp: Path) -> Path:
    shutil.copy(ROOT / "books.yaml", tmp / "books.yaml")
    for kind in ("problems", "answers"):
        (tmp / kind / "lim").mkdir(parents=True)
        shutil.copy(ROOT / kind / "lim" / "2031.yaml", tmp / kind / "lim" / "2031.yaml")
    return tmp


def _reader(proc, lines: queue.Queue) -> None:
    for line in proc.stdout:
        lines.put(line.rstrip("\n"))
    lines.put(None)


def _until(lines: queue.Queue, pattern: str, seen: list[str], timeout: float = 120) -> str:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            line = lines.get(timeout=max(0.01, end - time.monotonic()))
        except queue.Empty:
            break
        if line is None:
            break
        seen.append(line)
        if re.search(pattern, line):
            return line
    raise AssertionError(f"no line matching {pattern!r}; output:\n" + "\n".join(seen))


@pytest.mark.slow
def test_watch_rechecks_on_every_save(tmp_path):
    tree = _tree(tmp_path)
    key = tree / "answers" / "lim" / "2031.yaml"
    good = key.read_text("utf-8")
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    # a shell that ran these tests in the background ignores SIGINT for its children, and
    # Python then never turns it into KeyboardInterrupt: restore it, as a terminal would
    proc = subprocess.Popen([sys.executable, "-m", "mechbook", "--root", str(tree), "watch",
                             "lim-2031"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=_reader, args=(proc, lines), daemon=True).start()
    seen: list[str] = []
    try:
        first = _until(lines, r"lim-2031: .*checked in", seen)
        assert "6 pass" in first
        cold = float(CHECKED.search(first).group(2))
        _until(lines, "waiting for a change", seen)
        saved = time.monotonic()
        key.write_text(good.replace('book: "omega < Omega"', 'book: "omega < 2*Omega"'),
                       "utf-8")
        line = _until(lines, r"lim-2031: .*checked in", seen)
        answered = time.monotonic() - saved
        assert "1 fail" in line, line
        cpu = float(CHECKED.search(line).group(2))
        _until(lines, r"stability_condition\s+fail", seen)
        _until(lines, "waiting for a change", seen)
        key.write_text(good, "utf-8")
        line = _until(lines, r"lim-2031: .*checked in", seen)
        assert "6 pass" in line, (first, line)
        _until(lines, "waiting for a change", seen)
        print(f"save answered after {answered:.2f} s wall, {cpu:.2f} s CPU (cold {cold:.2f} s)")
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(30)
        except subprocess.TimeoutExpired:
            proc.kill()
    rest = []
    while True:
        try:
            item = lines.get(timeout=5)
        except queue.Empty:
            break
        if item is None:
            break
        rest.append(item)
    assert "stopped watching" in rest, rest
    assert proc.returncode == 130  # Ctrl-C: the status of every command (issue 44)
    assert not any("Traceback" in s or "Warning" in s for s in seen + rest)


def test_watch_names_a_missing_problem(tmp_path):
    tree = _tree(tmp_path)
    result = subprocess.run([sys.executable, "-m", "mechbook", "--root", str(tree), "watch",
                             "lim-2099"], capture_output=True, text=True, timeout=120)
    assert result.returncode == 5  # nothing selected
    assert "no problem" in result.stderr or "2099" in result.stderr
    assert "Traceback" not in result.stderr


# ---- issue 33: what an editor or a user can leave behind, and the limits of `check` ------
def _watch(tree: Path, *args: str):
    """A real `mechbook watch`, its address space bounded to 2 GB (a read without bound
    then fails in it instead of filling the machine), its lines read on a thread."""
    from hostile import limited

    # PYTHONFAULTHANDLER: a watch that crashes, or that _hung_ ends with SIGABRT, prints
    # where each of its threads was
    env = dict(os.environ, PYTHONUNBUFFERED="1", PYTHONFAULTHANDLER="1")
    proc = subprocess.Popen([sys.executable, "-m", "mechbook", "--root", str(tree), "watch",
                             *args], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, env=env, preexec_fn=limited())
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=_reader, args=(proc, lines), daemon=True).start()
    return proc, lines


def _hung(proc, lines: queue.Queue, seen: list[str], pattern: str,
          timeout: float = 60) -> str:
    """`_until`, and when no line matches: whether the watch is still running and, if it
    is, where it was (its stack, from SIGABRT under PYTHONFAULTHANDLER), in the message: a
    missed save seen once in `make test-min` left no trace of its cause."""
    try:
        return _until(lines, pattern, seen, timeout=timeout)
    except AssertionError as exc:
        state = f"exit status {proc.poll()}" if proc.poll() is not None else "still running"
        if proc.poll() is None:
            proc.send_signal(signal.SIGABRT)
            with contextlib.suppress(AssertionError):
                _until(lines, "(?!)", seen, timeout=10)  # its stack, until it ends
        raise AssertionError(f"{exc}\nthe watch was {state}; after SIGABRT:\n"
                             + "\n".join(seen[-60:])) from None


def _stop(proc) -> None:
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(30)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


@pytest.mark.slow
def test_watch_survives_special_files_and_links_in_place_of_its_files(tmp_path):
    """On 0834a76 a FIFO in place of the problem file blocked the watch for ever (later
    saves were missed) and a link to /dev/zero was read until memory ran out; a FIFO or
    /dev/zero as books.yaml the same. Each is now noticed, said, and the watch goes on."""
    tree = _tree(tmp_path)
    problem = tree / "problems" / "lim" / "2031.yaml"
    good = problem.read_bytes()
    books = tree / "books.yaml"
    books_text = books.read_bytes()
    proc, lines = _watch(tree, "lim-2031", "--no-crosscheck")
    seen: list[str] = []

    def replace(path: Path, how: str) -> None:
        """In one step (built beside it, then renamed over it), as an editor saves: with an
        unlink first, a watch that looked in between saw the file missing, kept the tree it
        had, and passed (seen once in CI under load)."""
        new = path.with_name(path.name + ".new")
        if how == "fifo":
            os.mkfifo(new)
        elif how == "devzero":
            new.symlink_to("/dev/zero")
        elif how == "large":
            new.write_bytes(b"# " + b"x" * 300_000 + b"\n")
        else:
            new.write_bytes(how)
        os.replace(new, path)

    try:
        assert "6 pass" in _until(lines, r"lim-2031: .*checked in", seen)
        _until(lines, "waiting for a change", seen)
        for path, how, said in [(problem, "fifo", "not a regular file"),
                                (problem, "devzero", "/dev/zero"),
                                (problem, "large", "file too large"),
                                (books, "fifo", "not a regular file"),
                                (books, "devzero", "read only from inside the tree")]:
            replace(path, how)
            line = _hung(proc, lines, seen, r"^lim-2031: ")
            assert said in line, (how, line)
            _hung(proc, lines, seen, "waiting for a change")
            replace(path, good if path == problem else books_text)
            assert "6 pass" in _hung(proc, lines, seen, r"lim-2031: .*checked in")
            _hung(proc, lines, seen, "waiting for a change")
    finally:
        _stop(proc)
    assert proc.returncode == 130  # Ctrl-C (issue 44)
    assert not any("Traceback" in s or "MemoryError" in s for s in seen)


def _bomb_tree(tmp: Path) -> Path:
    """The starter tree whose problem's potential, (r + theta + m + k + l0 + g)**64, makes
    the check of its Lagrangian expand it: gigabytes within a minute."""
    subprocess.run([sys.executable, "-m", "mechbook", "init", str(tmp / "tree")], check=True,
                   capture_output=True)
    path = tmp / "tree" / "problems" / "mybook" / "1.1.yaml"
    text = path.read_text("utf-8").split("springs:")[0]
    path.write_text(text + 'potential: "(r + theta + m + k + l0 + g)**64"\n', "utf-8")
    return tmp / "tree"


@pytest.mark.slow
@pytest.mark.parametrize("limit, said", [(["--memory", "700"], "exceeded the memory bound of "
                                                               "700 MB while in stage"),
                                         (["--timeout", "5", "--memory", "0"],
                                          "exceeded the time limit of 5 s while in stage")])
def test_watch_checks_under_the_limits_of_check(tmp_path, limit, said):
    """On 0834a76 watch had a CPU limit only, no memory bound: this 400-byte problem grew
    to gigabytes and ended in "MemoryError: " with no reason. Each check now runs in a
    worker under check's --timeout and --memory, stopped from outside, and the watch goes
    on."""
    tree = _bomb_tree(tmp_path)
    proc, lines = _watch(tree, "mybook-1.1", "--no-crosscheck", *limit)
    seen: list[str] = []
    try:
        line = _until(lines, r"^mybook-1.1: ", seen, timeout=240)
        assert said in line, line
        _until(lines, "waiting for a change", seen, timeout=60)
    finally:
        _stop(proc)
    out = "\n".join(seen + [ln for ln in iter(lambda: lines.get(timeout=10), None)])
    assert proc.returncode == 130, out  # Ctrl-C (issue 44)
    assert "stopped watching" in out
