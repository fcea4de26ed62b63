"""Cold and warm `mechbook check`, before and after, measured side by side in one run.

"Before" is an earlier commit of this repository (default: 27ee053, the last commit before
the demand-driven checker), checked out into a temporary git worktree and run with the same
interpreter and packages; "after" is this tree. Every timing is cold (a fresh store, no
cache) unless it says warm. Measured, in this order:

    before   the old `mechbook check` (one process, one core: it had no -j)
    after-1  `mechbook check -j 1` (one worker: each problem's cold time on one core)
    after-N  `mechbook check` (one worker per core: the wall time of `make check`)
    warm     the same command again, everything answered from the store

Per-problem seconds come from the progress lines each run prints; wall times from the
clock around the command. The outcome counts of both runs are printed side by side (they
must agree). With --profile ID..., each of those problems is also run under cProfile in
both trees and its time split by stage. With --tests, `pytest -n auto` is timed in both.
Results: a Markdown report on stdout (or --out FILE) and a CSV (--csv FILE). Never gates
CI: timings depend on the machine and its load.

    python bench/check_time.py [--before REF] [--profile ID ...] [--tests] [--out F] [--csv F]
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_BEFORE = "27ee053"
PROFILE_LIMIT = 600  # seconds per profiled problem (cProfile slows SymPy several times)
LINE = re.compile(r"^\[\d+/\d+\] (\S+) \(([0-9.]+) s\): (.*)$")
SUMMARY = re.compile(r"^(\d+) problems, (\d+) parts: (.*)$")
CROSS = re.compile(r"^cross-checks: (.*)$")


# An editable install of mechbook puts a finder on sys.meta_path that serves any mechbook
# module the tree on sys.path lacks from the installed checkout: a benchmark of another
# tree would silently mix the two. Every snippet run here drops it first.
ONLY_THIS_TREE = ("import sys\n"
                  "sys.meta_path[:] = [f for f in sys.meta_path\n"
                  "                    if 'editable' not in str(getattr(f, '__module__', ''))]")


def launcher(tree: Path) -> list[str]:
    """A command running the `mechbook` CLI of `tree` (imported from that tree only)."""
    code = (f"{ONLY_THIS_TREE}\nsys.path.insert(0, {str(tree)!r})\n"
            "try:\n    from mechbook.app.cli import main\n"
            "except ImportError:\n    from mechbook.cli import main\n"
            "sys.argv[0] = 'mechbook'\nmain()")
    return [sys.executable, "-c", code]


def run_check(tree: Path, ids: list[str], store: Path, extra: list[str]) -> dict:
    env = dict(os.environ, MECHBOOK_ROOT=str(tree))
    cmd = launcher(tree) + ["check", *ids, "--store", str(store), *extra]
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=tree)
    wall = time.perf_counter() - start
    seconds, summary, cross = {}, "", ""
    for line in proc.stderr.splitlines():
        m = LINE.match(line)
        if m:
            seconds[m.group(1)] = float(m.group(2))
    for line in proc.stdout.splitlines():
        if SUMMARY.match(line):
            summary = line
        elif CROSS.match(line):
            cross = line
    return {"wall": wall, "seconds": seconds, "summary": summary, "cross": cross,
            "code": proc.returncode}


def profile_problem(tree: Path, pid: str) -> dict[str, float]:
    """Seconds of one cold check of `pid` under cProfile, split into stages."""
    script = f"""
import cProfile, pstats, sys, io, json
sys.path.insert(0, {str(tree)!r})
from pathlib import Path
tree = Path({str(tree)!r})
pr = cProfile.Profile()
{ONLY_THIS_TREE}
try:
    from mechbook.app.run import run_problem  # the layout of the stages
except ImportError:
    from mechbook.run import run_problem  # the flat layout before it
call = lambda: run_problem({pid!r}, tree)
pr.enable(); call(); pr.disable()
st = pstats.Stats(pr)
out = {{}}
for (file, line, name), (cc, nc, tt, ct, callers) in st.stats.items():
    key = f"{{file.rsplit('/', 1)[-1]}}:{{name}}"
    out[key] = max(out.get(key, 0.0), ct)
