"""What a cold `mechbook check` costs, before and after, measured side by side in one run.

"Before" is an earlier commit of this repository (default: a5b256a, main before issue 24),
checked out into a temporary git worktree; "after" is this tree (or --after REF). Both run
with this interpreter and its packages, each tree imported on its own; a before tree that
did not install gmpy2 (its constraints.txt lacks it) with SymPy's pure-Python integers
(SYMPY_GROUND_TYPES=python), as on a machine without gmpy2. Both trees are byte-compiled
first (a user's machine compiles once). Measured for each tree, the two trees taking turns:

    cold -j N     `mechbook check --fresh --no-store -j N`: the wall time, and each
                  problem's wall seconds as the workers report them
    serial CPU    `mechbook check --fresh --no-store --serial`: the CPU time of the whole
                  process (user + system), the figure a loaded machine does not inflate
    per problem   every problem checked in one process with its CPU time per stage (the
                  median and the worst problem, and where each spent its time)
    profile       the five slowest problems (of the after tree) under cProfile in a fresh
                  process each: the functions that took the most time, in both trees

The outcome of every part and cross-check is compared between the trees and the
differences listed. With --tests, `pytest -n N` is timed in both trees too. Results: a
Markdown report on stdout (or --out FILE) and a CSV of the per-problem figures (--csv FILE).
Never gates CI: timings depend on the machine and its load.

    python bench/check_time.py [--before REF] [--after REF] [--ids ID ...] [-j N]
                               [--profile N] [--tests] [--out F] [--csv F]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_BEFORE = "a5b256a"
PROFILE_LIMIT = 900  # wall seconds per profiled problem (cProfile slows SymPy 2-3 times)
TOP_FUNCTIONS = 6
# An editable install of mechbook puts a finder on sys.meta_path that serves any mechbook
# module the tree on sys.path lacks from the installed checkout: a benchmark of another
# tree would silently mix the two. Every snippet run here drops it first.
ONLY_THIS_TREE = ("import sys\n"
                  "sys.meta_path[:] = [f for f in sys.meta_path\n"
                  "                    if 'editable' not in str(getattr(f, '__module__', ''))]")

# each problem in one process: CPU per problem and per stage, outcomes (JSON on stdout)
PER_PROBLEM = ONLY_THIS_TREE + """
import json, time
from pathlib import Path
tree = Path(sys.argv[1]); sys.path.insert(0, str(tree))
from mechbook.app.running.run import RunOptions, run_problem
try:  # as the tree's own check processes run (a tree that has it: its collector settled)
    from mechbook.app.running.batch import settle
    settle(preload=True)
except ImportError:
    pass
for pid in sys.argv[2:]:
    stages, cur = {}, ["loading", time.process_time()]
    def stage(text):
        now = time.process_time()
        stages[cur[0]] = stages.get(cur[0], 0.0) + now - cur[1]
        cur[0], cur[1] = text, now
    start = time.process_time()
    run = run_problem(pid, tree, RunOptions(), stage)
    stage("end")
    print(json.dumps({"pid": pid, "cpu": time.process_time() - start, "stages": stages}),
          flush=True)
"""

# one problem under cProfile: the functions with the largest cumulative time (JSON)
PROFILE = ONLY_THIS_TREE + """
import cProfile, json, pstats, time
from pathlib import Path
tree = Path(sys.argv[1]); sys.path.insert(0, str(tree))
from mechbook.app.running.run import RunOptions, run_problem
import mechbook.verify.checker, mechbook.verify.registry, mechbook.crosscheck  # noqa
pr = cProfile.Profile()
start = time.process_time()
pr.enable(); run_problem(sys.argv[2], tree, RunOptions()); pr.disable()
cpu = time.process_time() - start
rows = []
for (file, line, name), (cc, nc, tt, ct, callers) in pstats.Stats(pr).stats.items():
    where = file.split("/site-packages/")[-1] if "site-packages" in file else \\
        file.split(str(tree) + "/")[-1]
    rows.append((ct, tt, f"{where}:{name}"))
