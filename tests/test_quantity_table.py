"""The table of quantities is a value a check is given: a key is read against a table (the
built-in one unless a caller passes its own), checked with it, and a part whose quantity is
not in the table is refused with its file:line. The built-in table is built from the quantity
modules registry.MODULES names, and nothing is registered by importing a module."""

from __future__ import annotations

import dataclasses
import pkgutil
from pathlib import Path

import pytest
import sympy as sp
from hostile import pendulum_tree

import mechbook.verify.quantities as quantity_package
from mechbook.engine.analysis import Analysis
from mechbook.errors import SpecError
from mechbook.model.problem import load_problem
from mechbook.records import Status
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem
from mechbook.verify.compare import vanishes
from mechbook.verify.part import Part
from mechbook.verify.registration import Family, QuantityTable
from mechbook.verify.registry import MODULES, answers_schema, default_quantities
from mechbook.verify.wellformed import validate_key

OWN = Family()


@OWN.quantity("stiffness_ratio", book="K/M of the linearized one-coordinate system",
              how="K[0,0]/M[0,0] of the engine's linearization at the default point")
def stiffness_ratio(ctx, value):
    """The test's own quantity. For the test pendulum (bob of mass m on a rod of length l,
    angle theta from the downward vertical): T = m l² θ̇²/2 and V = -m g l cos θ, so about
    θ = 0 the linearization has M = m l² and K = V''(0) = m g l, and K/M = g/l (worked by
    hand, not by the engine)."""
    lin = ctx.linear()
    engine = lin.K[0, 0] / lin.M[0, 0]
    return vanishes(ctx.parse(value, ("book",)) - engine, ctx.sampler)


TABLE = QuantityTable.of(OWN)


def _tree(tmp_path: Path, quantity: str, book: str) -> tuple[Path, Analysis]:
    base = pendulum_tree(tmp_path)
    key = base / "answers" / "lim" / "2101.yaml"
    text = key.read_text(encoding="utf-8")
    text = text.replace("quantity: eom", f"quantity: {quantity}")
    text = text.replace('book: ["l*thetaddot + g*sin(theta) = 0"]', f'book: "{book}"'
                        if quantity == "stiffness_ratio" else
                        'book: ["l*thetaddot + g*sin(theta) = 0"]')
    key.write_text(text, encoding="utf-8")
    return key, Analysis(load_problem(base / "problems" / "lim" / "2101.yaml"))


@pytest.mark.parametrize("book, status", [("g/l", Status.PASS), ("1.01*g/l", Status.FAIL),
                                          ("(1 + 1e-6)*g/l", Status.FAIL),
                                          ("l/g", Status.FAIL)])
def test_a_problem_checks_with_a_table_of_its_own(tmp_path, book, status):
    """The key is read against the test's table (its schema allows `stiffness_ratio`),
    validated and checked with it: the true value passes, values 1 % and 1e-6 off fail."""
    path, analysis = _tree(tmp_path, "stiffness_ratio", book)
    key = load_answers(path, TABLE)
    assert key.quantities is TABLE
    assert validate_key(analysis, key) == {}
    stages: list[str] = []
    (outcome,) = check_problem(analysis, key, stage=stages.append)
    assert outcome.status == status, outcome.detail
    assert outcome.quantity == "stiffness_ratio"
    assert stages == ["part a (stiffness_ratio)"]


def test_the_built_in_table_does_not_know_the_tests_quantity(tmp_path):
    path, _ = _tree(tmp_path, "stiffness_ratio", "g/l")
    with pytest.raises(SpecError) as err:
        load_answers(path)
    assert f"{path}:6:" in str(err.value)
    assert "parts/0/quantity: 'stiffness_ratio' is not one of " in str(err.value)


def test_a_part_whose_quantity_is_not_in_the_table_is_refused(tmp_path):
    """Read against the test's table, a key naming the built-in `eom` is refused at its
    line; read with the built-in table and checked with the test's, the part is an error
    that says so (file:line), before anything is evaluated, and validation says the same."""
    path, analysis = _tree(tmp_path, "eom", "")
    with pytest.raises(SpecError) as err:
        load_answers(path, TABLE)
    assert f"{path}:6:" in str(err.value)
    assert "'eom' is not one of ['stiffness_ratio']" in str(err.value)

    key = load_answers(path)  # the built-in table: `eom` is known and passes
    assert [o.status for o in check_problem(analysis, key)] == [Status.PASS]
    (outcome,) = check_problem(analysis, key, quantities=TABLE)
    assert outcome.status == Status.ERROR
    assert outcome.detail == (f"{path}:6: parts/0/quantity: 'eom' is not a quantity of the "
                              "table this check uses (1 quantities)")
    faults = validate_key(analysis, key, TABLE)
    assert list(faults) == ["a"] and str(faults["a"]) == outcome.detail


