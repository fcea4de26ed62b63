"""How fast the command line answers: `mechbook --help` (and other commands that must not
load the engine) against a bare interpreter start, median of repeated runs.

    python bench/cli_startup.py [--repeat 20]

The figure goes in docs/performance.md. Wall-clock times on a shared machine are noisy; the
median of many runs and the ratio to `python -c pass` measured in the same loop are what to
compare.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def timed(cmd: list[str], repeat: int) -> tuple[float, float]:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       check=False)
        times.append(time.perf_counter() - start)
    return statistics.median(times), min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=20)
    args = ap.parse_args()
    py = sys.executable
    cases = [("python -c pass", [py, "-c", "pass"]),
             ("python -c 'import mechbook'", [py, "-c", "import mechbook"]),
             ("mechbook --help", [str(BIN / "mechbook"), "--help"]),
             ("python -m mechbook --help", [py, "-m", "mechbook", "--help"]),
             ("mechbook check --help", [str(BIN / "mechbook"), "check", "--help"]),
             ("mechbook check --bogus (argument error)",
              [str(BIN / "mechbook"), "check", "--bogus"]),
             ("mechbook list", [str(BIN / "mechbook"), "list"])]
    base = None
    print(f"{'command':<42} {'median s':>9} {'min s':>7} {'x bare':>7}")
    for label, cmd in cases:
        med, low = timed(cmd, args.repeat)
        base = base or med
        print(f"{label:<42} {med:9.3f} {low:7.3f} {med / base:7.1f}")


if __name__ == "__main__":
    main()
