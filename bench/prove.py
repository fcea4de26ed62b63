"""Issue 42's "Proofs" row: `mechbook check --prove` against a plain check, same tree, one
run, and the share of passing parts proved.

Runs `mechbook check BOOK --fresh --no-store -j 1 --format json` plain and with `--prove`,
alternating (plain, prove, plain, prove ...), each in a fresh process, and prints the ratio
of the wall times (medians) and of the problems' seconds summed, the share of passes
(erratum included) whose method is `symbolic`, and the unproved passes grouped by their
reason (the method column's "unproved: ..." tail). The outcome of every part must be the
same in both (the script exits 1 otherwise). Time it on a quiet machine: the ratio is the
figure (docs/performance.md).

    python bench/prove.py [--book lim] [--repeat 1] [--seconds 10]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from mechbook.verify.proof import UNREACHABLE  # noqa: E402 - this tree's phrases

PASSES = ("pass", "erratum")


def run(book: str, prove: bool, seconds: float) -> tuple[float, dict]:
    """(wall seconds, the JSON report) of one cold check of `book` in a fresh process."""
    cmd = [sys.executable, "-m", "mechbook", "check", book, "--fresh", "--no-store", "-j", "1",
           "--format", "json"] + (["--prove", "--prove-seconds", str(seconds)] if prove else [])
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    start = time.perf_counter()
    out = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if not out.stdout.strip():
        raise SystemExit(f"mechbook check failed: {out.stderr[-2000:]}")
    return wall, json.loads(out.stdout)


def parts(report: dict) -> dict:
    return {(p["id"], q["part"]): q for p in report["problems"] for q in p["parts"]}


def summed(report: dict) -> float:
    return sum(p["seconds"] for p in report["problems"])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--book", default="lim")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--seconds", type=float, default=10.0, help="--prove-seconds")
    ap.add_argument("--keep", type=Path, help="write the last plain.json and prove.json here")
    args = ap.parse_args()
    plain, proved = [], []
    for _ in range(args.repeat):
        plain.append(run(args.book, False, args.seconds))
        proved.append(run(args.book, True, args.seconds))
    if args.keep:
        args.keep.mkdir(parents=True, exist_ok=True)
        (args.keep / "plain.json").write_text(json.dumps(plain[-1][1]))
        (args.keep / "prove.json").write_text(json.dumps(proved[-1][1]))
    a, b = parts(plain[-1][1]), parts(proved[-1][1])
    differ = [k for k in a if k not in b or a[k]["status"] != b[k]["status"]]
    wall_a = statistics.median(w for w, _ in plain)
    wall_b = statistics.median(w for w, _ in proved)
    sum_a = statistics.median(summed(r) for _, r in plain)
    sum_b = statistics.median(summed(r) for _, r in proved)
    passes = [q for q in b.values() if q["status"] in PASSES]
    symbolic = [q for q in passes if q["method"] == "symbolic"]
    print(f"{args.book}: {len(a)} parts, {len(passes)} pass (erratum included), "
          f"{args.repeat} run(s) each, load average {os.getloadavg()[0]:.1f} at the end")
    print(f"wall: plain {wall_a:.1f} s, --prove {wall_b:.1f} s, ratio {wall_b / wall_a:.2f}x")
    print(f"problems' seconds summed: plain {sum_a:.1f} s, --prove {sum_b:.1f} s, "
          f"ratio {sum_b / sum_a:.2f}x")
    print(f"proved: {len(symbolic)} of {len(passes)} passes "
          f"({100 * len(symbolic) / max(1, len(passes)):.0f} %)")
    out_of_reach = [q for q in passes if any(q["method"].endswith(why) for why in UNREACHABLE)]
    expressible = len(passes) - len(out_of_reach)
    print(f"proved of what a proof can reach: {len(symbolic)} of {expressible} "
          f"({100 * len(symbolic) / max(1, expressible):.0f} %; {len(out_of_reach)} passes "
          "are out of any proof's reach: estimates, floating-point numbers, boundaries, "
          "limits, integrations, counts)")
    reasons = Counter(q["method"].split("; unproved: ", 1)[-1] for q in passes
                      if q["method"] != "symbolic")
    for why, n in reasons.most_common():
        kinds = Counter(q["quantity"] for q in passes if q["method"] != "symbolic"
                        and q["method"].endswith(why))
        print(f"  {n:3d} unproved: {why} ({', '.join(f'{k} {v}' for k, v in kinds.items())})")
    print(f"parts whose outcome differs: {len(differ)}" + (f" {differ[:10]}" if differ else ""))
    return 1 if differ else 0


if __name__ == "__main__":
    raise SystemExit(main())
