"""Fuzzing the loaders: mutated and hostile problem and answer files, run under limits.

Every input must end in success or a MechbookError-class message: never a traceback, never a
hang past the time limit, never memory past the bound. Inputs are generated from the real
problem and answer files (problems/, answers/) by six kinds of mutation (see KINDS), written
into a small tree per case, and run on the batch machinery (mechbook.app.running.batch) so a hang or
a memory bomb is stopped and reported, not waited for:

    python tests/fuzz.py --cases 10000 --seed 1      # `make fuzz`; a table of outcomes
    tests/test_fuzz.py runs a sample of it in `make test`.

Most cases run what `mechbook validate` runs (schema, systems built, every expression
parsed); the `check` kind runs the full check of a mutated problem (mechbook.app.running.run), where
an engine fault shows as a traceback in the run's debug log (the details carry messages
only). The kinds of issue 21 (store faults, strings through every output, numeric options,
symbolic links) are generated and judged by tests/fuzz_faults.py, which adds the failures
lost (silent data loss), leak (a file outside the tree read) and unsafe. A failing case's
files are kept under --keep (default results/fuzz/) to reproduce it with `mechbook validate`.
"""

from __future__ import annotations

import argparse
import io
import json
import logging
import os
import random
import re
import shutil
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import fuzz_faults as faults
import fuzz_surfaces as surfaces
import fuzz_surfaces44 as surfaces44
from ruamel.yaml import YAML

ROOT = Path(__file__).resolve().parents[1]
TRACEBACK = "Traceback (most recent call last)"
# per case; a good file validates in well under a second. Above validate's own bound on a
# build (BUILD_SECONDS, 15 s of CPU) with room for the parsing before it: a case that ends
# in validate's own "took more than 15 s" is limited, not hung (case 9188 of seed 1 took
# 16.2 s of CPU and was called a hang under the earlier 20 s on a loaded machine)
VALIDATE_SECONDS = 30.0
CHECK_SECONDS = 120.0  # per case of the `check` kind (a whole problem; limits reported)
MEMORY_MB = 1500.0

KINDS = {
    "text": "bytes and lines of a real file flipped, inserted, deleted, swapped, truncated",
    "structure": "the YAML tree of a real file: keys deleted, renamed, duplicated; values "
                 "replaced by random values of any type; subtrees taken from another file",
    "expression": "one expression of a real file replaced by a hostile one (1/0, sqrt(-1), "
                  "huge powers, attribute access, ...), a token-level mutation of itself, or "
                  "a random expression over the file's names",
    "hostile": "documents built to hurt: alias bombs, deep nesting, huge numbers and files, "
               "tags, binary, special files (FIFO, /dev/zero, directories)",
    "counts": "real files with coordinates, particles, parts or abbreviations multiplied past "
              "(or up to) the limits, and chains of abbreviations that double",
    "check": "a structure or expression mutation that still validates, run through the whole "
             "`mechbook check` of its problem",
    "store": "a store damaged on disk (truncated, bytes flipped, text, a directory, a FIFO, "
             "links) and faults injected into each step of a write; every record must stay "
             "readable or be kept in the side file named (tests/fuzz_faults.py)",
    "strings": "a NUL, surrogate, control character, bidi override, fullwidth letter ... put "
               "into a text field or an expression of a real file; what validates goes "
               "through HDF5, JSON, JUnit XML and the terminal",
    "options": "NaN, infinities, huge and odd numbers for every numeric option and sweep axis "
               "of the command line: refused, or accepted finite and within bounds",
    "symlinks": "a problem file, answer key or book folder replaced by a link: outside the "
                "tree (with a marker that must never be read), dangling, looping, /dev/zero, "
                "a FIFO, a directory, or inside the tree",
    "restore": "a side file of kept results with hostile lines (ids, fields, values, nesting, "
               "formats, stores outside the tree or that are not stores) or itself a FIFO, "
               "/dev/zero, a directory, a link; restored as from inside the tree "
               "(tests/fuzz_surfaces.py)",
    "init": "`mechbook init NAME` over dangling and linked files and folders, FIFOs, files "
            "where folders go, overlong and empty names",
    "watch": "watch's poll and check with its problem file, answer key or books.yaml replaced "
             "by a FIFO, /dev/zero, a directory, links, a sparse 3 GB file, random bytes",
    "pagelist": "the report's page list as a FIFO, /dev/zero, a directory, links, nested or "
                "random JSON, entries of the wrong shape, bytes; its old temporary names "
                "planted as links",
    "hdf5": "stores from elsewhere: compressed and unallocated bombs, huge attributes, foreign "
            "HDF5, unknown formats, soft, external and hard-cycle links, external and virtual "
            "storage, deep and many groups, damaged records",
    "regex": "books.yaml with a user's pattern: catastrophic backtracking on numbers of up to "
             "80 characters, backreferences, lookaround, huge and invalid patterns",
    "velocity": "a velocity constraint of random terms (tiny and huge coefficients, velocities "
                "inside Abs, sign, sqrt, powers, functions) or a rolling contact on a random "
                "surface, validated and checked (tests/fuzz_surfaces44.py)",
    "periods": "Floquet `period:` values from 1e-40 to 1e40, zero, negative, complex, names; "
               "driven coordinates with drives too slow, too fast, growing, not periodic",
    "schema": "`schema --write DIR` with a FIFO, /dev/zero, a directory, links or a sparse file "
              "at a schema's path, or DIR itself a file, link or FIFO",
    "lastfailed": "`--lf`'s record as a FIFO, /dev/zero, links, a directory, nested, random or "
                  "misshapen JSON, bytes; read, used and written again",
    "patterns": "id patterns of random glob pieces, or one piece repeated up to 30,000 times",
    "api": "the Python API's functions given NaN, infinities, 10**400, wrong types, lists for "
           "mappings, 10**12 points",
}

