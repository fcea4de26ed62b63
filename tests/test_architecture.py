"""The layout: which stage may import which, no import cycles (not even through imports inside
functions), the cross-checks independent of the engine's kinematics, the docs' table of
quantities equal to the registry, and no quantity named outside its registration."""

from __future__ import annotations

import ast
import functools
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "mechbook"

# stage -> the stages it may import (itself always allowed); see each package's __init__
BASE = {"errors", "records", "version"}
ALLOWED = {
    "errors": set(),
    "records": set(),
    "version": set(),
    "core": BASE,
    "model": BASE | {"core"},
    "engine": BASE | {"core", "model"},
    "numerics": BASE | {"core", "model", "engine"},
    "verify": BASE | {"core", "model", "engine", "numerics"},
    "crosscheck": BASE | {"core", "model", "engine", "numerics", "verify"},
    "app": BASE | {"core", "model", "engine", "numerics", "verify", "crosscheck", "app"},
    "__init__": {"app", "version"},  # app lazily (PEP 562): mechbook.load, mechbook.results
    "__main__": {"app"},
}
# modules a stage must not import even though the stage itself is allowed
FORBIDDEN = {"crosscheck": {"mechbook.model.bodies", "mechbook.model.attitude"}}


def modules() -> dict[str, Path]:
    """{module name: its file} of the package (a copy: the caller may change it)."""
    return dict(_modules())


@functools.cache
def _modules() -> dict[str, Path]:
    """Walked once per test process: `imports` asks for every file it reads, and the
    cycle tests read every module three times (each walk of the package took ~1.5 ms,
    10^3 times per test)."""
    out = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(ROOT).with_suffix("")
        name = ".".join(rel.parts)
        out[name.removesuffix(".__init__")] = path
    return out


def parsed(path: Path) -> ast.Module:
    """The file's syntax tree, parsed once per test process for each version of the file
    (the tests below read the same few hundred files many times over). Read only."""
    info = path.stat()
    return _parse(path, info.st_mtime_ns, info.st_size)


@functools.lru_cache(maxsize=4096)
def _parse(path: Path, mtime_ns: int, size: int) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"))


