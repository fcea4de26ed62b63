"""A periodically driven problem's check (issue 42, first row): this tree against a
reference tree, side by side in one run, with every outcome compared part by part.

The reference is a git worktree of REF (default: the merge-base of HEAD with main, the
tree before issue 42's work), made in a temporary directory and removed after. Both trees
run with this interpreter, each imported on its own (bench/check_time.py's launcher), both
byte-compiled first; the runs take turns (reference, this tree, reference, …) so the
machine's load falls on both alike. Each run is `mechbook check IDS --fresh --no-store -j 1
--format json`, timed by its wall clock (the check's worker is not the launcher's child,
so its CPU is not counted here: each problem's own seconds are printed as well).

Printed: the median wall and CPU of each tree and their ratio, each problem's own seconds
(as the check reports them), and for every part its status, method, detail and power line
in both trees: identical or not, and for a power line that differs, whether it is
identical once Floquet's point counts are set aside (how many points were integrated in
113 bits, how many the double-precision screen decided, and the worst resolution met
among them, which depend on how many points the search asked for, not on the verdicts).
`--profile` adds a cProfile of each problem in both trees (the functions that took the
most time). Never gates anything: timings depend on the machine and its load.

    python bench/driven.py [--ref REF] [--ids ID ...] [--repeat N] [--profile]
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check_time import (  # noqa: E402  (a sibling bench script: its launcher and profiler)
    ROOT,
    hot_functions,
    profile,
    timed_check,
)

DRIVEN = ["classic-pendulum-on-vibrating-pivot", "classic-rotating-saddle"]
FLOQUET_COUNTS = [
    (re.compile(r"Φ resolved to \S+ by Liouville's determinant over its condition at \d+ "
                r"points?"), "Φ resolved to … at … points"),
    (re.compile(r"; \d+ points? decided in double precision, where its error bound made "
                r"the 113-bit verdict certain"), ""),
]


def reference() -> str:
    got = subprocess.run(["git", "-C", str(ROOT), "merge-base", "HEAD", "main"],
                         capture_output=True, text=True)
    if got.returncode != 0 or not got.stdout.strip():
        raise SystemExit("no merge-base with main: give --ref")
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"],
                          capture_output=True, text=True).stdout.strip()
    if got.stdout.strip() == head:  # on main itself: the tree against itself says nothing
        raise SystemExit("this tree is main: give --ref (d002f7a is main before issue 42)")
    return got.stdout.strip()[:12]


def check(tree: Path, ids: list[str], before: bool) -> dict:
    """One cold check of `ids` in `tree`: wall, each problem's seconds, every part."""
    doc, wall, _ = timed_check(tree, [*ids, "-j", "1"], before)
    parts, seconds = {}, {}
    for p in doc["problems"]:
        seconds[p["id"]] = p["seconds"]
        if p.get("error"):
            parts[(p["id"], "(problem)")] = {"status": "error", "detail": p["error"]}
        for part in p["parts"]:
            parts[(p["id"], part["part"])] = {k: part.get(k) for k in
                                              ("status", "method", "detail", "power")}
    return {"wall": wall, "seconds": seconds, "parts": parts}


def without_counts(power: str | None) -> str:
    """A power line with Floquet's point counts and worst resolution set aside."""
    out = power or ""
    for pattern, stand_in in FLOQUET_COUNTS:
        out = pattern.sub(stand_in, out)
    return out


