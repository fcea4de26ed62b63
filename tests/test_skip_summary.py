"""A test skipped for a missing tool says so in the run's last lines (issue 42): the
suite's own hook (tests/conftest.py's pytest_terminal_summary and skip_reason, their source
copied into a run of a tiny test file, without the conftest's engine imports) counts the
skips by reason just above the final line, without `-rs`."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

SOURCE = Path(__file__).with_name("conftest.py").read_text()
HOOK = "\n\n".join(
    ["from collections import Counter", "import pytest"]
    + [ast.get_source_segment(SOURCE, node) for node in ast.parse(SOURCE).body
       if isinstance(node, ast.FunctionDef)
       and node.name in ("skip_reason", "pytest_terminal_summary")]) + "\n"

TINY = '''
import pytest

def test_runs():
    pass

@pytest.mark.parametrize("n", [1, 2])
def test_needs_a_browser(n):
    pytest.skip("Chromium not found: the report's pages are not rendered")

@pytest.mark.skipif(True, reason="node not found: ajv cannot run")
def test_needs_node():
    pass

@pytest.fixture
def browser():
    pytest.skip("Chromium not found: the report's pages are not rendered")

def test_skipped_in_its_fixture(browser):
    pass

def test_without_a_module():
    pytest.importorskip("a_module_that_is_not_installed")

@pytest.mark.xfail(reason="an expected failure is not a skip")
def test_xfail():
    assert False
'''


def test_each_skip_reason_is_counted_above_the_last_line(pytester):
    assert HOOK.count("\ndef ") == 2, HOOK
    pytester.makeconftest(HOOK)
    pytester.makepyfile(test_tiny=TINY)
    result = pytester.runpytest("-q", "-p", "no:cacheprovider")
    result.assert_outcomes(passed=1, skipped=5, xfailed=1)
    lines = [line for line in result.outlines if line.strip()]
    assert "5 skipped, by reason" in lines[-5], lines
    assert lines[-4:-1] == [
        "   3 × Chromium not found: the report's pages are not rendered",
        "   1 × node not found: ajv cannot run",
        "   1 × could not import 'a_module_that_is_not_installed': No module named "
        "'a_module_that_is_not_installed'",
    ], lines
    assert "skipped" in lines[-1] and "passed" in lines[-1], lines  # pytest's own last line
    assert "xfail" not in "\n".join(lines[-5:-1]), lines


def test_a_run_without_skips_adds_no_line(pytester):
    pytester.makeconftest(HOOK)
    pytester.makepyfile(test_tiny="def test_runs():\n    pass\n")
    result = pytester.runpytest("-q", "-p", "no:cacheprovider")
    result.assert_outcomes(passed=1)
    assert "by reason" not in result.stdout.str()


@pytest.mark.slow
def test_the_reasons_reach_the_end_of_a_run_on_workers(pytester):
    """`make test` runs on xdist workers: their skip reports cross to the controller, and
    the count is made there (one worker shows it)."""
    pytester.makeconftest(HOOK)
    pytester.makepyfile(test_tiny=TINY)
    result = pytester.runpytest("-q", "-p", "no:cacheprovider", "-n", "1")
    lines = [line for line in result.outlines if line.strip()]
    assert "5 skipped, by reason" in lines[-5], lines
    assert lines[-4] == "   3 × Chromium not found: the report's pages are not rendered", lines