# shares of a run: a `check` case costs ~50 validations, so that kind gets a small share
WEIGHTS = {"text": 20, "structure": 22, "expression": 26, "hostile": 14, "counts": 16,
           "check": 1, "store": 8, "strings": 6, "options": 4, "symlinks": 3,
           "restore": 4, "init": 3, "watch": 3, "pagelist": 3, "hdf5": 6, "regex": 3,
           "velocity": 3, "periods": 1, "schema": 2, "lastfailed": 2, "patterns": 2, "api": 2}
SURFACES = ("restore", "init", "watch", "pagelist", "hdf5", "regex",  # issue 33
            "velocity", "periods", "schema", "lastfailed", "patterns", "api")  # issue 44
GENERATORS = {**surfaces.GENERATORS, **surfaces44.GENERATORS}
RUNNERS = {**surfaces.RUNNERS, **surfaces44.RUNNERS}

HOSTILE_EXPRESSIONS = [
    "1/0", "0/0", "1/0*{x}", "sqrt(-1)*{x}**2", "sqrt(-{p})", "log(0)", "log(-1)", "asin(2)",
    "acosh(0)", "atanh(1)", "tan(pi/2)", "cot(0)", "atan2(0, 0)", "log({x}, 1)", "0**-1",
    "(-8)**(1/3)", "{x}**10**10", "{x}**(10**30)", "10**10**10", "9" * 120, "1e400", "1e-400",
    "(" * 80 + "{x}" + ")" * 80, "-" * 500 + "{x}", "+".join(["{x}"] * 3000),
    "__import__('os').system('touch /tmp/pwned')", "{x}.__class__", "lambda: 1",
    "[{x} for {x} in {p}]", "f'{{1}}'", "{x} if {p} else 1", "{x}[0]", "{x} @ {p}", "~{x}",
    "not {x}", "{x} << 2", "{x} % 2", "{x} // 2", "'text'", "b'x'", "...", "None", "True",
    "exp(exp(exp(exp(100))))", "exp(10**30)", "sin", "sin()", "sin({x}, {p})", "{x} = {p} = 1",
    "{x} == {p}", "{x} < {p}", "", " ", "#", "\x00", "{x}\n{p}", "1_000", "0x10", "1j", "2**-64",
    "Abs({x})**64**64", "sqrt({x})**-64", "{x}**-64", "(1+{x})**64*(1+{p})**64", "E", "I",
    "oo", "zoo", "nan", "pi**pi**pi", "sign(0)/0", "{x}/({p}-{p})", "= {x}", "{x} =", "{x} <",
    "a" * 30000, "sin(" * 59 + "{x}" + ")" * 59, "sin(" * 61 + "{x}" + ")" * 61,
]
HOSTILE_VALUES = [None, True, False, 0, -1, 1e308, -1e308, 1e-320, float("nan"), float("inf"),
                  10**40, -(10**40), [], {}, "", [[[[[]]]]], {"a": {"b": {"c": {}}}}]
