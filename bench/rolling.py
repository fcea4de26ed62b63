"""Issue 42's rows for a body rolling upright and the slowest book problem: what `mechbook
check ID -j 1` costs on this tree against a reference tree, side by side in one run.

The reference is another commit of this repository (default: the merge-base of HEAD with
main, the tree before this work), checked out into a temporary git worktree; a problem
file or answer key the reference lacks (a classic example added since) is copied into it
from this tree, so both engines check the same problem. Both trees are byte-compiled first
and run with this interpreter, each imported on its own (bench/check_time.py's launcher).
Each problem is checked in rounds, the two trees taking turns (reference, this tree, ...),
so the machine's load falls on both alike:

    wall    `mechbook check ID -j 1 --fresh --no-store`, the whole command as a user waits
            for it (start-up, the worker, the check), median of the rounds
    CPU     user + system CPU of `mechbook check ID --serial --fresh --no-store` (the same
            check in one process, whose CPU the load inflates least), median of the rounds

Every part's outcome, method and power line and every cross-check's outcome are compared
between the trees, part by part; the differences are listed (details, which hold measured
numbers such as a residual's size, are counted apart). With --profile, each problem is
run once more per tree under cProfile and its largest functions shown. Prints a Markdown
report (or --out FILE); never gates CI: timings depend on the machine and its load.

    python bench/rolling.py [--reference REF] [--ids ID ...] [--rounds N] [--profile]
                            [--out FILE]
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import tempfile
from datetime import UTC, datetime
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check_time import (  # noqa: E402 - bench/ is not a package
    hot_functions,
    profile,
    timed_check,
)

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ("classic-coin-rolling-upright", "symon-text-11-5-heavy-top",
            "classic-disk-rolling-incline", "classic-disk-rolling-on-line",
            "classic-chaplygin-sleigh")
GOAL = 3.0  # seconds of wall time per problem (issue 42)


def merge_base() -> str:
    """The commit this branch left main at: the tree before this work."""
    out = subprocess.run(["git", "-C", str(ROOT), "merge-base", "HEAD", "main"],
                         capture_output=True, text=True, check=True)
    return out.stdout.strip()


def files_of(tree: Path, pid: str) -> list[Path]:
    book, number = pid.split("-", 1)
    return [tree / "problems" / book / f"{number}.yaml",
            tree / "answers" / book / f"{number}.yaml"]


def provide(reference: Path, ids: list[str]) -> list[str]:
    """Copy into the reference tree the problem files and keys it lacks; their ids."""
    copied = []
    for pid in ids:
        for src, dst in zip(files_of(ROOT, pid), files_of(reference, pid), strict=True):
            if not dst.exists():
                dst.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(src, dst)
                copied.append(pid)
    return sorted(set(copied))


def check_once(tree: Path, pid: str, reference: bool, how: tuple[str, ...]) -> dict:
    """One `mechbook check PID HOW --fresh --no-store --format json` (HOW: `-j 1`, or
    `--serial`, whose CPU is all this process's children's): wall, CPU, outcomes."""
    doc, wall, cpu = timed_check(tree, [pid, *how], reference)
    return {"wall": wall, "cpu": cpu, **outcomes(doc)}


def outcomes(doc: dict) -> dict:
    """Each part's (status, method, power) and each cross-check's status, by name; the
    parts' and cross-checks' details apart (measured numbers, not outcomes)."""
    kept, details = {}, {}
    for p in doc["problems"]:
        for part in p["parts"]:
            key = (p["id"], "part", part["part"])
            kept[key] = (part["status"], part["method"], part["power"])
            details[key] = part["detail"]
        for c in p["crosschecks"]:
            key = (p["id"], "cross-check", c["name"])
            kept[key] = (c["status"],)
            details[key] = c["detail"]
        if p.get("error"):
            kept[(p["id"], "problem", "error")] = (p["error"],)
    return {"outcomes": kept, "details": details}


def differences(a: dict, b: dict) -> tuple[list[str], int]:
    """The entries whose outcome, method or power differ (listed), and how many details."""
    out = []
    for key in sorted(set(a["outcomes"]) | set(b["outcomes"])):
        x, y = a["outcomes"].get(key), b["outcomes"].get(key)
        if x != y:
            out.append(f"{' '.join(key)}: {x} → {y}")
    details = sum(1 for k in a["details"] if a["details"][k] != b["details"].get(k))
    return out, details


def measure(args, reference: Path) -> list[str]:
    for tree in (reference, ROOT):  # bytecode once, as on a user's machine
        subprocess.run([sys.executable, "-m", "compileall", "-q", str(tree / "mechbook")],
                       capture_output=True)
    copied = provide(reference, args.ids)
    rows, listed, profiles = [], [], []
    for pid in args.ids:
        runs, serial = {"reference": [], "this": []}, {"reference": [], "this": []}
        for r in range(args.rounds):
            for label, tree in (("reference", reference), ("this", ROOT)):
                print(f"{pid} round {r + 1} {label}", file=sys.stderr, flush=True)
                runs[label].append(check_once(tree, pid, label == "reference", ("-j", "1")))
                serial[label].append(check_once(tree, pid, label == "reference",
                                                ("--serial",)))
        wall = {k: statistics.median(x["wall"] for x in v) for k, v in runs.items()}
        cpu = {k: statistics.median(x["cpu"] for x in v) for k, v in serial.items()}
        diff, details = differences(runs["reference"][0], runs["this"][0])
        for label in runs:  # a check's outcomes do not depend on where it runs
            for other in runs[label][1:] + serial[label]:
                if differences(runs[label][0], other)[0]:
                    listed.append(f"- {pid}: {label}'s outcomes differ between its runs")
        n = len(runs["this"][0]["outcomes"])
        same = "identical" if not diff else f"{len(diff)} of {n} differ"
        rows.append(f"| {pid} | {wall['reference']:.2f} s | {wall['this']:.2f} s | "
                    f"{wall['reference'] / wall['this']:.2f}× | {cpu['reference']:.2f} s | "
                    f"{cpu['this']:.2f} s | {cpu['reference'] / cpu['this']:.2f}× | "
                    f"{'yes' if wall['this'] <= GOAL else 'no'} | {n}: {same} "
                    f"({details} details differ) |")
        listed += [f"- {pid}: {d}" for d in diff]
        if args.profile:
            for label, tree in (("reference", reference), ("this", ROOT)):
                got = profile(tree, pid, label == "reference")
                profiles.append(f"| {pid} | {label} | {got['cpu']:.2f} | "
                                f"{hot_functions(got['rows'])} |")
    load = Path("/proc/loadavg").read_text().split()[0] if Path("/proc/loadavg").exists() \
        else "?"
    when = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    out = [f"`bench/rolling.py`, {when}: this tree against {args.reference[:12]} (the "
           f"reference), {args.rounds} rounds each, the trees taking turns; load average "
           f"{load} at the end.", ""]
    if copied:
        out += [f"Copied into the reference tree (it lacks them): {', '.join(copied)}.", ""]
    out += ["| problem | wall -j 1, reference | wall -j 1, this tree | ratio | "
            "CPU --serial, reference | CPU --serial, this tree | ratio | ≤ 3 s wall | "
            "outcomes, method, power |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- |", *rows, ""]
    out += ["Outcomes that differ:", *(listed or ["- none"]), ""]
    if profiles:
        out += ["Under cProfile (one process each; cProfile slows SymPy 2-3 times): CPU s "
                "and the largest cumulative shares.", "",
                "| problem | tree | CPU s | where the time went |", "| --- | --- | --- | --- |",
                *profiles, ""]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reference", default=None,
                    help="git ref of the reference tree (default: the merge-base with main)")
    ap.add_argument("--ids", nargs="*", default=list(PROBLEMS), help="problems to time")
    ap.add_argument("--rounds", type=int, default=3, help="runs per tree and problem")
    ap.add_argument("--profile", action="store_true", help="add a cProfile run per tree")
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args()
    args.reference = args.reference or merge_base()
    with tempfile.TemporaryDirectory(prefix="mechbook-rolling-") as tmp:
        path = Path(tmp) / "reference"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(path),
                        args.reference], check=True, capture_output=True)
        try:
            report = measure(args, path)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                            str(path)], capture_output=True)
    text = "\n".join(report)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
