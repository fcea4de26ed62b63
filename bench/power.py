"""The checker's power: the share of small wrong answers it rejects, per quantity and δ.

Every answer part of every book that passes (or is an erratum) is perturbed one place at a
time (mechbook.verify.mutate): each number and each parameter occurrence of its value scaled
by 1 + δ, the value shifted by δ times its size, a count moved by one, a flag or verdict
word changed. A part with `estimate:` is perturbed at twice its stated precision instead
of the fixed δ. A part whose pass claims more than 1e-6 (its power line says what it
rejects: "to 1e-08", "≤ 1e-20 of its scale", "wrong by more than ~2e-11", "exact ... below
1e-39") is perturbed once more at ten times that (class "10×claim"): a claim the
arithmetic cannot back lets those mutants survive. Each mutant goes through the real
checker; it is *killed* when the part no longer passes (an erratum part: no longer an
erratum).

A surviving mutant is *equivalent* (excluded from the rate) only when it provably means the
same: the same value at 30 digits, an equation multiplied by a constant, a relation with
the same truth everywhere (compared at its boundary), or a change the quantity declares it
does not see (its registration's `equivalent`: a conserved quantity's function, a
Lagrangian's additive constant, a mode shape's length). Everything else counts against the
checker.

"Before" is an earlier commit (default 00b0b7e, main before issue 20) in a temporary git
worktree, measured on the same mutants in the same run. Results: a Markdown table per
quantity and δ (stdout, or --out FILE; --docs writes it into docs/answers.md between the
power markers) and every mutant as JSON lines (--json FILE). Never gates CI.

    python bench/power.py [--before REF | --no-before] [-j N] [--only ID ...] [--out F]
                          [--docs] [--json F] [--from-json F]
"""

from __future__ import annotations

import argparse
import copy
import importlib.util
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from fractions import Fraction
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_BEFORE = "00b0b7e"
DELTAS = (Fraction(1, 100), Fraction(1, 10**6))
MUTANT_SECONDS = 120  # CPU seconds one mutant may take (a timeout is reported, not killed)
MARK_BEGIN = "<!-- power: begin (bench/power.py --docs) -->"
MARK_END = "<!-- power: end -->"
# drops an editable install's finder so that a tree on sys.path is the only mechbook
ONLY_THIS_TREE = ("import sys\n"
                  "sys.meta_path[:] = [f for f in sys.meta_path\n"
                  "                    if 'editable' not in str(getattr(f, '__module__', ''))]")