def stage(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _type_checking_only(tree: ast.Module) -> set[ast.AST]:
    """The imports under `if TYPE_CHECKING:` (read by type checkers, never run)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and getattr(node.test, "id", None) == "TYPE_CHECKING":
            out |= {n for stmt in node.body for n in ast.walk(stmt)}
    return out


def imports(path: Path, top_level_only: bool = False, runtime_only: bool = False) -> set[str]:
    """The mechbook modules a file imports (all of them, or only those at module level;
    `runtime_only`: without those under `if TYPE_CHECKING:`)."""
    tree = parsed(path)
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    if runtime_only:
        skip = _type_checking_only(tree)
        nodes = [n for n in nodes if n not in skip]
    out = set()
    for node in nodes:
        if isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path}: relative import (use mechbook.<stage>.<module>)"
            if node.module and node.module.startswith("mechbook"):
                out.add(node.module)
                out |= {f"{node.module}.{a.name}" for a in node.names}
        elif isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("mechbook")}
    known = _modules()
    return {m for m in out if m in known}


@pytest.mark.parametrize("module", sorted(modules()))
def test_each_module_imports_only_what_its_stage_may(module):
    path = modules()[module]
    own = stage(module)
    bad = sorted(m for m in imports(path) if stage(m) != own and stage(m) not in ALLOWED[own]
                 and m != "mechbook")
    assert not bad, f"{module} ({own}) may not import {bad}"
    forbidden = sorted(m for m in imports(path) for f in FORBIDDEN.get(own, set())
                       if m == f or m.startswith(f + "."))  # a package and its modules
    assert not forbidden, f"{module} must not import {forbidden}"


# import cycles the test tolerates, each with why it is left (none: every cycle is broken)
KNOWN_CYCLES: list[set[str]] = []


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected groups of more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out = []

    def visit(m: str) -> None:
        index[m] = low[m] = len(index)
        stack.append(m)
        on_stack.add(m)
        for n in sorted(graph.get(m, ())):
            if n not in index:
                visit(n)
                low[m] = min(low[m], low[n])
            elif n in on_stack:
                low[m] = min(low[m], index[n])
        if low[m] == index[m]:
            group = []
            while True:
                n = stack.pop()
                on_stack.discard(n)
                group.append(n)
                if n == m:
                    break
            if len(group) > 1:
                out.append(sorted(group))

    for m in sorted(graph):
        if m not in index:
            visit(m)
    return out


def test_no_import_cycles_even_inside_functions():
    """Every import counts, at module level or inside a function (an import deferred into a
    function only hides a cycle); those under `if TYPE_CHECKING:` never run."""
    graph = {m: imports(p, runtime_only=True) - {m} for m, p in modules().items()}
    cycles = [c for c in import_cycles(graph) if set(c) not in KNOWN_CYCLES]
    shown = ["; ".join(f"{m} -> {sorted(graph[m] & set(c))}" for m in c) for c in cycles]
    assert not cycles, "import cycles:\n" + "\n".join(shown)


def test_no_import_cycles_even_for_type_hints():
    """Imports under `if TYPE_CHECKING:` count too: a module that needs another's type for a
    hint, while that one imports it, shares the type through a module below both (issue 43:
    mechbook.model.data below yamlio and fastyaml; mechbook.app.api.loaded below the API's
    problem and its systems; the system contract without the System it describes)."""
    graph = {m: imports(p) - {m} for m, p in modules().items()}
    typed = {m: (imports(p) - imports(p, runtime_only=True)) - {m}
             for m, p in modules().items()}
    cycles = [c for c in import_cycles(graph) if any(typed[m] & set(c) for m in c)]
    shown = ["; ".join(f"{m} -> {sorted(typed[m] & set(c))} (for type hints)" for m in c
                       if typed[m] & set(c)) for c in cycles]
    assert not cycles, "import cycles through TYPE_CHECKING imports:\n" + "\n".join(shown)


def test_the_cycle_test_can_fail():
    assert import_cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert import_cycles({"a": {"b"}, "b": set()}) == []


def test_every_package_says_what_it_owns_and_may_import():
    """Each stage, and each package of mechbook.app (issue 43: the folder shows the parts)."""
    for init in [*PACKAGE.glob("*/__init__.py"), *(PACKAGE / "app").glob("*/__init__.py")]:
        doc = ast.get_docstring(parsed(init)) or ""
        assert "May import" in doc, f"{init}: the docstring states no import rule"


def test_the_rules_forbid_what_they_should():
    """The test itself can fail: an upward import and the engine's kinematics are refused."""
    assert "engine" not in ALLOWED["model"] and "verify" not in ALLOWED["engine"]
    assert {"mechbook.model.bodies", "mechbook.model.attitude"} <= FORBIDDEN["crosscheck"]


def test_docs_table_of_quantities_is_the_registry():
    from mechbook.verify.registry import markdown_table

    text = (ROOT / "docs" / "answers.md").read_text(encoding="utf-8")
    begin, end = "<!-- quantities:begin -->", "<!-- quantities:end -->"
    assert begin in text and end in text
    table = text.split(begin, 1)[1].split(end, 1)[0].strip()
    assert table == markdown_table(), ("docs/answers.md is out of date; regenerate with "
                                       "`python -m mechbook.verify.registry`")


def test_a_key_that_does_not_apply_to_the_quantity_is_refused(tmp_path):
    from mechbook.errors import SpecError
    from mechbook.verify.answers import load_answers

    f = tmp_path / "key.yaml"
    f.write_text("problem: lim-2031\nsource: s\nparts:\n  - part: a\n    cite: c\n"
                 "    quantity: frequencies\n    stable: true\n    book: [1]\n")
    with pytest.raises(SpecError, match=r"key\.yaml:7: .*'stable' does not apply to quantity "
                                        r"'frequencies'"):
        load_answers(f)


# ---- one quantity, one registration ----------------------------------------------------------
# registered quantity names that are also ordinary words of crosscheck/ and app/ (what else
# they name there); they may appear, but never compared with a part's quantity
HOMONYMS = {
    "frequencies": "the frequency cross-check's kind, a sweep quantity, a table column",
    "stability": "a sweep quantity, a table column, a stored array",
    "conserved": "the first-integral cross-check's kind",
    "period": "a measured value of the trajectory cross-check",
    "lagrangian": "a system's `lagrangian:` key",
    "components": "a torque's `components:` key",
    "equilibrium": "a row kind of the report's table of equilibria",
    "motion": "the report's animated motion",
}
# where a quantity's name may be spelled: its registration and the checks it registers
OUTSIDE_REGISTRY = ("crosscheck", "app")


def _is_part_quantity(node: ast.AST, names: set[str]) -> bool:
    """`part.quantity`, `ctx.part.quantity`, an outcome's `.quantity` (not a sweep's
    `spec.quantity`), or a local name assigned from one."""
    if isinstance(node, ast.Name):
        return node.id in names
    if not (isinstance(node, ast.Attribute) and node.attr == "quantity"):
        return False
    base = node.value
    return getattr(base, "attr", getattr(base, "id", None)) != "spec"


def quantity_names_used(source: str, registered: set[str]) -> list[str]:
    """Registered quantity names a module spells (other than its HOMONYMS), and every string
    compared with a part's quantity: a choice by quantity that belongs in the registry."""
    tree = ast.parse(source)
    aliases = {t.id for node in ast.walk(tree) if isinstance(node, ast.Assign)
               and _is_part_quantity(node.value, set()) for t in node.targets
               if isinstance(t, ast.Name)}
    found = []
    for node in ast.walk(tree):
        if (isinstance(node, ast.Constant) and isinstance(node.value, str)
                and node.value in registered and node.value not in HOMONYMS):
            found.append(f"line {node.lineno}: {node.value!r}")
        if isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(_is_part_quantity(s, aliases) for s in sides):
                found += [f"line {node.lineno}: {c.value!r} compared with a part's quantity"
                          for s in sides for c in ast.walk(s)
                          if isinstance(c, ast.Constant) and isinstance(c.value, str)]
    return found


def _outside_registry() -> list[str]:
    return sorted(m for m in modules() if stage(m) in OUTSIDE_REGISTRY)


@pytest.mark.parametrize("module", _outside_registry())
def test_no_quantity_is_named_outside_the_registry(module):
    from mechbook.verify.registry import default_quantities

    source = modules()[module].read_text(encoding="utf-8")
    found = quantity_names_used(source, set(default_quantities()))
    assert not found, (f"{module} names quantities: {found}; declare it in the quantity's "
                       "registration (crosschecks=, display=, sweeps=) and read it from there")


def test_the_quantity_name_test_can_fail():
    from mechbook.verify.registry import default_quantities

    assert set(HOMONYMS) <= set(default_quantities()), "a homonym that is no quantity any more"
    registered = {"eom", "frequencies"}
    assert quantity_names_used('X = ("eom",)', registered)
    assert quantity_names_used('if part.quantity == "frequencies": pass', registered)
    assert quantity_names_used('q = ctx.part.quantity\nok = q in ("x", "y")', registered)
    assert not quantity_names_used('kind = "frequencies"', registered)
    assert not quantity_names_used('ok = spec.quantity == "frequencies"', registered)
    assert not quantity_names_used('ok = self.spec.quantity == "frequencies"', registered)


def test_every_declared_use_of_a_quantity_is_known():
    """Each name a registration declares is a cross-check, display or sweep that exists, and
    each of those is declared by some quantity."""
    from mechbook.app.report.values import DISPLAYS
    from mechbook.app.sweep import QUANTITIES as SWEEPS
    from mechbook.crosscheck.problem import CROSSCHECKS
    from mechbook.verify.registry import default_quantities

    table = default_quantities().values()
    for q in table:
        assert set(q.crosschecks) <= set(CROSSCHECKS), (q.name, q.crosschecks)
        assert q.display is None or q.display in DISPLAYS, (q.name, q.display)
        assert set(q.sweeps) <= set(SWEEPS), (q.name, q.sweeps)
    assert {c for q in table for c in q.crosschecks} == set(CROSSCHECKS)
    assert {q.display for q in table} - {None} == set(DISPLAYS)
    assert {s for q in table for s in q.sweeps} == set(SWEEPS) - {"drift"}  # drift: no key


# ---- statuses: compared as Status members, never as their strings -------------------------
STATUS_VALUES = {"pass", "fail", "erratum", "unsupported", "error", "n.a."}
STATUS_COMPARED_IN = ("app", "crosscheck", "verify")


def _names_a_status(node: ast.AST) -> bool:
    """`status`, `x.status`, `x.mode_status`, `r["status"]` or `r.get("status", ...)`."""
    if isinstance(node, ast.Name):
        return node.id.lower().endswith("status")
    if isinstance(node, ast.Attribute):
        return node.attr.lower().endswith("status")
    key = None
    if isinstance(node, ast.Subscript):
        key = node.slice
    elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
          and node.func.attr == "get" and node.args):
        key = node.args[0]
    return (isinstance(key, ast.Constant) and isinstance(key.value, str)
            and key.value.lower().endswith("status"))