TEXT_KEYS = {"doc", "notes", "description", "title", "source", "cite", "transcription",
             "note", "derivation", "unsupported", "id", "problem", "part", "quantity"}
YAML_CHARS = list(":{}[],&*!|>'\"#%@`-? \t\n") + ["\x00", "\x07", "\ufeff", "\u2028", "é"]


def _yaml(typ: str = "safe") -> YAML:
    y = YAML(typ=typ, pure=True)
    y.width = 4096
    return y


def dump(data) -> str:
    out = io.StringIO()
    _yaml().dump(data, out)
    return out.getvalue()


def load(text: str):
    return _yaml().load(text)


@dataclass
class Seed:
    """A real problem file and its answer key (the answer key may be missing)."""

    pid: str
    problem: str
    answers: str | None
    data: dict = field(repr=False, default_factory=dict)
    key: dict | None = field(repr=False, default=None)


def seeds(root: Path = ROOT) -> list[Seed]:
    out = []
    for path in sorted((root / "problems").glob("*/*.yaml")):
        book, num = path.parent.name, path.stem
        apath = root / "answers" / book / f"{num}.yaml"
        text = path.read_text("utf-8")
        atext = apath.read_text("utf-8") if apath.exists() else None
        out.append(Seed(f"{book}-{num}", text, atext, load(text),
                        load(atext) if atext else None))
    return out


@dataclass
class Case:
    """One generated input: files to write (relative to the case's tree) and the target."""

    index: int
    kind: str
    files: dict[str, str | bytes]
    target: str  # the file to validate (relative), or the problem id for `check`
    mode: str = "validate"  # or "check", "store", "strings", "options", "symlink"
    special: str | None = None  # "fifo", "devzero", "directory": the target is not a file
    spec: dict | None = None  # the parameters of a store, options or symlink case


# ---- mutations ---------------------------------------------------------------------------

def _names(data: dict) -> list[str]:
    names = list(data.get("parameters") or {})
    systems = data.get("systems") or {"main": data}
    for s in systems.values():
        if isinstance(s, dict):
            names += list(s.get("coordinates") or {})
    return [n for n in names if isinstance(n, str)] or ["x"]


def _paths(node, path=()):
    """Every (path, value) in a tree."""
    yield path, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, path + (i,))


def _set(tree, path, value):
    node = tree
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value


def _random_value(rng: random.Random, names: list[str], depth: int = 0):
    r = rng.random()
    if r < 0.25:
        return rng.choice(HOSTILE_VALUES)
    if r < 0.5:
        return _expression(rng, names)
    if r < 0.6:
        return rng.choice([rng.randint(-10, 10), rng.uniform(-1e3, 1e3),
                           10 ** rng.randint(1, 60)])
    if r < 0.7:
        alphabet = YAML_CHARS + list("abcxyz019")
        return "".join(rng.choice(alphabet) for _ in range(rng.randint(0, 20)))
    if r < 0.85 and depth < 4:
        return [_random_value(rng, names, depth + 1) for _ in range(rng.randint(0, 4))]
    if depth < 4:
        return {rng.choice(names + ["x", "doc", "value", "mass", "shape", "k", "about"]):
                _random_value(rng, names, depth + 1) for _ in range(rng.randint(0, 4))}
    return rng.choice(names)


def _expression(rng: random.Random, names: list[str]) -> str:
    r = rng.random()
    x, p = rng.choice(names), rng.choice(names)
    if r < 0.5:
        return rng.choice(HOSTILE_EXPRESSIONS).replace("{x}", x).replace("{p}", p) \
            .replace("{{", "{").replace("}}", "}")
    return _random_expr(rng, names, rng.randint(1, 6))


def _random_expr(rng: random.Random, names: list[str], depth: int) -> str:
    if depth <= 0 or rng.random() < 0.2:
        return rng.choice(names + ["0", "1", "2", "-1", "pi", "1/2", "0.5", "1e30", "t"])
    r = rng.random()
    a = _random_expr(rng, names, depth - 1)
    if r < 0.5:
        b = _random_expr(rng, names, depth - 1)
        return f"({a}){rng.choice(['+', '-', '*', '/', '**'])}({b})"
    if r < 0.9:
        f = rng.choice(["sin", "cos", "tan", "sqrt", "log", "exp", "asin", "acos", "atan",
                        "sinh", "cosh", "tanh", "acosh", "atanh", "Abs", "sign", "cbrt", "cot",
                        "sec", "csc"])
        return f"{f}({a})"
    return f"-({a})"