def _mutate_module():
    """This tree's mutation generator, loaded by path (the measured tree may predate it)."""
    spec = importlib.util.spec_from_file_location("_power_mutate",
                                                  ROOT / "mechbook" / "verify" / "mutate.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses look their module up there
    spec.loader.exec_module(mod)
    return mod


def _get(data, path):
    for p in path:
        data = data[p]
    return data


def _put(data, path, value):
    _get(data, path[:-1])[path[-1]] = value


CLAIMED = re.compile(r"(?:\bto|≤)\s*(\d(?:\.\d+)?e-\d+)")
NUMBER = r"(\d(?:\.\d+)?e-\d+)"
# how finely the engine's own side was computed, not what the pass rejects: "(quadrature
# resolved to 1e-20)", "(at 40 and 55 digits, agreeing to 1e-30)", "monodromy confirmed by
# finite differences to 1e-09", "(located to 1e-12)"; read as claims they set the class at
# 1e-19 for a value compared to 1e-15, and its mutants pass as they should
INTERNAL = re.compile(r"\([^()]*\)|\b(?:resolved|agreeing|confirmed[^;,]*?|located)\s+to\s+"
                      + NUMBER)


def finer_delta(power: str) -> Fraction | None:
    """Ten times what a pass's power line says it rejects, where that is finer than 1e-6
    (the coarsest class already measured); None where it says nothing finer. An
    asymptotic pass states it as a term "wrong by more than ~X", an exact one as "below X"
    (its error's last values say nothing about what it rejects); any other as "to X" or
    "≤ X", the finest counting."""
    if "would show" in power:
        found = re.findall("wrong by more than ~" + NUMBER, power)
    elif power.startswith("exact toward the limit"):
        found = re.findall("below " + NUMBER, power)
    else:
        found = CLAIMED.findall(INTERNAL.sub("", power))
    finest = min((float(x) for x in found if float(x) > 0), default=None)
    if finest is None or 10 * finest >= 1e-6:
        return None
    return Fraction(f"{10 * finest:.0e}")


# ---- measuring one tree (run in a subprocess with that tree first on sys.path) ----------
def measure(tree: Path, files: list[str], out: Path, deltas: list[Fraction]) -> None:
    from mechbook.core.timeout import Timeout, time_limit
    from mechbook.engine.analysis import Analysis
    from mechbook.verify.answers import Part, load_answers
    from mechbook.verify.checker import check_part
    from mechbook.verify.context import Context

    try:
        from mechbook.model.catalog import problem_path
        from mechbook.model.problem import load_problem
    except ImportError:  # pragma: no cover - a much older layout
        raise SystemExit("the measured tree has no mechbook.model.catalog") from None
    mutate = _mutate_module()
    with open(out, "a") as sink:
        for f in files:
            key = load_answers(f)
            analysis = Analysis(load_problem(problem_path(key.problem_id, tree)))
            names = set(analysis.problem.parameters) | set(key.symbols) | set(
                key.doc.data.get("abbreviations") or {})
            for part in key.parts:
                base = {"problem": key.problem_id, "part": part.name,
                        "quantity": part.quantity}
                t0 = time.process_time()
                original = check_part(analysis, part)
                if original.status not in ("pass", "erratum"):
                    sink.write(json.dumps({**base, "skip": original.status}) + "\n")
                    continue
                erratum = "erratum" in part.data
                root = ("erratum", "corrected") if erratum else ("book",)
                value = _get(part.data, root)
                try:
                    sizes = mutate.shift_sizes(Context(analysis, part), value, root)
                except Exception:  # noqa: BLE001 - a size is only for the shift mutants
                    sizes = {}
                est = part.data.get("estimate")
                classes = ([Fraction(2 * est["rtol"]).limit_denominator(10**9)] if est
                           else list(deltas))
                finer = None if est else finer_delta(original.power or "")
                if finer is not None:
                    classes.append(finer)
                seen_discrete = False
                for delta in classes:
                    for m in mutate.part_mutants(value, root, names, delta, sizes,
                                                 counts=part.quantity in mutate.COUNTS):
                        if m.kind == "discrete":
                            if seen_discrete:
                                continue
                        data = copy.deepcopy(part.data)
                        _put(data, m.path, m.value)
                        start = time.process_time()
                        try:
                            with time_limit(MUTANT_SECONDS):
                                got = check_part(analysis, Part(key, part.index, data))
                            status, detail = got.status, got.detail[:300]
                        except Timeout:
                            status, detail = "timeout", ""
                        killed = (status != "erratum") if erratum else status in ("fail",
                                                                                    "error")
                        sink.write(json.dumps({
                            **base, "path": list(m.path), "label": m.label, "kind": m.kind,
                            "delta": "discrete" if m.kind == "discrete" else str(delta),
                            "old": _get(part.data, m.path), "new": m.value,
                            "token": getattr(m, "token", ""),
                            "status": status, "killed": killed and status != "timeout",
                            "detail": detail, "estimate": bool(est),
                            "claim": delta == finer, "limit": "limit" in part.data,
                            "seconds": time.process_time() - start}, default=str) + "\n")
                        sink.flush()
                    seen_discrete = True
                sink.write(json.dumps({**base, "done": time.process_time() - t0}) + "\n")


# ---- equivalence of survivors (in this tree) ---------------------------------------------
def equivalence(records: list[dict]) -> dict:
    """(problem, part, path, label, delta) -> why the surviving mutant means the same."""
    from mechbook.engine.analysis import Analysis
    from mechbook.model.catalog import answer_path, problem_path
    from mechbook.model.problem import load_problem
    from mechbook.verify.answers import load_answers
    from mechbook.verify.context import Context
    from mechbook.verify.power import same_meaning

    out = {}
    by_problem = defaultdict(list)
    for r in records:
        by_problem[r["problem"]].append(r)
    for pid, rs in by_problem.items():
        try:
            key = load_answers(answer_path(pid, ROOT))
            analysis = Analysis(load_problem(problem_path(pid, ROOT)))
        except Exception as exc:  # noqa: BLE001 - undecided counts against the checker
            for r in rs:
                out[_id(r)] = ""
                r["equivalence_error"] = f"{type(exc).__name__}: {exc}"[:200]
            continue
        parts = {p.name: p for p in key.parts}
        for r in rs:
            part = parts[r["part"]]
            try:
                ctx = Context(analysis, part)
                why = same_meaning(ctx, tuple(r["path"]), r["old"], r["new"],
                                   r.get("token", ""))

            except Exception as exc:  # noqa: BLE001 - undecided counts against the checker
                why = ""
                r["equivalence_error"] = f"{type(exc).__name__}: {exc}"[:200]
            out[_id(r)] = why
    return out


def _id(r: dict) -> tuple:
    return (r["problem"], r["part"], tuple(r["path"]), r["label"], r["delta"])


# ---- the run ----------------------------------------------------------------------------
def _worker_cmd(tree: Path, files: list[str], out: Path, deltas: list[Fraction]) -> list[str]:
    code = (f"{ONLY_THIS_TREE}\nsys.path.insert(0, {str(tree)!r})\n"
            f"sys.path.insert(1, {str(ROOT / 'bench')!r})\n"
            "import power\n"
            f"power.measure(__import__('pathlib').Path({str(tree)!r}), {files!r}, "
            f"__import__('pathlib').Path({str(out)!r}), "
            f"[__import__('fractions').Fraction(x) for x in {[str(d) for d in deltas]!r}])")
    return [sys.executable, "-c", code]


def run_tree(tree: Path, files: list[Path], jobs: int, workdir: Path, tag: str,
             deltas: list[Fraction]) -> list[dict]:
    """Measure `tree` on `files` in `jobs` processes (longest files first, dealt round-robin)."""
    chunks = [[] for _ in range(jobs)]
    for i, f in enumerate(sorted(files, key=lambda p: -p.stat().st_size)):
        chunks[i % jobs].append(str(f))
    procs = []
    outs = []
    env = dict(os.environ, MECHBOOK_ROOT=str(tree))
    for i, chunk in enumerate(chunks):
        if not chunk:
            continue
        out = workdir / f"{tag}-{i}.jsonl"
        outs.append(out)
        procs.append(subprocess.Popen(_worker_cmd(tree, chunk, out, deltas), env=env))
    for p in procs:
        if p.wait() != 0:
            print(f"warning: a {tag} worker exited with {p.returncode}", file=sys.stderr)
    records = []
    for out in outs:
        if out.exists():
            records += [json.loads(line) for line in out.read_text().splitlines() if line]
    return records


def table(mutants: list[dict], equiv: dict, title: str) -> str:
    """Kill rate per quantity and δ (equivalent mutants excluded)."""
    rows = defaultdict(lambda: [0, 0, 0])  # mutants, equivalent, killed
    for r in mutants:
        cls = _class(r)
        row = rows[(_quantity(r), cls)]
        row[0] += 1
        if r["killed"]:
            row[2] += 1
        elif equiv.get(_id(r)):
            row[1] += 1
    total = defaultdict(lambda: [0, 0, 0])
    lines = [f"| {title}: quantity | class | mutants | equivalent | killed | kill rate |",
             "| --- | --- | ---: | ---: | ---: | ---: |"]
    for (q, cls), (n, e, k) in sorted(rows.items()):
        rate = k / (n - e) if n > e else float("nan")
        lines.append(f"| `{q}` | {cls} | {n} | {e} | {k} | {rate:.1%} |")
        for c in (cls, "all"):
            t = total[c]
            t[0] += n
            t[1] += e
            t[2] += k
    for cls, (n, e, k) in sorted(total.items()):
        rate = k / (n - e) if n > e else float("nan")
        lines.append(f"| **all** | {cls} | {n} | {e} | {k} | **{rate:.2%}** |")
    return "\n".join(lines)


def _quantity(r: dict) -> str:
    """The row's quantity: a part with `limit:` (an asymptotic claim) has its own."""
    return f"{r['quantity']}` with `limit:" if r.get("limit") else r["quantity"]


def _class(r: dict) -> str:
    if r["delta"] == "discrete":
        return "discrete"
    if r.get("estimate"):
        return "2×estimate"
    if r.get("claim"):
        return "10×claim"
    return f"δ = {float(Fraction(r['delta'])):g}"


def survivors(mutants: list[dict], equiv: dict) -> list[str]:
    out = []
    for r in mutants:
        if not r["killed"] and not equiv.get(_id(r)):
            out.append(f"- {r['problem']} {r['part']} (`{r['quantity']}`) "
                       f"{'/'.join(map(str, r['path']))}: {r['label']} ({_class(r)}): "
                       f"{r['status']} {r['detail'][:160]}")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default=DEFAULT_BEFORE)
    ap.add_argument("--no-before", action="store_true")
    ap.add_argument("-j", "--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--only", nargs="*", default=None, help="problem ids")
    ap.add_argument("--out", type=Path)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--docs", action="store_true", help="write the table into docs/answers.md")
    ap.add_argument("--from-json", type=Path, help="tables from an earlier run's --json "
                    "records (no measuring)")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from mechbook.model.catalog import all_ids, answer_path

    ids = args.only or [i for i in all_ids(ROOT) if answer_path(i, ROOT).exists()]
    files = [answer_path(i, ROOT) for i in ids]
    deltas = list(DELTAS)
    started = time.time()
    if args.from_json:
        records = [json.loads(line) for line in args.from_json.read_text().splitlines() if line]
        after = [r for r in records if r.get("tree") != "before"]
        before = [r for r in records if r.get("tree") == "before"]
        return _report(args, after, before, started)
    with tempfile.TemporaryDirectory(prefix="mechbook-power-") as tmp:
        tmp = Path(tmp)
        after = run_tree(ROOT, files, args.jobs, tmp, "after", deltas)
        before = []
        if not args.no_before:
            old = tmp / "before-tree"
            subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q",
                            str(old), args.before], check=True)
            try:
                before = run_tree(old, [old / f.relative_to(ROOT) for f in files], args.jobs,
                                  tmp, "before", deltas)
            finally:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                                str(old)], check=False)
    for r in before:  # the same answer files, by their path in this tree
        r["tree"] = "before"
    if args.json:  # the measurements first: an equivalence step that fails loses nothing
        with open(args.json, "w") as f:
            for r in before + after:
                f.write(json.dumps(r, default=str) + "\n")
    return _report(args, after, before, started)


