"""Shared fixtures for the test suite.

The helper modules beside the tests (systems.py, hostile.py, fuzz.py, fuzz_faults.py, and
test modules whose helpers others reuse, such as test_store.make_record) are importable by
name: pyproject.toml puts tests/ on the path (`pythonpath = ["tests"]`), so no test module
inserts into sys.path.

Tiers: tests marked `slow` (whole modules by `pytestmark`) are left out of
`make test-quick` (`-m 'not slow'`). The two mutation tests of every answer key (the
checker's structural mutants, tests/test_checker.py, and its 1 % mutants,
tests/test_power.py) run on a sample of six keys in `make test`; on every other key they
are marked `mutation` too and run in `make test-mutation` (CI runs both; the sample and
the marks: tests/mutation_keys.py).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from mechbook.engine.analysis import Analysis
from mechbook.model.catalog import problem_path
from mechbook.model.problem import load_problem

ROOT = Path(__file__).resolve().parents[1]  # the repository: books.yaml, problems/, answers/
TESTS = ROOT / "tests"


@pytest.fixture(scope="session")
def root() -> Path:
    """The repository's root, with its committed problems and answer keys."""
    return ROOT


@pytest.fixture(scope="session")
def repo_analysis() -> Callable[[str], Analysis]:
    """`repo_analysis("lim-2031")`: the analysis of a committed problem, built once per
    test process (the derivations it caches are shared by every test that asks)."""
    cache: dict[str, Analysis] = {}

    def get(pid: str) -> Analysis:
        if pid not in cache:
            cache[pid] = Analysis(load_problem(problem_path(pid, ROOT)))
        return cache[pid]

    return get
