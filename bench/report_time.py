"""`mechbook report`, before and after, side by side in one run, on the same store.

"Before" is an earlier commit (default cd60d0e, main before issue 23: every page derived
everything again, with up to 30 s of simplification a page) in a temporary git worktree;
"after" is this tree (pages from what the check stored, cached by content hash). Both read
the same store, which a `mechbook check` of this tree wrote first (`--store`, default
results/mechbook.h5). Measured, each a fresh process (CPU of it and all its workers):

    before   the old report of --problems (default: a seeded sample of --sample problems;
             --all for every one: about an hour on two cores)
    after    the new report of the same problems, cold (an empty output directory)
    all      the new report of every problem, cold (skipped with --no-all)
    rerun    the same command again with nothing changed (every page up to date)

    python bench/report_time.py [--sample 24 | --all | --problems ID ...] [--out FILE]
"""

from __future__ import annotations

import argparse
import random
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from author_loop import DEFAULT_BEFORE, launcher, measured  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def ids() -> list[str]:
    return sorted(f"{p.parent.name}-{p.stem}" for p in (ROOT / "problems").glob("*/*.yaml"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default=DEFAULT_BEFORE)
    ap.add_argument("--store", type=Path, default=ROOT / "results" / "mechbook.h5")
    ap.add_argument("--sample", type=int, default=24)
    ap.add_argument("--all", action="store_true", help="the old report of every problem")
    ap.add_argument("--problems", nargs="*", default=None)
    ap.add_argument("--no-all", action="store_true", help="skip the new report of all")
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args()
    everything = ids()
    chosen = args.problems or (everything if args.all else
                               sorted(random.Random(23).sample(everything, args.sample)))
    store = args.store.resolve()
    lines = [f"`mechbook report` before ({args.before}) and after, store {store}", "",
             "| run | problems | wall s | CPU s | CPU s a page |",
             "| --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        old = tmp / "before"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(old),
                        args.before], check=True, capture_output=True)
        try:
            runs = [("before (cold)", old, chosen, tmp / "r-before"),
                    ("after (cold)", ROOT, chosen, tmp / "r-after")]
            if not args.no_all:
                runs += [("after, all problems (cold)", ROOT, everything, tmp / "r-all"),
                         ("after, all problems, nothing changed", ROOT, everything,
                          tmp / "r-all")]
            for label, tree, problems, out in runs:
                cmd = [*launcher(tree), "--root", str(tree), "report", "--store", str(store),
                       "--out", str(out), *(problems if problems != everything else [])]
                wall, cpu = measured(cmd, tree)
                lines.append(f"| {label} | {len(problems)} | {wall:.1f} | {cpu:.1f} | "
                             f"{cpu / len(problems):.2f} |")
                print(lines[-1], flush=True)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                            str(old)], check=False, capture_output=True)
    text = "\n".join(lines)
    print(text)
    if args.out:
        args.out.write_text(text + "\n", "utf-8")


if __name__ == "__main__":
    main()
