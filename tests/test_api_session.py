"""docs/api.md is a notebook session: every ```python cell runs here, in order, in one
namespace (in a scratch directory, the repository's tree as $MECHBOOK_ROOT), so what the
page shows is what mechbook does (issue 34's "done when": load, equilibria by string key,
frequencies at other parameter values, simulate, to_xarray(), the equations as a callable
integrated by solve_ivp agreeing with `mechbook simulate`; issue 43: the function with
inputs per call, and the motion shown inline by animate() and plot())."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CELL = re.compile(r"```python\n(.*?)```", re.S)


def cells() -> list[str]:
    return CELL.findall((ROOT / "docs" / "api.md").read_text("utf-8"))


def test_the_page_has_the_session():
    text = "\n".join(cells())
    for needed in ('e["theta"]', "params={", "to_xarray()", "ode_function()", "solve_ivp(",
                   '"simulate"', "TypeError", "ode_function(inputs=", "fu(0.0, y, [omega])",
                   "run.animate()", "run.plot()"):
        assert needed in text, needed


@pytest.mark.slow  # a check, two simulations and a `mechbook simulate` process
def test_the_session_runs(tmp_path, monkeypatch, capsys):
    pytest.importorskip("xarray")
    pytest.importorskip("pandas")
    monkeypatch.setenv("MECHBOOK_ROOT", str(ROOT))
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for i, cell in enumerate(cells()):
        exec(compile(cell, f"docs/api.md, cell {i + 1}", "exec"), namespace)  # noqa: S102
    printed = capsys.readouterr().out
    assert "params=" in printed and "did you mean 'init'?" in printed