def _mutate_expression_text(rng: random.Random, text: str, names: list[str]) -> str:
    tokens = re.findall(r"[A-Za-z_][A-Za-z0-9_]*|\d+\.?\d*(?:e[-+]?\d+)?|\*\*|\S", text)
    if not tokens:
        return _expression(rng, names)
    i = rng.randrange(len(tokens))
    r = rng.random()
    pool = ["+", "-", "*", "/", "**", "(", ")", "0", "1", "-1", "1e30", ",", "=", "<", ".",
            "sqrt", "log", rng.choice(names)]
    if r < 0.4:
        tokens[i] = rng.choice(pool)
    elif r < 0.7:
        tokens.insert(i, rng.choice(pool))
    else:
        del tokens[i]
    return " ".join(tokens)


def _text(rng: random.Random, text: str) -> str | bytes:
    data = bytearray(text.encode("utf-8"))
    lines = text.splitlines(keepends=True)
    r = rng.random()
    if r < 0.3 and data:  # byte edits
        for _ in range(rng.randint(1, 8)):
            i = rng.randrange(len(data))
            op = rng.random()
            if op < 0.4:
                data[i] = rng.randrange(256)
            elif op < 0.7:
                data[i:i] = rng.choice(YAML_CHARS).encode("utf-8")
            else:
                del data[i:i + rng.randint(1, 20)]
        return bytes(data)
    if r < 0.6 and lines:  # line edits
        for _ in range(rng.randint(1, 4)):
            i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
            op = rng.random()
            if op < 0.3:
                lines.insert(i, lines[j])
            elif op < 0.6 and len(lines) > 1:
                del lines[i]
            elif op < 0.8:
                lines[i], lines[j] = lines[j], lines[i]
            else:
                lines[i] = (" " * rng.randint(0, 6)) + lines[i].lstrip()
        return "".join(lines)
    if r < 0.75:
        return text[: rng.randrange(len(text) + 1)]
    # insert a YAML construct somewhere
    snippet = rng.choice(["&a ", "*a", "!!python/object:os.system ", "!foo ", "<<: *a\n",
                          "? [a, b]\n: 1\n", "--- \n", "...\n", "%YAML 1.1\n", "|\n", ">-\n",
                          "{", "[", "\t", ": ", "- ", "'", '"', "\\", "#"])
    i = rng.randrange(len(text) + 1)
    return text[:i] + snippet + text[i:]


def _structure(rng: random.Random, tree, other, names: list[str]):
    spots = [p for p, _ in _paths(tree) if p]
    for _ in range(rng.randint(1, 3)):
        if not spots:
            break
        path = rng.choice(spots)
        r = rng.random()
        try:
            parent = tree
            for p in path[:-1]:
                parent = parent[p]
            if r < 0.2:  # delete
                del parent[path[-1]]
            elif r < 0.35 and isinstance(parent, dict):  # rename a key
                value = parent.pop(path[-1])
                parent[rng.choice(names + ["coordinates", "particles", "kinetic", "potential",
                                           "springs", "book", "about", "value", "x", "1"])] = value
            elif r < 0.5 and other is not None:  # graft a subtree of another file
                graft = rng.choice([v for _, v in _paths(other)])
                parent[path[-1]] = json.loads(json.dumps(graft))  # a copy: never the pool's
            elif r < 0.6 and isinstance(parent, list):  # duplicate an entry
                parent.append(parent[path[-1]])
            else:
                parent[path[-1]] = _random_value(rng, names)
        except (KeyError, IndexError, TypeError):
            pass
        spots = [p for p, _ in _paths(tree) if p]
    return tree


def _expr_spots(tree) -> list[tuple]:
    return [p for p, v in _paths(tree)
            if isinstance(v, str) and p and not any(k in TEXT_KEYS for k in p if
                                                    isinstance(k, str))]