def _status_literals(node: ast.AST) -> list[str]:
    """A status's string, alone or in a tuple, list or set of them."""
    if isinstance(node, ast.Constant):
        return [node.value] if isinstance(node.value, str) and node.value in STATUS_VALUES \
            else []
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return [v for e in node.elts for v in _status_literals(e)]
    return []


def status_literals_compared(source: str) -> list[str]:
    """Each string of a status value compared (==, !=, in, not in, ...) with a status."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(_names_a_status(s) for s in sides):
                found += [f"line {node.lineno}: {v!r}" for s in sides
                          for v in _status_literals(s)]
    return found


@pytest.mark.parametrize("module", sorted(m for m in modules()
                                          if stage(m) in STATUS_COMPARED_IN))
def test_no_status_is_compared_with_its_string(module):
    found = status_literals_compared(modules()[module].read_text(encoding="utf-8"))
    assert not found, (f"{module} compares a status with a string: {found}; use "
                       "mechbook.records.Status (and its tuples STATUSES, "
                       "CROSSCHECK_STATUSES, FAILING)")


def test_the_status_test_can_fail():
    for bad in ('ok = o.status == "pass"', 'ok = "fail" != x.status',
                'ok = o.status in ("fail", "error")', 'ok = r["status"] == "erratum"',
                'ok = m.get("status", "") not in ["n.a."]', 'ok = status == "unsupported"',
                'ok = a < self.cross_status == "pass"'):
        assert status_literals_compared(bad), bad
    for good in ('ok = o.status == Status.PASS', 'ok = o.status in FAILING',
                 'ok = kind == "error"', 'ok = o.status == "passed"', 'message = "fail"',
                 'ok = status.startswith("pass")'):
        assert not status_literals_compared(good), good


# ---- size: modules and functions short enough to read ---------------------------------------
MAX_MODULE_LINES = 400
MAX_FUNCTION_LINES = 60  # from `def` to the last line of the body (decorators not counted)
SIZED = ("app", "crosscheck")  # the stages held to the limits
# too long and allowed for now (none today). An entry that is no longer too long fails the
# test below: take it out, so the list cannot go stale.
KNOWN_LONG: set[str] = set()


def too_long(path: Path) -> dict[str, int]:
    """{'<file>' or '<file>:<function>': lines} of a module over MAX_MODULE_LINES and each
    function (or method, nested ones too) over MAX_FUNCTION_LINES."""
    source = path.read_text(encoding="utf-8")
    name = path.relative_to(ROOT).as_posix() if path.is_relative_to(ROOT) else path.name
    out = {}
    lines = len(source.splitlines())
    if lines > MAX_MODULE_LINES:
        out[name] = lines
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            length = node.end_lineno - node.lineno + 1
            if length > MAX_FUNCTION_LINES:
                out[f"{name}:{node.name}"] = length
    return out


def _sized_files() -> list[Path]:
    return sorted(p for stage_ in SIZED for p in (PACKAGE / stage_).rglob("*.py"))


def test_no_module_or_function_too_long():
    found = {k: v for p in _sized_files() for k, v in too_long(p).items()}
    new = {k: v for k, v in found.items() if k not in KNOWN_LONG}
    assert not new, (f"over {MAX_MODULE_LINES} lines a module or {MAX_FUNCTION_LINES} a "
                     f"function: {new}; split it by job")
    stale = sorted(KNOWN_LONG - set(found))
    assert not stale, f"no longer too long, take them out of KNOWN_LONG: {stale}"


def test_the_size_test_can_fail(tmp_path):
    path = tmp_path / "probe.py"
    path.write_text("def f():\n" + "    x = 1\n" * MAX_FUNCTION_LINES
                    + "\n" * (MAX_MODULE_LINES - MAX_FUNCTION_LINES), encoding="utf-8")
    assert set(too_long(path)) == {"probe.py", "probe.py:f"}
    path.write_text("def f():\n    pass\n", encoding="utf-8")
    assert too_long(path) == {}


# ---- the docs' table names every module of the application ----------------------------------
def _documented_app_modules() -> str:
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    row = next(ln for ln in text.splitlines() if ln.startswith("| `mechbook.app` |"))
    return row


def test_docs_table_names_every_app_module():
    """Each module of mechbook/app (and of its packages, named as `package/` with its
    modules) is named in the `mechbook.app` row of docs/architecture.md's table."""
    row = _documented_app_modules()
    words = set(re.findall(r"[A-Za-z_]+", row))
    missing = []
    for path in sorted((PACKAGE / "app").rglob("*.py")):
        rel = path.relative_to(PACKAGE / "app")
        if rel.name == "__init__.py":
            rel = rel.parent
            if rel == Path("."):
                continue
            if f"{rel.as_posix()}/" not in row:
                missing.append(f"{rel.as_posix()}/")
            continue
        if rel.stem not in words:
            missing.append(rel.as_posix())
    assert not missing, f"docs/architecture.md's table does not name: {missing}"


