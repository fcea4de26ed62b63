"""The layout: which stage may import which, no import cycles, the cross-checks independent of
the engine's kinematics, and the docs' table of quantities equal to the registry."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "mechbook"

# stage -> the stages it may import (itself always allowed); see each package's __init__
BASE = {"errors", "records"}
ALLOWED = {
    "errors": set(),
    "records": set(),
    "core": BASE,
    "model": BASE | {"core"},
    "engine": BASE | {"core", "model"},
    "numerics": BASE | {"core", "model", "engine"},
    "verify": BASE | {"core", "model", "engine", "numerics"},
    "crosscheck": BASE | {"core", "model", "engine", "numerics", "verify"},
    "app": BASE | {"core", "model", "engine", "numerics", "verify", "crosscheck", "app"},
    "__init__": {"app"},  # lazily (PEP 562): mechbook.load, mechbook.results
    "__main__": {"app"},
}
# modules a stage must not import even though the stage itself is allowed
FORBIDDEN = {"crosscheck": {"mechbook.model.bodies", "mechbook.model.attitude"}}


def modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(ROOT).with_suffix("")
        name = ".".join(rel.parts)
        out[name.removesuffix(".__init__")] = path
    return out


def stage(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def imports(path: Path, top_level_only: bool = False) -> set[str]:
    """The mechbook modules a file imports (all of them, or only those at module level)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    out = set()
    for node in nodes:
        if isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path}: relative import (use mechbook.<stage>.<module>)"
            if node.module and node.module.startswith("mechbook"):
                out.add(node.module)
                out |= {f"{node.module}.{a.name}" for a in node.names}
        elif isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("mechbook")}
    known = modules()
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


def test_no_import_cycles_at_module_level():
    graph = {m: imports(p, top_level_only=True) - {m} for m, p in modules().items()}
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for n in sorted(graph.get(m, ())):
            if state.get(n) == 1:
                cycle = stack[stack.index(n):] + [n]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if n not in state:
                visit(n)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)


def test_every_package_says_what_it_owns_and_may_import():
    for init in PACKAGE.glob("*/__init__.py"):
        doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8"))) or ""
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