def _hostile(rng: random.Random, seed: Seed) -> tuple[str | bytes, str | None]:
    """(text of the target problem file, special) for the hostile kind."""
    r = rng.randrange(14)
    if r == 0:  # billion laughs, of random depth and width
        depth, width = rng.randint(3, 12), rng.randint(2, 10)
        lines = [f'a0: &a0 [{", ".join(["lol"] * width)}]']
        for d in range(1, depth):
            lines.append(f"a{d}: &a{d} [{', '.join([f'*a{d - 1}'] * width)}]")
        return "\n".join(lines) + "\n", None
    if r == 1:  # the bomb inside a real problem
        width = rng.randint(5, 10)
        bomb = "".join(f"\n  - &l{d} [{', '.join([f'*l{d - 1}'] * width)}]" for d in range(1, 9))
        return seed.problem + f"notes:\n  - &l0 [x, x]{bomb}\n", None
    if r == 2:
        n = rng.randint(30, 3000)
        return seed.problem + "doc: " + "[" * n + "]" * n + "\n", None
    if r == 3:
        n = rng.randint(30, 3000)
        return seed.problem + "doc: " + "{a: " * n + "1" + "}" * n + "\n", None
    if r == 4:
        return seed.problem.replace("value:", "value: " + "9" * rng.randint(50, 6000) + " #",
                                    1), None
    if r == 5:  # too large a file
        return seed.problem + "notes: |\n" + ("  " + "x" * 79 + "\n") * rng.randint(3300,
                                                                                  5000), None
    if r == 6:
        return bytes(rng.randrange(256) for _ in range(rng.randint(0, 4000))), None
    if r == 7:
        return seed.problem.encode("utf-16"), None
    if r == 8:
        return "!!python/object/apply:os.system ['touch /tmp/pwned']\n", None
    if r == 9:
        n = rng.randint(1000, 60000)
        return "parameters:\n" + "".join(f"  p{i}: {{}}\n" for i in range(n)), None
    if r == 10:
        return rng.choice(["", "\n", "# only a comment\n", "---\n", "---\n...\n", "~\n",
                           "[]\n", "{}\n", "- 1\n", "'x'\n", seed.problem + "---\nb: 1\n"]), None
    if r == 11:
        return "", rng.choice(["fifo", "devzero", "directory"])
    if r == 12:  # deep nesting under a real key, just inside / outside the limit
        n = rng.randint(25, 40)
        return seed.problem + "notes: " + "- " * 0 + "[" * n + "x" + "]" * n + "\n", None
    return seed.problem.replace("parameters:", "parameters: &p", 1), None


def _counts(rng: random.Random, seed: Seed) -> tuple[str, str, str | None]:
    """(which file: 'problem' or 'answers', its text, or None)."""
    r = rng.randrange(4)
    data = json.loads(json.dumps(seed.data))
    if r == 0:
        n = rng.choice([8, 16, 17, 40, 400])
        names = [f"q{i}" for i in range(n)]
        data.pop("systems", None)
        for k in ("particles", "rigid_bodies", "springs", "constraints", "driven", "forces",
                  "lagrangian", "approximation", "equilibria", "initial", "velocity_potential",
                  "gravity"):
            data.pop(k, None)
        data["coordinates"] = {q: {} for q in names}
        data["kinetic"] = " + ".join(f"{q}dot**2/2" for q in names)
        pairs = zip(names, names[1:], strict=False)
        data["potential"] = " + ".join(f"({a} - {b})**2/2" for a, b in pairs)
        data["potential"] = data["potential"] or "q0**2"
        return "problem", dump(data), None
    if r == 1:
        n = rng.choice([4, 32, 33, 200])
        data.pop("systems", None)
        data["coordinates"] = {"x": {}}
        for k in ("rigid_bodies", "springs", "constraints", "driven", "forces", "lagrangian",
                  "approximation", "equilibria", "initial", "velocity_potential", "kinetic",
                  "potential"):
            data.pop(k, None)
        data.setdefault("parameters", {})["m"] = {}
        data["particles"] = {f"b{i}": {"mass": "m", "position": [f"x + {i}", f"x*{i}", "0"]}
                             for i in range(n)}
        return "problem", dump(data), None
    if seed.key is None:
        return "problem", seed.problem, None
    key = json.loads(json.dumps(seed.key))
    if r == 2:
        n = rng.choice([2, 64, 65, 500])
        key["parts"] = [dict(p, part=f"{p['part']}-{i}") for i in range(n)
                        for p in key["parts"]][: n]
        return "answers", dump(key), None
    n = rng.choice([5, 12, 20, 40])
    names = _names(seed.data)
    abbr = {"A0": f"{names[0]} + 1"}
    for i in range(1, n):
        abbr[f"A{i}"] = f"(A{i - 1} + {names[i % len(names)]})*(A{i - 1} - 1)"
    key["abbreviations"] = {**(key.get("abbreviations") or {}), **abbr}
    first = key["parts"][0]
    if isinstance(first.get("book"), str):
        first["book"] = f"{first['book']} + 0*A{n - 1}"
    return "answers", dump(key), None


