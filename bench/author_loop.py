"""The author's loop, before and after, side by side in one run: cold-process CPU time of
`mechbook list`, `validate` of one problem and of its answer key, and `check ID --fresh`.

"Before" is an earlier commit (default cd60d0e, main before issue 23) checked out into a
temporary git worktree and run with this interpreter; "after" is this tree. Each command is
a fresh process with compiled bytecode already on disk (one warm-up run first: a user's
machine compiles once), run `--repeat` times alternating before/after; the CPU time counts
the process and every process it starts (worker pools included: this script makes itself
a child subreaper and waits for all of them). Medians are reported, and the ratio to a bare
`python -c pass`. Wall times on a shared machine are shown but are not the measure.

    python bench/author_loop.py [--before REF] [--repeat 3] [--out FILE]
"""

from __future__ import annotations

import argparse
import ctypes
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
DEFAULT_BEFORE = "cd60d0e"
ONLY_THIS_TREE = ("import sys\n"
                  "sys.meta_path[:] = [f for f in sys.meta_path\n"
                  "                    if 'editable' not in str(getattr(f, '__module__', ''))]")


def launcher(tree: Path) -> list[str]:
    """A command running the `mechbook` CLI of `tree` (imported from that tree only)."""
    code = (f"{ONLY_THIS_TREE}\nsys.path.insert(0, {str(tree)!r})\n"
            "from mechbook.app.cli import main\nsys.argv[0] = 'mechbook'\nmain()")
    return [sys.executable, "-c", code]


def measured(cmd: list[str], cwd: Path) -> tuple[float, float]:
    """(wall, CPU) seconds of `cmd` and all its descendants."""
    out = subprocess.run([sys.executable, __file__, "--measure", "--", *cmd], cwd=cwd,
                         capture_output=True, text=True, check=False,
                         env={k: v for k, v in os.environ.items()
                              if k != "PYTHONDONTWRITEBYTECODE"})
    data = json.loads(out.stdout.strip().splitlines()[-1])
    return data["wall"], data["cpu"]


def _measure(cmd: list[str]) -> None:
    """Run `cmd` as a child subreaper: every descendant is waited for and counted."""
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        os.execvp(cmd[0], cmd)
    while True:
        try:
            os.wait()
        except ChildProcessError:
            break
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(json.dumps({"wall": time.perf_counter() - start,
                      "cpu": usage.ru_utime + usage.ru_stime}))


def cases(tree: Path) -> list[tuple[str, list[str]]]:
    cli = launcher(tree)
    return [("mechbook list", [*cli, "list"]),
            ("mechbook validate problems/lim/2031.yaml",
             [*cli, "validate", "problems/lim/2031.yaml"]),
            ("mechbook validate answers/lim/2031.yaml",
             [*cli, "validate", "answers/lim/2031.yaml"]),
            ("mechbook check lim-2031 --fresh", [*cli, "check", "lim-2031", "--fresh",
                                                 "--no-store"])]


def main() -> None:
    if len(sys.argv) > 2 and sys.argv[1] == "--measure":
        _measure(sys.argv[3:])
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default=DEFAULT_BEFORE)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        old = Path(tmp) / "before"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(old),
                        args.before], check=True, capture_output=True)
        try:
            lines = run(old, args.repeat, args.before)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                            str(old)], check=False, capture_output=True)
    text = "\n".join(lines)
    print(text)
    if args.out:
        args.out.write_text(text + "\n", "utf-8")


def run(old: Path, repeat: int, ref: str) -> list[str]:
    bare = [sys.executable, "-c", "pass"]
    rows = []
    for (label, before), (_, after) in zip(cases(old), cases(ROOT), strict=True):
        measured(before, old)  # warm-up: bytecode compiled, files in the page cache
        measured(after, ROOT)
        b, a, base = [], [], []
        for _ in range(repeat):
            b.append(measured(before, old))
            a.append(measured(after, ROOT))
            base.append(measured(bare, ROOT))
        cpu_b = statistics.median(x[1] for x in b)
        cpu_a = statistics.median(x[1] for x in a)
        cpu_0 = statistics.median(x[1] for x in base)
        rows.append((label, cpu_b, cpu_a, cpu_0, statistics.median(x[0] for x in b),
                     statistics.median(x[0] for x in a)))
    out = [f"Cold-process CPU time, median of {repeat} (before: {ref}; after: this tree)", "",
           "| command | before CPU s | after CPU s | after / before | after / bare python "
           "| wall before s | wall after s |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for label, cb, ca, c0, wb, wa in rows:
        out.append(f"| `{label}` | {cb:.2f} | {ca:.2f} | {ca / cb:.2f} | "
                   f"{ca / max(c0, 1e-3):.0f}× | {wb:.2f} | {wa:.2f} |")
    return out


if __name__ == "__main__":
    main()