total = max(ct for (_, _, _, ct, _) in st.stats.values())
out["total"] = total
print(json.dumps(out))
"""
    import json

    try:
        proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                              cwd=tree, timeout=PROFILE_LIMIT)
    except subprocess.TimeoutExpired:
        return {"total": float("inf")}  # shown as "inf": over PROFILE_LIMIT under cProfile

    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    if not lines:
        return {"total": float("nan")}
    cum = json.loads(lines[-1])
    pick = {
        "total": ["total"],
        "checking the parts": ["checker.py:check_problem", "checker.py:check_part"],
        "cross-checks": ["crosscheck.py:crosscheck_problem", "__init__.py:crosscheck_problem"],
        "derive for display": ["derive.py:derive"],
        "stored summary": ["derive.py:computed"],
        "SymPy simplify": ["simplify.py:simplify"],
        "SymPy solve": ["solvers.py:solve"],
        "symbolic proofs": ["compare.py:_symbolic_zero"],
    }
    out = {}
    for label, keys in pick.items():
        out[label] = max((cum.get(k, 0.0) for k in keys), default=0.0)
    return out


def time_tests(tree: Path) -> float:
    start = time.perf_counter()
    code = (f"{ONLY_THIS_TREE}\nsys.path.insert(0, {str(tree)!r})\nimport pytest\n"
            "sys.exit(pytest.main(['-q', '-n', 'auto', '-p', 'no:cacheprovider']))")
    subprocess.run([sys.executable, "-c", code], cwd=tree, capture_output=True)
    return time.perf_counter() - start


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default=DEFAULT_BEFORE, help="git ref of the 'before' tree")
    ap.add_argument("--after", default=None,
                    help="git ref of the 'after' tree (default: this working tree)")
    ap.add_argument("--ids", nargs="*", default=None, help="problems (default: all in both)")
    ap.add_argument("--profile", nargs="*", default=[], metavar="ID")
    ap.add_argument("--tests", action="store_true", help="also time the test suites")
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--csv", type=Path, default=None)
    args = ap.parse_args()

    with tempfile.TemporaryDirectory(prefix="mechbook-bench-") as tmp:
        tmp = Path(tmp)
        trees = {"before": args.before, "after": args.after}
        made = []
        try:
            for label, ref in trees.items():
                if ref is None:
                    continue
                path = tmp / label
                subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach",
                                str(path), ref], check=True, capture_output=True)
                made.append(path)
            new = tmp / "after" if args.after else ROOT
            report = measure(args, tmp / "before", new, tmp)
        finally:
            for path in made:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                                str(path)], capture_output=True)
    text = "\n".join(report)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text + "\n")
    print(text)


def ids_of(tree: Path) -> list[str]:
    return sorted(f"{p.parent.name}-{p.stem}" for p in (tree / "problems").glob("*/*.yaml"))


def measure(args, old: Path, new: Path, tmp: Path) -> list[str]:
    ids = args.ids or sorted(set(ids_of(old)) & set(ids_of(new)))
    cores = os.cpu_count() or 1
    print(f"{len(ids)} problems; before = {args.before}; {cores} cores", file=sys.stderr)
    before = run_check(old, ids, tmp / "before.h5", [])
    print(f"before: {before['wall']:.1f} s", file=sys.stderr)
    one = run_check(new, ids, tmp / "after1.h5", ["-j", "1"])
    print(f"after -j 1: {one['wall']:.1f} s", file=sys.stderr)
    many = run_check(new, ids, tmp / "after.h5", [])
    warm = run_check(new, ids, tmp / "after.h5", [])
    print(f"after -j {cores}: {many['wall']:.1f} s, warm {warm['wall']:.2f} s", file=sys.stderr)
    rows = []
    for pid in ids:
        b, a = before["seconds"].get(pid, float("nan")), one["seconds"].get(pid, float("nan"))
        rows.append((pid, b, a))
    if args.csv:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        with open(args.csv, "w") as fh:
            fh.write("problem,before_s,after_one_core_s\n")
            for pid, b, a in rows:
                fh.write(f"{pid},{b:.3f},{a:.3f}\n")
    out = [f"Measured {time.strftime('%Y-%m-%d')} on {cores} cores by `bench/check_time.py` "
           f"(before = {args.before}, after = this tree), {len(ids)} problems.", "",
           "| run | wall time | outcomes | cross-checks |", "| --- | --- | --- | --- |",
           f"| before: old `mechbook check` (one core) | {before['wall']:.1f} s | "
           f"{before['summary']} | {before['cross']} |",
           f"| after: `mechbook check -j 1` | {one['wall']:.1f} s | {one['summary']} | "
           f"{one['cross']} |",
           f"| after: `mechbook check` (-j {cores}, as `make check`) | {many['wall']:.1f} s | "
           f"{many['summary']} | {many['cross']} |",
           f"| after: warm rerun | {warm['wall']:.2f} s | {warm['summary']} | "
           f"{warm['cross']} |", "",
           f"Cold wall time ratio before / after (-j {cores}): "
           f"**{before['wall'] / many['wall']:.1f}×**; slowest problem after, one core: "
           f"{max(a for _, _, a in rows):.1f} s.", "",
           "Slowest problems before, and the same problems after (seconds, cold, one core):",
           "", "| problem | before | after |", "| --- | --- | --- |"]
    for pid, b, a in sorted(rows, key=lambda r: -r[1])[:15]:
        out.append(f"| {pid} | {b:.1f} | {a:.1f} |")
    if args.profile:
        out += ["", "Where the time went (cProfile, cumulative seconds, cold, one core):", ""]
        labels = None
        for pid in args.profile:
            for label, tree in (("before", old), ("after", new)):
                prof = profile_problem(tree, pid)
                if labels is None:
                    labels = list(prof)
                    out += ["| problem | tree | " + " | ".join(labels) + " |",
                            "| --- | --- | " + " | ".join("---" for _ in labels) + " |"]
                out.append(f"| {pid} | {label} | "
                           + " | ".join(f"{prof.get(k, 0.0):.1f}" for k in labels) + " |")
                print(f"profiled {pid} {label}", file=sys.stderr)
    if args.tests:
        tb, ta = time_tests(old), time_tests(new)
        out += ["", f"`pytest -n auto` (the test suite of each tree): before {tb:.0f} s, "
                f"after {ta:.0f} s."]
    return out


if __name__ == "__main__":
    main()
