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

A test skipped for a missing tool (Chromium for the report's pages, node for ajv) says so
in the run's last lines: `pytest_terminal_summary` below counts the skips by reason, so a
`make test` without `-rs` still shows what it did not test.
"""

from __future__ import annotations

from collections import Counter
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


def skip_reason(report: pytest.TestReport) -> str:
    """Why a test was skipped: its `pytest.skip` (or `skipif`, `importorskip`) reason."""
    longrepr = report.longrepr
    reason = str(longrepr[2]) if isinstance(longrepr, (tuple, list)) and len(longrepr) == 3 \
        else str(longrepr)
    return reason.removeprefix("Skipped: ").strip() or "no reason given"


def pytest_terminal_summary(terminalreporter, exitstatus, config) -> None:
    """Each skip reason, with how many tests it skipped, just above the run's last line
    (pytest shows them only under `-rs`; a missing browser skips the report's page tests
    and must not pass unnoticed)."""
    skipped = [r for r in terminalreporter.stats.get("skipped", ())
               if getattr(r, "longrepr", None) is not None and not hasattr(r, "wasxfail")]
    if not skipped:
        return
    reasons = Counter(skip_reason(r) for r in skipped)
    terminalreporter.write_sep("-", f"{len(skipped)} skipped, by reason", yellow=True)
    for reason, count in reasons.most_common():
        terminalreporter.write_line(f"{count:4d} × {reason}")
