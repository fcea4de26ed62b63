"""Where a cold serial `mechbook check` spends its CPU time, by stage (a CPU-time sampler).

Runs the problems as `mechbook check IDS --fresh --no-store --serial` does (settle(preload),
then run_problem one after another in this process) under a sampler driven by the process's
CPU clock (`signal.setitimer(ITIMER_PROF)`: a sample every 1/RATE s of user + system time,
each weighted by the CPU time since the one before, so a long call into C that delays the
signal is counted whole). Each sample is filed three ways:

    stage      what run_problem was told (loading, validating, "part a (frequencies)" as
               the quantity's family, cross-check kind, storing) or start-up before it
    mechbook   the innermost mechbook module on the stack (what the engine was doing)
    operation  the outermost SymPy / SymEngine / SciPy / mpmath / NumPy call made from
               mechbook (what it cost in the library)

Prints three tables (CPU seconds and shares) and, with --json FILE, the raw tallies.
The sampler costs a few per cent; the totals are CPU seconds of this process.

    python bench/cold_profile.py [--rate 200] [--top 25] [--json F] [ID ...]   (default: lim symon)
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import time
from collections import Counter, defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LIBRARIES = ("sympy", "symengine", "scipy", "mpmath", "numpy", "heyoka", "h5py", "yaml",
             "ruamel", "jsonschema", "click")


def _where(filename: str) -> tuple[str, str] | None:
    """('mechbook', 'engine/lagrange') or ('sympy', 'simplify') for a frame's file; None for
    the standard library and the rest."""
    path = filename.replace("\\", "/")
    if "/mechbook/" in path and "/site-packages/" not in path:
        tail = path.rsplit("/mechbook/", 1)[1]
        return "mechbook", tail.removesuffix(".py")
    for lib in LIBRARIES:
        marker = f"/site-packages/{lib}/"
        if marker in path:
            return lib, path.split(marker, 1)[1].split("/", 1)[0].removesuffix(".py")
    return None


class Sampler:
    """Samples the main thread's stack on the CPU clock; see the module's docstring."""

    def __init__(self, rate: float):
        self.interval = 1.0 / rate
        self.stage = "start-up"
        self.by_stage: Counter = Counter()
        self.by_module: Counter = Counter()
        self.by_operation: Counter = Counter()
        self.by_pair: Counter = Counter()
        self.by_function: Counter = Counter()
        self.by_stage_function: Counter = Counter()
        self.per_problem: dict[str, Counter] = defaultdict(Counter)
        self.problem = ""
        self.last = time.process_time()

    def start(self) -> None:
        signal.signal(signal.SIGPROF, self._sample)
        signal.setitimer(signal.ITIMER_PROF, self.interval, self.interval)

    def stop(self) -> None:
        signal.setitimer(signal.ITIMER_PROF, 0, 0)

    def _sample(self, _sig, frame) -> None:
        now = time.process_time()
        weight, self.last = now - self.last, now
        module, operation, function = "(none)", "(python)", "(none)"
        stack = []
        while frame is not None:
            stack.append(frame)
            frame = frame.f_back
        # innermost mechbook frame; the outermost library call above a mechbook frame
        for i, f in enumerate(stack):
            where = _where(f.f_code.co_filename)
            if where and where[0] == "mechbook":
                module = where[1]
                function = f"{where[1]}.{f.f_code.co_name}"
                inner = stack[:i]
                for g in reversed(inner):
                    lib = _where(g.f_code.co_filename)
                    if lib and lib[0] != "mechbook":
                        operation = f"{lib[0]}.{lib[1]}.{g.f_code.co_name}"
                        break
                break
        else:
            for f in reversed(stack):
                lib = _where(f.f_code.co_filename)
                if lib:
                    operation = f"{lib[0]}.{lib[1]}.{f.f_code.co_name}"
                    break
        self.by_stage[self.stage] += weight
        self.by_module[module] += weight
        self.by_operation[operation] += weight
        self.by_pair[(module, operation)] += weight
        self.by_function[function] += weight
        self.by_stage_function[(self.stage, function, operation)] += weight
        if self.problem:
            self.per_problem[self.problem][self.stage] += weight


def _family(text: str, families: dict[str, str]) -> str:
    """The stage table's row for a run_problem stage text."""
    if text.startswith("part "):
        quantity = text[text.find("(") + 1:text.rfind(")")] if "(" in text else ""
        return f"part: {families.get(quantity, quantity or '?')}"
    if text.startswith("cross-check"):
        kind = text.split(" ", 1)[1].split(":", 1)[0] if " " in text else text
        return f"cross-check: {kind.strip()}"
    return text