def generate(index: int, seed_value: int, pool: list[Seed], kinds: list[str]) -> Case:
    """Case `index` of a run: deterministic in (seed_value, index)."""
    rng = random.Random(f"{seed_value}-{index}")
    kind = rng.choices(kinds, [WEIGHTS[k] for k in kinds])[0]
    seed = rng.choice(pool)
    book, num = seed.pid.split("-", 1)
    ppath, apath = f"problems/{book}/{num}.yaml", f"answers/{book}/{num}.yaml"
    files: dict[str, str | bytes] = {ppath: seed.problem}
    if seed.answers is not None:
        files[apath] = seed.answers
    target = ppath
    on_answers = seed.key is not None and rng.random() < 0.5
    if on_answers:
        target = apath
    names = _names(seed.data)
    source, tree = (seed.answers, seed.key) if on_answers else (seed.problem, seed.data)
    if kind == "text":
        files[target] = _text(rng, source)
    elif kind in ("structure", "expression", "check"):
        tree = json.loads(json.dumps(tree))
        if kind == "structure" or (kind == "check" and rng.random() < 0.3):
            other = rng.choice(pool)
            _structure(rng, tree, other.key if on_answers else other.data, names)
        else:
            spots = _expr_spots(tree)
            if spots:
                path = rng.choice(spots)
                node = tree
                for p in path:
                    node = node[p]
                new = (_mutate_expression_text(rng, node, names) if rng.random() < 0.5
                       else _expression(rng, names))
                _set(tree, path, new)
        files[target] = dump(tree)
        if kind == "check":
            return Case(index, kind, files, seed.pid, mode="check")
    elif kind == "hostile":
        text, special = _hostile(rng, seed)
        files[ppath] = text
        return Case(index, kind, files, ppath, special=special)
    elif kind == "counts":
        which, text, _ = _counts(rng, seed)
        target = ppath if which == "problem" else apath
        files[target] = text
    elif kind in SURFACES:
        return Case(index, kind, {}, "", mode=kind, spec=GENERATORS[kind](rng))
    elif kind == "store":
        return Case(index, kind, {}, "", mode="store", spec=faults.store_spec(rng))
    elif kind == "options":
        return Case(index, kind, {}, "", mode="options", spec=faults.options_spec(rng))
    elif kind == "symlinks":
        return Case(index, kind, files, ppath, mode="symlink", spec=faults.link_spec(rng))
    elif kind == "strings":
        tree, value = faults.strings_doc(rng, json.loads(json.dumps(tree)))
        files[target] = dump(tree).replace(faults.PLACEHOLDER, json.dumps(value))
        return Case(index, kind, files, target, mode="strings")
    return Case(index, kind, files, target)


# ---- running ----------------------------------------------------------------------------

@dataclass
class Result:
    index: int
    kind: str
    status: str  # ok, refused, crash, hang, bomb, died, limited (check kind: a reported limit)
    message: str = ""
    seconds: float = 0.0


def write_case(case: Case, where: Path) -> Path:
    """The case's tree under `where`; returns the target's path (or the case root for
    `check`)."""
    where.mkdir(parents=True, exist_ok=True)
    for rel, content in case.files.items():
        path = where / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content, encoding="utf-8", errors="surrogatepass")
    if case.mode == "symlink":
        faults.make_links(where, case.target, case.spec["link"])
        return where
    if case.mode in ("store", "options", *SURFACES):
        (where / "spec.json").write_text(json.dumps(case.spec))
        return where
    target = where / case.target
    if case.special:
        target.unlink(missing_ok=True)
        if case.special == "fifo":
            os.mkfifo(target)
        elif case.special == "devzero":
            target.symlink_to("/dev/zero")
        else:
            target.mkdir()
    return where if case.mode == "check" else target


def _item(case: Case, where: Path, target: Path) -> str:
    """What the batch task receives: '<mode>:<where>[:<id>]'."""
    if case.mode == "check":
        return f"check:{where}:{case.target}"
    if case.mode == "symlink":
        return f"symlink:{where}:{_pid(case.target)}"
    if case.mode in ("store", "options", *SURFACES):
        return f"{case.mode}:{where}"
    return f"{'strings' if case.mode == 'strings' else 'validate'}:{target}"


