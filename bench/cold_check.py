"""Issue 42's cold check, side by side: this tree against a reference commit, and the same
outcomes and power lines as main, part by part.

Each tree is checked as `mechbook check BOOKS --fresh --no-store --serial --format json` in
a fresh process, with this interpreter and its packages, each tree importing its own
mechbook (PYTHONPATH, the editable install's finder dropped); the trees take turns (ref,
main, this, ref, main, this, ...) so that the machine's load falls on all alike. For each:
the CPU time of the child (user + system, `resource.getrusage`) and its wall time, the
median of the rounds. The reference (default 0834a76, the commit issue 42 measures
against) gives the ratio; main (default: the merge base of HEAD and main, so that main's
own later changes are not counted as this tree's) gives the outcomes: every part's status,
method and power line and every cross-check's status must be the same in this tree as in
main's, or the script lists the differences and exits 1 (details such as "worst relative
4.8e-32" may differ, as between two runs of one tree). Each reference tree is exported
from git into a temporary directory (removed at the end) and byte-compiled first, as an
installed tree is.

    python bench/cold_check.py [--ref 0834a76] [--main COMMIT] [--repeat 1] [BOOK_OR_ID ...]

Never gates CI: timings depend on the machine and its load; run it niced, and take the
ratio on a quiet machine.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from contextlib import ExitStack, contextmanager
from pathlib import Path

from classic_cost import check  # the one timed cold check of a tree (bench/ is on sys.path)

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = "0834a76"  # main when issue 42 was opened: its ratio is to this commit


@contextmanager
def exported(ref: str, into: Path):
    """The tree of `ref` in a temporary directory (git archive: nothing is written to the
    repository, its worktrees or its index), byte-compiled."""
    path = into / ref.replace("/", "_")
    path.mkdir()
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", "--format=tar", ref],
                             capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(path)], input=archive, check=True)
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(path / "mechbook")],
                   check=True)
    yield path


def expand(args: list[str]) -> list[str]:
    """Problem ids, a book's name (no '-') replaced by its problems' ids (0834a76's check
    knows ids only, not books)."""
    out = []
    for arg in args:
        if "-" in arg:
            out.append(arg)
        else:
            out += [f"{arg}-{p.stem}" for p in sorted((ROOT / "problems" / arg).glob("*.yaml"))]
    return out


def run(tree: Path, ids: list[str]) -> tuple[float, float, dict]:
    """(CPU seconds, wall seconds, {(problem, part or cross-check): what must not change})
    of one serial cold check of `ids` on `tree` (bench/classic_cost.py's `check`)."""
    wall, cpu, doc = check(ids, None, tree)
    return cpu, wall, outcomes(doc)


def outcomes(doc: dict) -> dict:
    """What the issue asks to stay the same: each part's status, method and power line,
    each cross-check's status, each problem's error."""
    found: dict = {}

    def put(key: tuple, value) -> None:
        n = 1
        while (key[0], f"{key[1]} #{n}" if n > 1 else key[1]) in found:
            n += 1  # a problem's two cross-checks of one name: both compared, in order
        found[(key[0], f"{key[1]} #{n}" if n > 1 else key[1])] = value

    for prob in doc["problems"]:
        put((prob["id"], "error"), prob.get("error"))
        for part in prob.get("parts", []):
            put((prob["id"], f"part {part['part']}"),
                (part["status"], part.get("method"), part.get("power")))
        for x in prob.get("crosschecks", []):
            put((prob["id"], f"cross-check {x.get('name', '')}"), x["status"])
    return found


def differences(main: dict, this: dict) -> list[str]:
    lines = []
    for key in sorted(set(main) | set(this), key=str):
        if main.get(key) != this.get(key):
            lines.append(f"  {key[0]} {key[1]}: main {main.get(key)!r}, this {this.get(key)!r}")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("ids", nargs="*", default=["lim", "symon"])
    ap.add_argument("--ref", default=REFERENCE, help="the commit the ratio is to")
    ap.add_argument("--main", default=None,
                    help="the commit the outcomes are compared with (default: the merge base "
                         "of this tree's HEAD and main, so that main's own later changes are "
                         "not counted as this tree's)")
    ap.add_argument("--repeat", type=int, default=1)
    opts = ap.parse_args()
    if opts.main is None:
        opts.main = subprocess.run(["git", "-C", str(ROOT), "merge-base", "HEAD", "main"],
                                   capture_output=True, text=True, check=True).stdout.strip()[:12]
    ids = expand(opts.ids)
    with tempfile.TemporaryDirectory(prefix="mechbook-cold-") as tmp, ExitStack() as stack:
        trees = {"ref": stack.enter_context(exported(opts.ref, Path(tmp)))}
        if opts.main != opts.ref:
            trees["main"] = stack.enter_context(exported(opts.main, Path(tmp)))
        trees["this"] = ROOT
        cpu: dict[str, list[float]] = {name: [] for name in trees}
        wall: dict[str, list[float]] = {name: [] for name in trees}
        found: dict[str, dict] = {}
        for round_ in range(opts.repeat):
            for name, tree in trees.items():
                c, w, found[name] = run(tree, ids)
                cpu[name].append(c)
                wall[name].append(w)
                print(f"round {round_ + 1}, {name}: {c:.2f} s CPU, {w:.2f} s wall",
                      file=sys.stderr)
    med = {name: (statistics.median(cpu[name]), statistics.median(wall[name])) for name in trees}
    print(f"checked: {' '.join(opts.ids)}, {len(ids)} problems (--fresh --no-store --serial), "
          f"{opts.repeat} round(s), load {os.getloadavg()[0]:.1f} at the end")
    for name, ref in (("ref", opts.ref), ("main", opts.main), ("this", "this tree")):
        if name in med:
            print(f"  {name:4} {ref:>10}: {med[name][0]:7.2f} s CPU  {med[name][1]:7.2f} s wall")
    print(f"ratio this/ref ({opts.ref}): {med['this'][0] / med['ref'][0]:.3f}× CPU, "
          f"{med['this'][1] / med['ref'][1]:.3f}× wall")
    compared = "main" if "main" in found else "ref"
    diff = differences(found[compared], found["this"])
    print(f"outcomes against {compared} ({len(found['this'])} entries: status, method and power "
          f"of every part, status of every cross-check): "
          f"{'the same' if not diff else f'{len(diff)} differ'}")
    if diff:
        print("\n".join(diff))
        sys.exit(1)


if __name__ == "__main__":
    main()
