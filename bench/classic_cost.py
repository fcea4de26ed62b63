"""What the example book `classic` adds to a cold `mechbook check` of the books (issues 39, 40).

Both issues allow the example problems at most 10 % of the cold `make check`. Measured on
this tree, in one run, the two configurations taking turns:

    books      `mechbook check lim symon --fresh --no-store -j N --format json`
    + classic  `mechbook check lim symon classic --fresh --no-store -j N --format json`

Each run's wall time and its problems' worker seconds (as the workers report them) are
taken; the ratio the issues ask for is the wall time of `+ classic` over `books`, less one,
and, in the same `+ classic` run, classic's worker seconds over the books' (the figure the
order of the problems in the pool does not move). With --cpu, both sets are checked once
more `--serial` in one process each, and their CPU time (user + system: the figure a
loaded machine does not inflate) is compared too. Every classic part must pass, no
problem may end in an error, and the books' outcomes (status and power line of each part,
each cross-check) must be the same in both configurations (exit 1 otherwise). The classic
problems' seconds are listed, the slowest first. Never gates CI: timings depend on the
machine and its load.

With --cpu the serial figure is the margin: the CPU time of `books + classic` in one
process less that of `books` in one process (start-up and imports are paid once either
way, so they are not classic's). With --before REF, the issues' own wording is measured
too: this tree's cold `make check` (every book, classic included) against REF's (main
before issues 39 and 40, 83adced: every book it had), side by side, REF checked out in a
temporary git worktree and run on the same interpreter.

    python bench/classic_cost.py [-j N] [--repeat 1] [--cpu] [--books lim symon]
                                 [--before REF]
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
BUDGET = 0.10  # the issues' limit: classic adds at most 10 % to the cold check
BEFORE = "83adced"  # main before issues 39 and 40 (no classic book)
# `python -m mechbook` with an editable install's finder dropped, so that the tree on
# PYTHONPATH is the only mechbook (bench/power.py does the same)
ONLY_THIS_TREE = ("import sys, runpy\n"
                  "sys.meta_path[:] = [f for f in sys.meta_path\n"
                  "                    if 'editable' not in str(getattr(f, '__module__', ''))]\n"
                  "sys.argv[0] = 'mechbook'\n"
                  "runpy.run_module('mechbook', run_name='__main__', alter_sys=True)")


def check(ids: list[str], jobs: int | None, tree: Path = ROOT) -> tuple[float, float, dict]:
    """(wall seconds, CPU seconds of the child and of the children it waited for, the JSON
    document) of one cold check of `ids` (every book: []) on `tree` (`jobs` None: --serial,
    the only way whose CPU figure is complete)."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # timed as on a user's machine
    how = ["--serial"] if jobs is None else ["-j", str(jobs)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", ONLY_THIS_TREE, "--root", str(tree), "check",
                          *ids, "--fresh", "--no-store", *how, "--format", "json"],
                         env=env, cwd=str(tree), capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    try:
        doc = json.loads(out.stdout)
    except json.JSONDecodeError:
        sys.exit(f"mechbook check {' '.join(ids)} gave no JSON (exit {out.returncode}):\n"
                 f"{out.stderr[-2000:]}")
    return wall, cpu, doc


def outcomes(doc: dict) -> dict:
    """{(problem, 'part', name): (status, power), (problem, 'cross', name, parts): status}."""
    found = {}
    for prob in doc["problems"]:
        for part in prob.get("parts", []):
            found[(prob["id"], "part", part["part"])] = (part["status"], part.get("power"))
        for x in prob.get("crosschecks", []):
            found[(prob["id"], "cross", x["name"], tuple(x["parts"]))] = x["status"]
        if prob.get("error"):
            found[(prob["id"], "error")] = prob["error"]
    return found


def seconds(doc: dict, classic: bool) -> dict[str, float]:
    """Each problem's worker seconds, of the classic book's problems or of the others."""
    return {p["id"]: p["seconds"] for p in doc["problems"] if (p["book"] == "classic") == classic}


def not_passing(doc: dict) -> list[str]:
    """The classic parts that do not pass, and the problems that ended in an error (every
    classic key is an own derivation: each of its parts passes)."""
    return [f"{p['id']}/{part['part']}: {part['status']}" for p in doc["problems"]
            if p["book"] == "classic" for part in p.get("parts", [])
            if part["status"] != "pass"] + \
        [f"{p['id']}: {p['error']}" for p in doc["problems"] if p.get("error")]


def compiled(tree: Path) -> None:
    """Byte-compile `tree`'s package first, so that no run pays for it (nor for writing it
    where PYTHONDONTWRITEBYTECODE is unset)."""
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(tree / "mechbook")],
                   check=False, capture_output=True)