# ---- no module that nothing uses -------------------------------------------------------------
ENTRY_POINTS = {"mechbook.__main__"}  # `python -m mechbook`


def unused_modules(known: dict[str, Path], users: list[Path]) -> list[str]:
    """The modules of `known` that no other file imports (a mechbook module, a benchmark or
    a test: imports inside functions count) and no mechbook module names as a string (a
    fork server's preload list), and that are no entry point."""
    used: set[str] = set()
    owner = {p: m for m, p in known.items()}
    for path in [*known.values(), *users]:
        own = owner.get(path)
        for name in imports(path):
            if name != own:
                parts = name.split(".")
                used |= {".".join(parts[:i]) for i in range(1, len(parts) + 1)}
    text = "\n".join(p.read_text(encoding="utf-8") for p in known.values())
    named = set(re.findall(r"[\"'](mechbook(?:\.\w+)+)[\"']", text))
    return sorted(m for m in known if m not in used | named | ENTRY_POINTS)


def test_every_module_is_used_somewhere():
    """A module nothing imports is dead code that still has to be read and kept (issue 34
    found mechbook/app/report/figures.py so)."""
    users = sorted([*(ROOT / "bench").rglob("*.py"), *(ROOT / "tests").rglob("*.py")])
    assert unused_modules(modules(), users) == []


