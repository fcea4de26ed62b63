"""What a save costs under `mechbook watch`: the CPU time and the wall time of each recheck.

A real `mechbook watch PROBLEM` runs in a scratch copy of the problem and its answer key; the
key is saved `--saves` times, alternately with a wrong answer and with the right one (the
same edits as tests/test_watch.py), and each check's line ("checked in W s, CPU C s") is
read. Reported: the first check's figures, and the median, least and greatest of the
rechecks'. Issue 23's target was a recheck within one CPU second. Timings depend on the
machine and its load: never a gate, only a measure.

    python bench/watch_recheck.py [--problem lim-2031] [--saves 10]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CHECKED = re.compile(r"checked in ([0-9.]+) s, CPU ([0-9.]+) s")
WRONG = ('book: "omega < Omega"', 'book: "omega < 2*Omega"')  # lim-2031's key, part b


def _tree(tmp: Path, pid: str) -> Path:
    book, num = pid.split("-", 1)
    shutil.copy(ROOT / "books.yaml", tmp / "books.yaml")
    for kind in ("problems", "answers"):
        (tmp / kind / book).mkdir(parents=True)
        shutil.copy(ROOT / kind / book / f"{num}.yaml", tmp / kind / book / f"{num}.yaml")
    return tmp / "answers" / book / f"{num}.yaml"


def _next_check(proc: subprocess.Popen, timeout: float = 300) -> tuple[float, float]:
    end = time.monotonic() + timeout
    for line in proc.stdout:
        found = CHECKED.search(line)
        if found:
            return float(found.group(1)), float(found.group(2))
        if time.monotonic() > end:
            break
    raise SystemExit("the watch printed no check line")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--problem", default="lim-2031")
    ap.add_argument("--saves", type=int, default=10)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        key = _tree(Path(tmp), args.problem)
        good = key.read_text("utf-8")
        wrong = good.replace(*WRONG) if WRONG[0] in good else good + "\n# edited\n"
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        env.pop("PYTHONDONTWRITEBYTECODE", None)  # a user's machine keeps its bytecode
        proc = subprocess.Popen([sys.executable, "-m", "mechbook", "--root", tmp, "watch",
                                 args.problem], stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, env=env)
        try:
            first = _next_check(proc)
            rechecks = []
            for i in range(args.saves):
                time.sleep(0.5)  # past the watch's poll, so each save is seen on its own
                key.write_text(wrong if i % 2 == 0 else good, "utf-8")
                rechecks.append(_next_check(proc))
        finally:
            proc.send_signal(signal.SIGINT)
            proc.wait(30)
    walls, cpus = [w for w, _ in rechecks], [c for _, c in rechecks]
    print(f"{args.problem}: first check {first[0]:.2f} s wall, {first[1]:.2f} s CPU")
    print(f"{len(rechecks)} rechecks: CPU median {statistics.median(cpus):.2f} s "
          f"(from {min(cpus):.2f} to {max(cpus):.2f}); wall median "
          f"{statistics.median(walls):.2f} s (from {min(walls):.2f} to {max(walls):.2f})")


if __name__ == "__main__":
    main()