def _report(args, after: list[dict], before: list[dict], started: float) -> int:
    """Equivalence of the survivors, the tables, and where they go."""
    mutants_after = [r for r in after if "label" in r]
    mutants_before = [r for r in before if "label" in r]
    unkilled = {_id(r): r for r in mutants_after + mutants_before if not r["killed"]}
    equiv = equivalence(list(unkilled.values()))
    seconds = time.time() - started
    when = (f"Measured {time.strftime('%Y-%m-%d')} by `bench/power.py` in {seconds:.0f} s "
            f"({args.jobs} processes)" if not args.from_json else
            f"Tables by `bench/power.py --from-json` from the records in {args.from_json.name}")
    report = [f"{when}: {len(mutants_after)} mutants of "
              f"{len({(r['problem'], r['part']) for r in mutants_after})} parts.", ""]
    if mutants_before:
        report += [table(mutants_before, equiv, f"before ({args.before})"), ""]
    report += [table(mutants_after, equiv, "after"), ""]
    left = survivors(mutants_after, equiv)
    report += [f"Surviving mutants after: {len(left)}", ""] + left
    text = "\n".join(report) + "\n"
    if args.out:
        args.out.write_text(text)
    print(text)
    if args.json and not args.from_json:  # a new file, then renamed: the first copy stays
        part = args.json.with_name(args.json.name + ".part")
        with open(part, "w") as f:
            for r in before + after:
                if "label" in r:  # a mutant (a part's own record has no path or label)
                    r["equivalent"] = equiv.get(_id(r), "")
                f.write(json.dumps(r, default=str) + "\n")
        part.replace(args.json)
    if args.docs:
        doc = ROOT / "docs" / "answers.md"
        body = doc.read_text()
        block = f"{MARK_BEGIN}\n{text}{MARK_END}"
        if MARK_BEGIN in body:
            head, rest = body.split(MARK_BEGIN, 1)
            body = head + block + rest.split(MARK_END, 1)[1]
        else:
            body = body.rstrip() + "\n\n## The checker's power, measured\n\n" + block + "\n"
        doc.write_text(body)
    return 0


if __name__ == "__main__":
    sys.exit(main())