def test_the_schema_follows_the_table():
    own = answers_schema(TABLE)["$defs"]["part"]
    assert own["properties"]["quantity"] == {"enum": ["stiffness_ratio"]}
    built_in = answers_schema()["$defs"]["part"]["properties"]["quantity"]["enum"]
    assert "eom" in built_in and "stiffness_ratio" not in built_in


def test_the_built_in_table_is_built_from_every_quantity_module():
    """Every module of mechbook.verify.quantities is listed in registry.MODULES (a family
    left out would silently vanish from the table), and the table is their entries."""
    listed = {m.__name__.rsplit(".", 1)[1] for m in MODULES}
    present = {m.name for m in pkgutil.iter_modules(quantity_package.__path__)}
    assert listed == present
    table = default_quantities()
    names = [q.name for m in MODULES for q in m.FAMILY.entries]
    assert sorted(names) == sorted(table) and len(names) == len(set(names))
    assert all(table[q.name] is q for m in MODULES for q in m.FAMILY.entries)


def test_a_name_in_two_families_is_refused():
    other = Family()
    other.quantity("stiffness_ratio", book="", how="")(lambda ctx, value: None)
    with pytest.raises(ValueError, match="'stiffness_ratio' is in the table twice"):
        QuantityTable.of(OWN, other)
    with pytest.raises(ValueError, match="declared twice"):
        OWN.quantity("stiffness_ratio", book="", how="")(lambda ctx, value: None)


def test_a_part_is_a_frozen_record_and_its_context_keeps_what_is_learned(tmp_path):
    """A Part holds only its key, index and data; an abbreviation that does not parse in
    the part's system is the context's knowledge (and its message), not the part's."""
    from mechbook.verify.context import Context

    assert [f.name for f in dataclasses.fields(Part)] == ["key", "index", "data"]
    path, analysis = _tree(tmp_path, "eom", "")
    path.write_text(path.read_text(encoding="utf-8").replace(
        "parts:", "abbreviations:\n  w: sqrt(g/l)*phi\nparts:"), encoding="utf-8")
    key = load_answers(path)
    (part,) = key.parts
    with pytest.raises(dataclasses.FrozenInstanceError):
        part.index = 1  # type: ignore[misc]
    ctx = Context(analysis, part)
    assert set(ctx.unavailable) == {"w"} and "phi" in ctx.unavailable["w"]
    assert "w" not in ctx.names and isinstance(ctx.names["theta"], sp.Basic)
    with pytest.raises(SpecError, match="abbreviation 'w' does not parse here"):
        ctx.parse("w*theta", ("book", 0))


def test_the_command_line_and_the_api_run_verifys_pipeline(tmp_path, monkeypatch):
    """`mechbook check` and `Problem.check()` validate with verify's validate_key and check
    with verify's check_problem (told the stage of each part), not a loop of their own."""
    from hostile import check

    import mechbook
    from mechbook.verify import checker, wellformed

    calls: list[tuple[str, list[str]]] = []
    real_check, real_validate = checker.check_problem, wellformed.validate_key

    def check_problem_spy(analysis, key, policy, stage=None, quantities=None):
        seen: list[str] = []

        def staged(text: str) -> None:
            seen.append(text)
            stage(text)

        out = real_check(analysis, key, policy, staged, quantities)
        calls.append(("check", seen))
        return out

    def validate_spy(analysis, key, quantities=None):
        calls.append(("validate", []))
        return real_validate(analysis, key, quantities)

    monkeypatch.setattr(checker, "check_problem", check_problem_spy)
    monkeypatch.setattr(wellformed, "validate_key", validate_spy)
    base = pendulum_tree(tmp_path)
    result = check(base, "--no-store")
    assert result.exit_code == 0, result.output
    assert calls == [("validate", []), ("check", ["part a (eom)"])]
    calls.clear()
    got = mechbook.load("lim-2101", base).check(crosscheck=False)
    assert got.ok and [o.status for o in got.outcomes] == [Status.PASS]
    assert calls == [("validate", []), ("check", ["part a (eom)"])]
