"""CPU time of a cold `mechbook check` on a few problems, this tree against a base commit.

Both trees are checked by the same interpreter and packages, each importing its own
mechbook (PYTHONPATH), as `mechbook check PIDS --fresh --no-store --serial --format json`
in a fresh process; runs alternate (base, this, base, this, ...) and the CPU time of each
child (user + system, `resource.getrusage`) is summed over the problems. The outcome of
every part and cross-check must be the same in both (the script exits 1 otherwise).

    python bench/check_cpu.py [--base COMMIT] [--repeat 3] [PID ...]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PIDS = ("lim-2031", "lim-2033", "lim-2036", "lim-2040", "lim-2042", "lim-2057",
        "symon-09-18", "symon-11-08", "symon-11-15")


def export(commit: str, into: Path) -> Path:
    """The tree of `commit` (git archive: no worktree, nothing written to the repository)."""
    archive = into / "base.tar"
    with archive.open("wb") as fh:
        subprocess.run(["git", "-C", str(ROOT), "archive", commit], stdout=fh, check=True)
    tree = into / "tree"
    tree.mkdir()
    with tarfile.open(archive) as tar:
        tar.extractall(tree, filter="data")
    return tree


def run(tree: Path, pids: list[str]) -> tuple[float, dict]:
    env = {**os.environ, "PYTHONPATH": str(tree)}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run([sys.executable, "-m", "mechbook", "--root", str(tree), "check",
                          *pids, "--fresh", "--no-store", "--serial", "--format", "json"],
                         env=env, cwd=str(tree), capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    doc = json.loads(out.stdout)
    outcomes = {}
    for prob in doc["problems"]:
        for part in prob.get("parts", []):
            outcomes[(prob["id"], "part", part["part"])] = part["status"]
        for x in prob.get("crosschecks", []):
            outcomes[(prob["id"], "cross", x.get("name", ""))] = x["status"]
    return cpu, outcomes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pids", nargs="*", default=list(PIDS))
    ap.add_argument("--base", default="main",
                    help="the commit to compare with (use the merge base of a branch)")
    ap.add_argument("--repeat", type=int, default=3)
    opts = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="mechbook-base-") as tmp:
        base = export(opts.base, Path(tmp))
        times = {"base": [], "this": []}
        results = {}
        for _ in range(opts.repeat):
            for name, tree in (("base", base), ("this", ROOT)):
                cpu, outcomes = run(tree, opts.pids)
                times[name].append(cpu)
                results[name] = outcomes
                print(f"{name}: {cpu:.2f} s CPU", file=sys.stderr)
    b, t = statistics.median(times["base"]), statistics.median(times["this"])
    same = results["base"] == results["this"]
    print(f"problems: {' '.join(opts.pids)}")
    print(f"base {opts.base}: {b:.2f} s CPU (runs {', '.join(f'{x:.2f}' for x in times['base'])})")
    print(f"this tree: {t:.2f} s CPU (runs {', '.join(f'{x:.2f}' for x in times['this'])})")
    print(f"ratio this/base: {t / b:.3f}; outcomes ({len(results['this'])} parts and "
          f"cross-checks): {'the same' if same else 'DIFFERENT'}")
    if not same:
        for key in sorted(set(results["base"]) | set(results["this"])):
            if results["base"].get(key) != results["this"].get(key):
                print(f"  {key}: {results['base'].get(key)} -> {results['this'].get(key)}")
        sys.exit(1)


if __name__ == "__main__":
    main()