def test_the_unused_module_test_can_fail(tmp_path):
    known = dict(modules())
    orphan = tmp_path / "orphan.py"
    orphan.write_text('"""Nobody imports me."""\n', encoding="utf-8")
    known["mechbook.app.orphan"] = orphan
    assert "mechbook.app.orphan" in unused_modules(known, [])


def test_an_answer_key_record_and_its_loader_do_not_import_each_other():
    """verify.part (the key and part records) is below verify.answers (the loader, which
    needs the table of quantities): not even a TYPE_CHECKING import goes back up."""
    assert "mechbook.verify.answers" not in imports(modules()["mechbook.verify.part"])
    assert "mechbook.verify.part" in imports(modules()["mechbook.verify.answers"])


# ---- the store and the sweeps: packages with a public __init__ -------------------------------
def test_the_sweep_package_names_resolve_to_their_modules():
    """mechbook.app.sweep loads its names on first use (the command line must not load NumPy
    at start-up): each public name is in `__all__` and in the table, and is found there."""
    import importlib

    import mechbook.app.sweep as sweep

    assert sorted(sweep.__all__) == sorted(sweep._HOME)
    for name, home in sweep._HOME.items():
        assert getattr(sweep, name) is getattr(importlib.import_module(home), name), name
    with pytest.raises(AttributeError):
        sweep.no_such_name  # noqa: B018