print(json.dumps({"cpu": cpu, "rows": sorted(rows, reverse=True)[:400]}))
"""


def launcher(tree: Path) -> list[str]:
    """A command running the `mechbook` CLI of `tree` (imported from that tree only)."""
    code = (f"{ONLY_THIS_TREE}\nsys.path.insert(0, {str(tree)!r})\n"
            "from mechbook.app.cli import main\nsys.argv[0] = 'mechbook'\nmain()")
    return [sys.executable, "-c", code]


def environment(tree: Path, before: bool) -> dict:
    env = dict(os.environ, MECHBOOK_ROOT=str(tree))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    constraints = tree / "constraints.txt"
    if before and constraints.exists() and "gmpy2" not in constraints.read_text():
        env["SYMPY_GROUND_TYPES"] = "python"  # a tree that did not install gmpy2
    return env


def children_cpu() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def timed_check(tree: Path, args: list[str], before: bool) -> tuple[dict, float, float]:
    """`mechbook check ARGS --fresh --no-store --format json` in `tree`: its JSON, wall
    seconds and CPU seconds (this process's children's)."""
    cmd = launcher(tree) + ["check", *args, "--fresh", "--no-store", "--format", "json"]
    cpu0, start = children_cpu(), time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=tree,
                          env=environment(tree, before))
    wall, cpu = time.perf_counter() - start, children_cpu() - cpu0
    try:
        doc = json.loads(proc.stdout)
    except json.JSONDecodeError:
        raise SystemExit(f"{tree}: check {' '.join(args)} printed no JSON:\n"
                         f"{proc.stderr[-2000:]}") from None
    return doc, wall, cpu


def run_check(tree: Path, ids: list[str], extra: list[str], before: bool) -> dict:
    """One `mechbook check --fresh --no-store --format json`: wall, CPU, per-problem
    seconds, outcomes."""
    doc, wall, cpu = timed_check(tree, [*ids, *extra], before)
    seconds = {p["id"]: p["seconds"] for p in doc["problems"]}
    outcomes = {}
    for p in doc["problems"]:
        for part in p["parts"]:
            outcomes[(p["id"], "part", part["part"])] = part["status"]
        for c in p["crosschecks"]:
            outcomes[(p["id"], "cross-check", c["name"])] = c["status"]
        if p.get("error"):
            outcomes[(p["id"], "problem", "error")] = "error"
    return {"wall": wall, "cpu": cpu, "seconds": seconds, "outcomes": outcomes,
            "summary": doc["summary"]}


def per_problem(tree: Path, ids: list[str], before: bool) -> dict:
    proc = subprocess.run([sys.executable, "-c", PER_PROBLEM, str(tree), *ids],
                          capture_output=True, text=True, cwd=tree,
                          env=environment(tree, before))
    out = {}
    for line in proc.stdout.splitlines():
        if line.startswith("{"):
            row = json.loads(line)
            out[row["pid"]] = row
    return out


def profile(tree: Path, pid: str, before: bool) -> dict:
    try:
        proc = subprocess.run([sys.executable, "-c", PROFILE, str(tree), pid],
                              capture_output=True, text=True, cwd=tree,
                              env=environment(tree, before), timeout=PROFILE_LIMIT)
    except subprocess.TimeoutExpired:
        return {"cpu": float("inf"), "rows": []}
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    return json.loads(lines[-1]) if lines else {"cpu": float("nan"), "rows": []}


def hot_functions(rows: list, tree_marker: str = "mechbook/") -> str:
    """The largest cumulative times below the top of the call tree: SymPy's (and SciPy's)
    work and mechbook's own stages, without the call chain's wrappers."""
    skip = ("run_problem", "check_part", "crosscheck_problem", "<module>", "exec",
            "wrapper", "__get__", "_guarded", "<listcomp>", "<genexpr>", "<lambda>")
    total = rows[0][0] if rows else 0.0
    picked = []
    for ct, _, name in rows:
        if any(s in name for s in skip) or ct < 0.05 * total:
            continue
        picked.append(f"{name.split('/')[-1]} {100 * ct / total:.0f} %")
        if len(picked) >= TOP_FUNCTIONS:
            break
    return "; ".join(picked)


def time_tests(tree: Path, jobs: int, before: bool) -> float:
    code = (f"{ONLY_THIS_TREE}\nsys.path.insert(0, {str(tree)!r})\nimport pytest\n"
            f"sys.exit(pytest.main(['-q', '-n', '{jobs}', '-p', 'no:cacheprovider']))")
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], cwd=tree, capture_output=True,
                   env=environment(tree, before))
    return time.perf_counter() - start


def ids_of(tree: Path) -> list[str]:
    return sorted(f"{p.parent.name}-{p.stem}" for p in (tree / "problems").glob("*/*.yaml"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default=DEFAULT_BEFORE, help="git ref of the 'before' tree")
    ap.add_argument("--after", default=None,
                    help="git ref of the 'after' tree (default: this working tree)")
    ap.add_argument("--ids", nargs="*", default=None, help="problems (default: all in both)")
    ap.add_argument("-j", "--jobs", type=int, default=2, help="workers of the cold run")
    ap.add_argument("--profile", type=int, default=5, metavar="N",
                    help="profile the N slowest problems (0: none)")
    ap.add_argument("--tests", action="store_true", help="also time the test suites")
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--csv", type=Path, default=None)
    args = ap.parse_args()

    with tempfile.TemporaryDirectory(prefix="mechbook-bench-") as tmp:
        tmp = Path(tmp)
        made = []
        try:
            for label, ref in (("before", args.before), ("after", args.after)):
                if ref is None:
                    continue
                path = tmp / label
                subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach",
                                str(path), ref], check=True, capture_output=True)
                made.append(path)
            new = tmp / "after" if args.after else ROOT
            report = measure(args, tmp / "before", new)
        finally:
            for path in made:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                                str(path)], capture_output=True)
    text = "\n".join(report)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text + "\n")
    print(text)


def _say(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def measure(args, old: Path, new: Path) -> list[str]:
    ids = args.ids or sorted(set(ids_of(old)) & set(ids_of(new)))
    trees = (("before", old, True), ("after", new, False))
    for _, tree, _ in trees:  # bytecode once, as on a user's machine
        subprocess.run([sys.executable, "-m", "compileall", "-q", str(tree / "mechbook")],
                       capture_output=True)
    _say(f"{len(ids)} problems; before = {args.before}; after = {args.after or 'this tree'}")
    res = {label: {} for label, _, _ in trees}
    for label, tree, before in trees:
        res[label]["cold"] = run_check(tree, ids, ["-j", str(args.jobs)], before)
        _say(f"{label}: cold -j {args.jobs}: {res[label]['cold']['wall']:.1f} s wall")
    for label, tree, before in trees:
        res[label]["serial"] = run_check(tree, ids, ["--serial"], before)
        _say(f"{label}: serial: {res[label]['serial']['cpu']:.1f} s CPU")
    for label, tree, before in trees:
        res[label]["each"] = per_problem(tree, ids, before)
        _say(f"{label}: per problem done")
    out = report(args, ids, res)
    if args.profile:
        after = res["after"]["each"]
        slowest = sorted(after, key=lambda p: -after[p]["cpu"])[:args.profile]
        out += ["", f"Profiles of the {len(slowest)} slowest problems (after), cold, one "
                "process each under cProfile (which slows SymPy 2-3 times): the share of "
                "the problem's profiled time spent in each function (cumulative, so nested "
                "ones overlap).", "",
                "| problem | tree | CPU s | profiled s | where the time went |",
                "| --- | --- | --- | --- | --- |"]
        for pid in slowest:
            for label, tree, before in trees:
                prof = profile(tree, pid, before)
                cpu = res[label]["each"].get(pid, {}).get("cpu", float("nan"))
                out.append(f"| {pid} | {label} | {cpu:.2f} | {prof['cpu']:.1f} | "
                           f"{hot_functions(prof['rows'])} |")
                _say(f"profiled {pid} ({label})")
    if args.tests:
        tb = time_tests(old, args.jobs, True)
        ta = time_tests(new, args.jobs, False)
        out += ["", f"`pytest -n {args.jobs}` (each tree's own suite): before {tb:.0f} s, "
                f"after {ta:.0f} s wall."]
    if args.csv:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        nan = float("nan")
        with open(args.csv, "w") as fh:
            fh.write("problem,before_cpu_s,after_cpu_s,before_cold_wall_s,after_cold_wall_s\n")
            for pid in ids:
                row = [res[t]["each"].get(pid, {}).get("cpu", nan) for t in ("before", "after")]
                row += [res[t]["cold"]["seconds"].get(pid, nan) for t in ("before", "after")]
                fh.write(f"{pid}," + ",".join(f"{x:.3f}" for x in row) + "\n")
    return out


def report(args, ids: list[str], res: dict) -> list[str]:
    def stats(label: str) -> tuple:
        each = res[label]["each"]
        cpus = [each[p]["cpu"] for p in ids if p in each]
        worst = max(ids, key=lambda p: each.get(p, {}).get("cpu", -1.0))
        return (sum(cpus), statistics.median(cpus) if cpus else float("nan"), worst,
                each.get(worst, {}).get("cpu", float("nan")),
                sum(1 for c in cpus if c > 3.0))

    lines = [f"Measured {time.strftime('%Y-%m-%d %H:%M')} on {os.cpu_count()} cores by "
             f"`bench/check_time.py` (before = {args.before}, after = "
             f"{args.after or 'this tree'}), {len(ids)} problems, load average "
             f"{os.getloadavg()[0]:.1f} at the end.", "",
             "| | before | after | ratio |", "| --- | --- | --- | --- |"]
    b, a = res["before"], res["after"]
    rows = [(f"cold `check --fresh -j {args.jobs}`, wall", b["cold"]["wall"],
             a["cold"]["wall"]),
            ("the same, problems' wall seconds summed", sum(b["cold"]["seconds"].values()),
             sum(a["cold"]["seconds"].values())),
            ("`check --fresh --serial`, process CPU", b["serial"]["cpu"], a["serial"]["cpu"]),
            ("`check --fresh --serial`, wall", b["serial"]["wall"], a["serial"]["wall"])]
    for name, x, y in rows:
        lines.append(f"| {name} | {x:.1f} s | {y:.1f} s | {x / y:.2f}× |")
    sb, sa = stats("before"), stats("after")
    lines += [f"| problems' CPU summed (one process) | {sb[0]:.1f} s | {sa[0]:.1f} s | "
              f"{sb[0] / sa[0]:.2f}× |",
              f"| median problem, CPU | {sb[1]:.2f} s | {sa[1]:.2f} s | {sb[1] / sa[1]:.2f}× |",
              f"| worst problem, CPU | {sb[2]} {sb[3]:.2f} s | {sa[2]} {sa[3]:.2f} s | |",
              f"| problems above 3 s CPU | {sb[4]} | {sa[4]} | |"]
    diffs = [(k, b["cold"]["outcomes"].get(k), a["cold"]["outcomes"].get(k))
             for k in sorted(set(b["cold"]["outcomes"]) | set(a["cold"]["outcomes"]))
             if b["cold"]["outcomes"].get(k) != a["cold"]["outcomes"].get(k)]
    parts = [d for d in diffs if d[0][1] != "cross-check"]
    lines += ["", f"Outcomes: before {_summary(b['cold']['summary'])}; after "
              f"{_summary(a['cold']['summary'])}. Parts that differ: {len(parts)}; "
              f"cross-checks that differ (by name): {len(diffs) - len(parts)}."]
    for (pid, kind, name), x, y in diffs:
        lines.append(f"- {pid} {kind} `{name}`: {x or 'absent'} → {y or 'absent'}")
    slow = sorted(ids, key=lambda p: -a["each"].get(p, {}).get("cpu", 0.0))[:10]
    lines += ["", "The ten slowest problems after, CPU seconds in one process (before in "
              "brackets), and their largest stages after:", "",
              "| problem | before | after | largest stages after (CPU s) |",
              "| --- | --- | --- | --- |"]
    for pid in slow:
        st = sorted(a["each"][pid]["stages"].items(), key=lambda kv: -kv[1])[:3]
        lines.append(f"| {pid} | {b['each'].get(pid, {}).get('cpu', float('nan')):.2f} | "
                     f"{a['each'][pid]['cpu']:.2f} | "
                     + "; ".join(f"{k} {v:.2f}" for k, v in st) + " |")
    return lines


def _summary(s: dict) -> str:
    cc = s.get("crosschecks", {})
    return (f"{s['parts']} parts: {s['pass']} pass, {s['fail']} fail, {s['erratum']} erratum, "
            f"{s['unsupported']} unsupported, {s['error']} error; cross-checks "
            + ", ".join(f"{v} {k}" for k, v in cc.items()))


if __name__ == "__main__":
    main()