def _table(title: str, tally: Counter, total: float, top: int) -> str:
    rows = [f"\n{title}", f"{'':>2}{'CPU s':>8} {'share':>6}  what"]
    for what, seconds in tally.most_common(top):
        name = " / ".join(what) if isinstance(what, tuple) else what
        rows.append(f"{'':>2}{seconds:8.2f} {100 * seconds / total:5.1f}%  {name}")
    rest = total - sum(s for _, s in tally.most_common(top))
    if rest > 0.005:
        rows.append(f"{'':>2}{rest:8.2f} {100 * rest / total:5.1f}%  (the rest)")
    return "\n".join(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("ids", nargs="*", default=["lim", "symon"])
    ap.add_argument("--rate", type=float, default=200.0, help="samples per CPU second")
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--json", type=Path)
    opts = ap.parse_args()
    sampler = Sampler(opts.rate)
    started = time.process_time()  # the interpreter's own start-up, before this line
    sampler.start()
    from mechbook.app.running.batch import settle
    from mechbook.app.running.run import RunOptions, run_problem
    from mechbook.app.selection import select
    from mechbook.verify.registry import MODULES

    settle(preload=True)
    families = {q.name: module.__name__.rsplit(".", 1)[1]
                for module in MODULES for q in module.FAMILY.entries}
    ids = select(opts.ids, ROOT)
    statuses = Counter()

    def stage(text: str) -> None:
        sampler.stage = _family(text, families)

    for pid in ids:
        sampler.problem = pid
        run = run_problem(pid, ROOT, RunOptions(), stage)
        sampler.stage = "after the problem"
        statuses.update(o.status.value for o in run.outcomes)
        if run.error:
            statuses["problem error"] += 1
    sampler.stop()
    total = sum(sampler.by_stage.values())
    print(f"{len(ids)} problems, {time.process_time():.1f} s CPU in all "
          f"({started:.2f} s before sampling began), {total:.1f} s sampled; "
          f"outcomes {dict(statuses)}")
    print(_table("by stage", sampler.by_stage, total, opts.top))
    print(_table("by mechbook module (innermost)", sampler.by_module, total, opts.top))
    print(_table("by library operation (outermost call from mechbook)",
                 sampler.by_operation, total, opts.top))
    print(_table("by mechbook function (innermost)", sampler.by_function, total, opts.top))
    print(_table("by module and operation", sampler.by_pair, total, opts.top))
    print(_table("by stage, function and operation", sampler.by_stage_function, total,
                 opts.top))
    slow = sorted(sampler.per_problem.items(), key=lambda kv: -sum(kv[1].values()))[:15]
    print("\nslowest problems")
    for pid, tally in slow:
        parts = ", ".join(f"{k} {v:.2f}" for k, v in tally.most_common(3))
        print(f"  {sum(tally.values()):6.2f}  {pid}: {parts}")
    if opts.json:
        opts.json.write_text(json.dumps({
            "stage": dict(sampler.by_stage), "module": dict(sampler.by_module),
            "operation": dict(sampler.by_operation), "function": dict(sampler.by_function),
            "problems": {p: dict(t) for p, t in sampler.per_problem.items()}}, indent=1))


if __name__ == "__main__":
    sys.exit(main())