def test_the_api_package_names_resolve_to_their_modules():
    """mechbook.app.api loads its names on first use, as mechbook.load does."""
    import importlib

    import mechbook.app.api as api

    assert sorted(api.__all__) == sorted(api._HOME)
    for name, home in api._HOME.items():
        assert getattr(api, name) is getattr(importlib.import_module(home), name), name
    with pytest.raises(AttributeError):
        api.no_such_name  # noqa: B018


def test_the_store_package_exports_what_it_lists():
    import mechbook.app.store as store

    missing = [n for n in store.__all__ if not hasattr(store, n)]
    assert not missing, missing


# ---- issue 35: no private name crosses a module, function-level imports only with a reason ----
def _imports_from_mechbook(path: Path):
    """(node, inside a function?) for each `from mechbook... import ...` of a file."""
    tree = parsed(path)
    inside = {id(n) for fn in ast.walk(tree)
              if isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef)
              for n in ast.walk(fn)}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("mechbook"):
            yield node, id(node) in inside


def private_imports(paths) -> list[str]:
    return [f"{p.name}:{node.lineno} {node.module}.{a.name}"
            for p in paths for node, _ in _imports_from_mechbook(p) for a in node.names
            if a.name.startswith("_") and not a.name.startswith("__")]


def test_no_module_imports_another_modules_private_name():
    paths = [*PACKAGE.rglob("*.py"), *(ROOT / "tests").rglob("*.py"),
             *(ROOT / "bench").rglob("*.py")]
    assert private_imports(paths) == []


def test_the_private_import_test_can_fail(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("def f():\n    from mechbook.verify.power import _hidden, public\n")
    assert private_imports([probe]) == ["probe.py:2 mechbook.verify.power._hidden"]
    assert [inside for _, inside in _imports_from_mechbook(probe)] == [True]  # in a function


# where a function may import a mechbook module: start-up time (the command line, `import
# mechbook`, the entry point that catches a Ctrl-C during the imports, books.yaml's reader,
# a sweep's spec, the editor's schemas) or the engine kept out of a warm check and of
# `validate` (run, validate); each such import says why
LAZY_IMPORTS = ("mechbook/__init__.py", "mechbook/__main__.py", "mechbook/app/cli/",
                "mechbook/app/running/run.py",
                "mechbook/app/authoring/validate.py", "mechbook/app/authoring/editor.py",
                "mechbook/app/sweep/spec.py", "mechbook/model/books.py")


def test_function_level_imports_only_where_start_up_needs_them():
    found = [f"{p.relative_to(ROOT)}:{node.lineno}" for p in PACKAGE.rglob("*.py")
             for node, inside in _imports_from_mechbook(p)
             if inside and not str(p.relative_to(ROOT)).startswith(LAZY_IMPORTS)]
    assert found == []


def private_module_reads(paths) -> list[str]:
    """`module._name` where `module` is a mechbook module the file imported by name."""
    known = set(modules())
    out = []
    for p in paths:
        tree = parsed(p)
        bound = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("mechbook"):
                bound |= {a.asname or a.name for a in node.names
                          if f"{node.module}.{a.name}" in known}
            elif isinstance(node, ast.Import):
                bound |= {a.asname for a in node.names if a.asname and a.name in known}
        out += [f"{p.name}:{n.lineno} {n.value.id}.{n.attr}" for n in ast.walk(tree)
                if isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name)
                and n.value.id in bound and n.attr.startswith("_")
                and not n.attr.startswith("__")]
    return out


def test_no_module_reads_another_modules_private_name_through_it():
    assert private_module_reads(list(PACKAGE.rglob("*.py"))) == []