def before_ratio(ref: str, jobs: int, repeat: int, cpu: bool) -> None:
    """This tree's cold `make check` (every book) against `ref`'s, alternating, the median of
    `repeat` rounds each: the issues' ratio "against main before this issue". Wall time
    with `jobs` workers (as `make check`); with `cpu`, the CPU time of each checked
    `--serial` in one process as well (a fork server's workers are not this process's
    children, so their CPU is not counted under -j)."""
    with tempfile.TemporaryDirectory(prefix="mechbook-classic-cost-") as tmp:
        old = Path(tmp) / "before"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(old),
                        ref], check=True)
        try:
            compiled(old)
            walls: dict[str, list[float]] = {"before": [], "now": []}
            cpus: dict[str, list[float]] = {"before": [], "now": []}
            for _ in range(repeat):
                for name, tree in (("before", old), ("now", ROOT)):
                    runs = [(jobs, walls)] + ([(None, cpus)] if cpu else [])
                    for how, into in runs:
                        wall, used, doc = check([], how, tree)
                        into[name].append(wall if how is not None else used)
                        if any(p.get("error") for p in doc["problems"]):
                            sys.exit(f"{name}: a problem ended in an error")
            wb, wn = statistics.median(walls["before"]), statistics.median(walls["now"])
            print(f"cold `make check` (every book), this tree against {ref}, median of "
                  f"{repeat}: -j {jobs} {wn:.1f} s against {wb:.1f} s wall "
                  f"({wn / wb:.3f}x; budget {1 + BUDGET:.2f}x)")
            if cpu:
                cb, cn = statistics.median(cpus["before"]), statistics.median(cpus["now"])
                print(f"  serial CPU: {cn:.1f} s against {cb:.1f} s ({cn / cb:.3f}x)")
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(old)],
                           check=False)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-j", "--jobs", type=int, default=0, help="workers (0: one per core, as "
                    "`make check`)")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--cpu", action="store_true", help="also the serial CPU time of each set")
    ap.add_argument("--books", nargs="+", default=["lim", "symon"])
    ap.add_argument("--before", metavar="REF", nargs="?", const=BEFORE, default=None,
                    help=f"also this tree's cold `make check` against REF's (default {BEFORE})")
    opts = ap.parse_args()
    compiled(ROOT)
    walls: dict[str, list[float]] = {"books": [], "all": []}
    shares, docs, bad = [], {}, []
    for rnd in range(opts.repeat):
        for name, ids in (("books", opts.books), ("all", [*opts.books, "classic"])):
            wall, _, doc = check(ids, opts.jobs)
            walls[name].append(wall)
            docs.setdefault(name, []).append(doc)
            bad += not_passing(doc) if name == "all" else []
            print(f"round {rnd + 1} {name}: {wall:.1f} s wall", file=sys.stderr)
        last = docs["all"][-1]
        shares.append(sum(seconds(last, True).values()) / sum(seconds(last, False).values()))
    same = all(outcomes(a) == {k: v for k, v in outcomes(b).items()
                               if not k[0].startswith("classic-")}
               for a, b in zip(docs["books"], docs["all"], strict=True))
    wb, wa = statistics.median(walls["books"]), statistics.median(walls["all"])
    print(f"cold check -j {opts.jobs}, median of {opts.repeat} round(s), one tree "
          f"({ROOT.name}):")
    print(f"  books ({' '.join(opts.books)}): {wb:.1f} s wall; + classic: {wa:.1f} s wall; "
          f"classic adds {100 * (wa / wb - 1):+.1f} % of the wall time (budget "
          f"{100 * BUDGET:.0f} %)")
    print(f"  worker seconds in the + classic run: classic / books = "
          f"{100 * statistics.median(shares):.1f} %")
    if opts.cpu:
        _, cb, _ = check(opts.books, None)
        _, ca, _ = check([*opts.books, "classic"], None)
        print(f"  serial CPU: books {cb:.1f} s, books + classic {ca:.1f} s: classic adds "
              f"{ca - cb:.1f} s, {100 * (ca - cb) / cb:+.1f} % (budget {100 * BUDGET:.0f} %)")
    if opts.before:
        before_ratio(opts.before, opts.jobs, opts.repeat, opts.cpu)
    last = docs["all"][-1]
    classic = sorted(seconds(last, True).items(), key=lambda kv: -kv[1])
    print(f"classic problems, worker seconds (last round; {sum(v for _, v in classic):.1f} s "
          f"against the books' {sum(seconds(last, False).values()):.1f} s):")
    for pid, sec in classic:
        print(f"  {sec:6.2f}  {pid}")
    print(f"outcomes: books the same in both configurations: {'yes' if same else 'NO'}; "
          f"not passing: {len(bad)}")
    for a, b in zip(docs["books"], docs["all"], strict=True):
        books, both = outcomes(a), outcomes(b)
        for k in sorted(set(books) | {k for k in both if not k[0].startswith("classic-")},
                        key=str):
            if books.get(k) != both.get(k):
                print(f"  differs: {k}: books {books.get(k)!r}; + classic {both.get(k)!r}")
    for line in bad:
        print(f"  {line}")
    if bad or not same:
        sys.exit(1)


if __name__ == "__main__":
    main()