def _pid(target: str) -> str:
    """problems/<book>/<n>.yaml -> <book>-<n>."""
    parts = Path(target).parts
    return f"{parts[-2]}-{Path(parts[-1]).stem}"


def run_one(item: str, base: Path, options, stage) -> tuple[str, str, float]:
    """The batch task: (status, message, seconds) of one case. `item` is 'validate:<path>'
    or 'check:<root>:<id>'."""
    start = time.perf_counter()
    status, message = _classify(item, stage)
    return status, message, time.perf_counter() - start


def _classify(item: str, stage) -> tuple[str, str]:
    from mechbook.errors import MechbookError

    os.environ.pop("MECHBOOK_ROOT", None)
    logging.getLogger("mechbook").setLevel(logging.ERROR)  # a moved store's warning: expected
    mode, _, rest = item.partition(":")
    try:
        if mode in SURFACES:
            stage(mode)
            return RUNNERS[mode](Path(rest), json.loads((Path(rest) / "spec.json")
                                                                 .read_text()))
        if mode == "store":
            stage("store")
            return faults.run_store(Path(rest), json.loads((Path(rest) / "spec.json")
                                                           .read_text()))
        if mode == "options":
            stage("options")
            return faults.run_options(json.loads((Path(rest) / "spec.json").read_text()))
        if mode == "strings":
            stage("strings")
            return faults.run_strings(Path(rest))
        if mode == "symlink":
            stage("symlink")
            root, _, pid = rest.rpartition(":")
            return faults.run_symlink(Path(root), pid)
        if mode == "validate":
            from mechbook.app.authoring.validate import validate_file

            stage("validating")
            return "ok", validate_file(rest)[:300]
        from mechbook.app.running.run import RunOptions, run_problem

        root, _, pid = rest.rpartition(":")
        run = run_problem(pid, Path(root), RunOptions(crosscheck=False), stage)
        texts = [run.error or ""] + [o.detail for o in run.outcomes if o.status == "error"]
        # an engine fault: a traceback in the run's debug log (details hold messages only;
        # a traceback in a detail would be a failure of its own)
        crash = next((t for t in run.debug + texts if TRACEBACK in t), None)
        if crash:
            return "crash", crash
        return ("refused", run.error) if run.error else ("ok", f"{len(run.outcomes)} parts")
    except MechbookError as exc:
        message = str(exc)
        if not message.strip():
            return "crash", f"{type(exc).__name__} with an empty message"
        return "refused", message
    except Exception as exc:  # noqa: BLE001 - what the fuzzer looks for
        import traceback

        return "crash", f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}"


def stopped(item: str, why: str, seconds: float, stage: str) -> tuple[str, str, float]:
    """The batch's result for a case stopped from outside."""
    if "time limit" in why:
        status = "hang"
    elif "memory" in why:
        status = "bomb"
    else:
        status = "died"
    if item.startswith("check:") and status in ("hang", "bomb"):
        status = "limited"  # a whole check stopped by its limit is reported, by design
    return status, why, seconds


def run_cases(cases: list[Case], workdir: Path, jobs: int = 2, keep: Path | None = None,
              on_result=None) -> list[Result]:
    """Write the cases, run them on the batch machinery, classify, keep failures' files."""
    from mechbook.app.running.batch import Batch, BatchOptions

    items, by_item = [], {}
    for case in cases:
        where = workdir / f"case-{case.index}"
        target = write_case(case, where)
        item = _item(case, where, target)
        items.append(item)
        by_item[item] = (case, where)
    results: list[Result] = []
    # a whole check (the check kind, and the kinds of issue 44 that check: a Floquet
    # check compiles a Taylor integrator first, ~10 s) under the check's limit
    checking = ("check:", "periods:", "velocity:")
    groups = {"validate": [i for i in items if not i.startswith(checking)],
              "check": [i for i in items if i.startswith(checking)]}
    for mode, todo in groups.items():
        if not todo:
            continue
        limit = CHECK_SECONDS if mode == "check" else VALIDATE_SECONDS
        options = BatchOptions(jobs=jobs, timeout=limit, memory_mb=MEMORY_MB, max_tasks=200)
        batch = Batch(workdir, options, task=run_one, failed=stopped)
        for item, (status, message, seconds) in zip(todo, batch.run(todo), strict=True):
            case, where = by_item[item]
            res = Result(case.index, case.kind, status, message, seconds)
            results.append(res)
            if on_result:
                on_result(res)
            if keep is not None and status in BAD:
                dest = keep / f"case-{case.index}-{case.kind}-{status}"
                shutil.rmtree(dest, ignore_errors=True)
                if case.special:
                    dest.mkdir(parents=True, exist_ok=True)
                    (dest / "SPECIAL").write_text(f"{case.special}: {case.target}\n")
                else:  # links as links; a FIFO or device cannot be copied: noted
                    shutil.copytree(where, dest, symlinks=True,
                                    copy_function=_copy_regular)
                (dest / "RESULT.txt").write_text(f"{status}\n{message}\n")
    return sorted(results, key=lambda r: r.index)