def test_the_private_read_test_can_fail(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("from mechbook.verify import boundary\n"
                     "import mechbook.verify.power as power\n"
                     "x = boundary._hidden, power._other, boundary.public\n")
    assert private_module_reads([probe]) == ["probe.py:3 boundary._hidden",
                                             "probe.py:3 power._other"]


# ---- issue 43: mechbook/app shows its parts, one package per kind ---------------------------
# the modules left flat in mechbook/app, each shared by several of its packages (a module of
# one package's kind belongs in that package)
APP_FLAT = {
    "options": "numeric options with bounds and a batch's default limits: the command line, "
               "the API's argument checks, the batch, watch and sweeps read them (--help too)",
    "outputs": "where results may be written (regular files, replaced whole): the store, "
               "sweeps, formats, the report, the editor's schemas and restore write through it",
    "bounded": "files mechbook reads back, read within bounds: the store's side file, the "
               "report's page list, watch's polled files, the last failures",
    "selection": "which problems a command means (ids, patterns, books, --lf): the command "
                 "line and the check service",
    "fingerprint": "content hashes for the warm-run cache: the store, the check and the report",
    "docs": "the documentation pages, in a checkout or in the wheel: the command line, and "
            "the pages --help and the starter point to",
}
# the packages of mechbook/app from the bottom up: each imports only those below it (and the
# flat modules above), with the exceptions below, each with why
APP_PACKAGES = ("output", "store", "running", "sweep", "report", "authoring", "api", "cli")
APP_EXCEPTIONS = {
    ("running", "mechbook.app.authoring.validate"):
        "every check starts with validate's bounded build of the problem and its key",
}


def test_app_has_no_flat_module_beyond_the_shared_ones():
    flat = sorted(p.stem for p in (PACKAGE / "app").glob("*.py") if p.stem != "__init__")
    assert flat == sorted(APP_FLAT), ("a module of one kind belongs in its package (api/, "
                                      "running/, authoring/, output/, ...); one shared by "
                                      "several is listed in APP_FLAT with why")
    packages = sorted(p.parent.name for p in (PACKAGE / "app").glob("*/__init__.py"))
    assert packages == sorted(APP_PACKAGES), "a new package of mechbook.app: place it in order"


def test_the_packages_passed_through_at_start_up_import_nothing():
    """The fork server imports running.forkstart first (before the engine, to ignore Ctrl-C)
    and the command line reads output.text and authoring's modules at start-up: their
    packages' `__init__` import nothing; api's only importlib (its names load on first use)."""
    for name in ("running", "authoring", "output", "api"):
        tree = ast.parse((PACKAGE / "app" / name / "__init__.py").read_text("utf-8"))
        imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        imported |= {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
        assert imported <= {"__future__", "importlib"}, (name, imported)


def app_layer_breaches(known: dict[str, Path]) -> list[str]:
    """Imports (TYPE_CHECKING ones too) from one package of mechbook.app to another that is
    not below it in APP_PACKAGES, and from a flat module to any package."""
    def package(module: str) -> str | None:  # None: a flat module, app itself, or outside
        parts = module.split(".")
        inside = len(parts) > 2 and parts[:2] == ["mechbook", "app"]
        return parts[2] if inside and (PACKAGE / "app" / parts[2]).is_dir() else None

    out = []
    for m, path in sorted(known.items()):
        if not m.startswith("mechbook.app."):
            continue
        own = package(m)
        for n in sorted(imports(path)):
            other = package(n)
            if other is None or other == own or (own, n) in APP_EXCEPTIONS:
                continue
            if own is None or APP_PACKAGES.index(other) > APP_PACKAGES.index(own):
                out.append(f"{m} -> {n}")
    return out


def test_each_app_package_imports_only_those_below_it():
    assert app_layer_breaches(modules()) == []


def test_the_app_layer_test_can_fail(tmp_path):
    known = dict(modules())
    up = tmp_path / "up.py"
    up.write_text("from mechbook.app.cli.common import echo\n", encoding="utf-8")
    known["mechbook.app.output.up"] = up
    flat = tmp_path / "flat.py"
    flat.write_text("from mechbook.app.store import read\n", encoding="utf-8")
    known["mechbook.app.flat"] = flat
    assert app_layer_breaches(known) == ["mechbook.app.flat -> mechbook.app.store",
                                         "mechbook.app.output.up -> mechbook.app.cli.common"]
