"""What is built from a problem is kept by the object that built it, never on the problem:
a model.built.Built keeps the systems and declared objects (once each), an engine Analysis
owns one and keeps what it derived, and what a check stores is read through their public
methods (issue 35, item 3)."""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path

import pytest

from mechbook.engine.analysis import Analysis
from mechbook.errors import NotFoundError
from mechbook.model.built import Built
from mechbook.model.problem import Problem, load_problem
from mechbook.model.system import system_name, system_of

ROOT = Path(__file__).resolve().parents[1]


def _problem(pid: str) -> Problem:
    book, number = pid.split("-", 1)
    return load_problem(ROOT / "problems" / book / f"{number}.yaml")


def test_a_problem_keeps_no_state_of_its_own():
    assert [f.name for f in fields(Problem) if f.name.startswith("_")] == []


def test_built_builds_each_system_once_and_lists_what_it_built():
    problem = _problem("lim-2029")  # two systems: general, sinusoidal
    built = Built(problem)
    assert built.systems_built() == [] and built.declared_built() is None
    second = built.system("sinusoidal")
    assert built.system("sinusoidal") is second
    assert built.systems_built() == [second]
    first = built.system("general")
    assert built.systems_built() == [first, second]  # the problem's order, not the calls'
    assert system_of(problem, "general") is not first  # built anew, kept by nobody
    with pytest.raises(NotFoundError, match="has no system 'nosuch'"):
        built.system("nosuch")
    with pytest.raises(NotFoundError, match="several systems"):
        system_name(problem)


def test_a_body_made_of_parts_uses_the_declared_objects_its_builder_keeps():
    built = Built(_problem("symon-11-17"))  # rigid body `planet` with inertia: {body: ringed}
    built.system()
    decl = built.declared_built()
    assert decl is not None and list(decl.bodies) == ["ringed"]
    assert built.declared() is decl


def test_an_analysis_keeps_what_it_derived_and_a_new_one_starts_empty():
    problem = _problem("lim-2031")
    analysis = Analysis(problem)
    assert analysis.derived() == []
    analysis.equilibria().symbolic  # noqa: B018 - derive them
    (derived,) = analysis.derived()
    assert derived.system is analysis.system()
    assert derived.dynamics is analysis.dynamics()
    assert derived.equilibria is analysis.equilibria()
    assert derived.equilibria.solved  # the closed-form equilibria found
    assert derived.linear == []
    analysis.linear(None, derived.equilibria.solved[0])
    assert len(analysis.derived()[0].linear) == 1
    fresh = Analysis(problem)  # the same Problem object: nothing carried over
    assert fresh.derived() == [] and fresh.built.systems_built() == []
    shared = Analysis(problem, simplify=True, built=analysis.built)
    assert shared.system() is analysis.system()  # systems shared, derivations not
    assert shared.derived()[0].dynamics is None