def _copy_regular(src: str, dst: str) -> None:
    if os.path.isfile(src) and os.path.getsize(src) <= 1 << 24:
        shutil.copy2(src, dst)
    elif os.path.isfile(src):  # a sparse file of gigabytes: its size is what matters
        Path(dst + ".SPECIAL").write_text(f"a file of {os.path.getsize(src)} bytes: {src}\n")
    else:
        Path(dst + ".SPECIAL").write_text(f"not a regular file: {src}\n")


def fuzz(cases: int, seed: int = 1, jobs: int = 2, kinds: list[str] | None = None,
         keep: Path | None = None, chunk: int = 500, verbose: bool = False,
         log: Path | None = None) -> list[Result]:
    """Generate and run `cases` inputs, `chunk` at a time (a fresh temporary tree each);
    each chunk's results are appended to `log` (JSON lines) as it finishes."""
    pool = seeds()
    frozen = json.dumps([(s.data, s.key) for s in pool])
    kinds = kinds or list(KINDS)
    out: list[Result] = []
    for start in range(0, cases, chunk):
        batch = [generate(i, seed, pool, kinds) for i in range(start, min(cases, start + chunk))]
        assert json.dumps([(s.data, s.key) for s in pool]) == frozen, "the pool was mutated"
        with tempfile.TemporaryDirectory(prefix="mechbook-fuzz-") as tmp:
            res = run_cases(batch, Path(tmp), jobs, keep)
        out += res
        if log is not None:  # as the run goes, so an interrupted run keeps its numbers
            with open(log, "a", encoding="utf-8") as fh:
                fh.writelines(json.dumps(r.__dict__) + "\n" for r in res)
        if verbose:
            counts = Counter(r.status for r in out)
            print(f"[{len(out)}/{cases}] " + ", ".join(f"{k} {v}" for k, v in
                                                         sorted(counts.items())), flush=True)
    return out


BAD = ("crash", "hang", "bomb", "died", "lost", "leak", "unsafe", "outside")


def summary(results: list[Result]) -> str:
    statuses = ["ok", "refused", "limited", *BAD]
    lines = [f"| kind | cases | {' | '.join(statuses)} | slowest (s) |",
             "|" + " --- |" * (len(statuses) + 3)]
    kinds = sorted({r.kind for r in results}, key=list(KINDS).index)
    for kind in [*kinds, "all"]:
        rows = [r for r in results if kind in ("all", r.kind)]
        c = Counter(r.status for r in rows)
        slowest = max((r.seconds for r in rows), default=0.0)
        lines.append(f"| {kind} | {len(rows)} | " + " | ".join(str(c.get(s, 0)) for s in statuses)
                     + f" | {slowest:.1f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("--kinds", nargs="*", choices=list(KINDS), default=None)
    ap.add_argument("--keep", type=Path, default=ROOT / "results" / "fuzz",
                    help="where the files of failing cases are kept")
    ap.add_argument("--json", type=Path, default=None,
                    help="append every result here (JSON lines), chunk by chunk")
    args = ap.parse_args(argv)
    start = time.monotonic()
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text("")
    results = fuzz(args.cases, args.seed, args.jobs, args.kinds, args.keep, verbose=True,
                   log=args.json)
    print(summary(results))
    bad = [r for r in results if r.status in BAD]
    for r in bad[:20]:
        print(f"case {r.index} ({r.kind}): {r.status}: {r.message[:400]}")
    print(f"{len(results)} cases in {time.monotonic() - start:.0f} s; {len(bad)} failures "
          f"(files kept under {args.keep})")
    return 1 if bad else 0


if __name__ == "__main__":
    # run as the module `fuzz`, so the workers can import the task by that name
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import fuzz as _self

    sys.exit(_self.main())