def compare(ref: dict, new: dict) -> list[str]:
    lines = ["| problem | part | status | method | detail | power line |",
             "| --- | --- | --- | --- | --- | --- |"]
    notes = []
    for key in sorted(set(ref) | set(new)):
        a, b = ref.get(key), new.get(key)
        if a is None or b is None:
            where = "this tree" if a is None else "the reference"
            lines.append(f"| {key[0]} | {key[1]} | only in {where} | | | |")
            continue
        same = {f: a.get(f) == b.get(f) for f in ("status", "method", "detail", "power")}
        power = "identical" if same["power"] else (
            "identical but Floquet's counts" if without_counts(a.get("power")) ==
            without_counts(b.get("power")) else "DIFFERS")
        lines.append(f"| {key[0]} | {key[1]} | {a.get('status')} → {b.get('status')}"
                     f"{'' if same['status'] else ' DIFFERS'} | "
                     f"{'identical' if same['method'] else 'DIFFERS'} | "
                     f"{'identical' if same['detail'] else 'DIFFERS'} | {power} |")
        for f in ("detail", "power"):
            if not same[f]:
                notes += [f"- {key[0]} `{key[1]}` {f}:", f"  - reference: {a.get(f)}",
                          f"  - this tree: {b.get(f)}"]
    return lines + ([""] + notes if notes else [])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", default=None, help="git ref of the reference tree "
                    "(default: the merge-base of HEAD with main)")
    ap.add_argument("--ids", nargs="*", default=DRIVEN, help="problems (default: the "
                    "example book's driven ones)")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each tree, taking turns")
    ap.add_argument("--profile", action="store_true", help="cProfile each problem too")
    args = ap.parse_args()
    ref = args.ref or reference()
    with tempfile.TemporaryDirectory(prefix="mechbook-driven-") as tmp:
        old = Path(tmp) / "reference"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(old),
                        ref], check=True, capture_output=True)
        try:
            lines = measure(args, ref, old, ROOT)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                            str(old)], capture_output=True)
    print("\n".join(lines))


def measure(args, ref: str, old: Path, new: Path) -> list[str]:
    trees = (("reference", old), ("this tree", new))
    for _, tree in trees:
        subprocess.run([sys.executable, "-m", "compileall", "-q", str(tree / "mechbook")],
                       capture_output=True)
    runs: dict[str, list] = {label: [] for label, _ in trees}
    for k in range(args.repeat):
        for label, tree in trees:
            runs[label].append(check(tree, args.ids, tree == old))
            print(f"round {k + 1}: {label} {runs[label][-1]['wall']:.1f} s wall",
                  file=sys.stderr, flush=True)

    def median(label: str, what: str) -> float:
        return statistics.median(r[what] for r in runs[label])

    lines = [f"Measured {time.strftime('%Y-%m-%d %H:%M')} on {os.cpu_count()} cores by "
             f"`bench/driven.py` (reference = {ref}, {args.repeat} runs of each tree taking "
             f"turns; load average {os.getloadavg()[0]:.1f} at the end): "
             f"`mechbook check {' '.join(args.ids)} --fresh --no-store -j 1`.", "",
             "| | reference | this tree | ratio |", "| --- | --- | --- | --- |"]
    x, y = median("reference", "wall"), median("this tree", "wall")
    lines.append(f"| wall, median | {x:.2f} s | {y:.2f} s | {x / y:.2f}× |")
    for pid in args.ids:
        x = statistics.median(r["seconds"].get(pid, float("nan")) for r in runs["reference"])
        y = statistics.median(r["seconds"].get(pid, float("nan")) for r in runs["this tree"])
        lines.append(f"| {pid}, its own seconds | {x:.2f} s | {y:.2f} s | {x / y:.2f}× |")
    lines += ["", "Outcomes part by part (the first run of each tree):", ""]
    lines += compare(runs["reference"][0]["parts"], runs["this tree"][0]["parts"])
    if args.profile:
        lines += ["", "| problem | tree | profiled CPU s | where the time went |",
                  "| --- | --- | --- | --- |"]
        for pid in args.ids:
            for label, tree in trees:
                prof = profile(tree, pid, tree == old)
                lines.append(f"| {pid} | {label} | {prof['cpu']:.1f} | "
                             f"{hot_functions(prof['rows'])} |")
    return lines


if __name__ == "__main__":
    main()
