"""The public Python API has numpydoc docstrings, as SciPy's and SymPy's do (issue 34 item
5): a Parameters section naming every parameter of the signature, Returns, and Examples
with a `>>>` line. numpydoc's own validator needs Sphinx; these few rules are what a
reader of `help()` relies on."""

from __future__ import annotations

import inspect
import re

import pytest

from mechbook.app.api import Problem, load
from mechbook.app.api.frames import results
from mechbook.app.api.linearization import Linearization
from mechbook.app.api.results import CheckResult, Simulation
from mechbook.app.api.system import SIMULATE_OPTIONS, SystemView

PUBLIC = [load, results, Problem.system, Problem.check, SystemView.frequencies,
          SystemView.modes, SystemView.simulate, SystemView.linearize,
          SystemView.ode_function, Simulation.to_xarray, Simulation.plot, Simulation.animate,
          Simulation.store,
          CheckResult.to_frame, Linearization.exponents, Linearization.frequencies,
          Linearization.stability]
# the shortcuts on a problem are its system's methods, with their docstrings
DELEGATED = ["frequencies", "modes", "simulate", "linearize", "ode_function"]


def sections(doc: str) -> dict[str, str]:
    """numpydoc's sections: a title line underlined with dashes, up to the next one."""
    doc = inspect.cleandoc(doc)
    parts = re.split(r"^(\w[\w ]*)\n-{3,}\n", doc, flags=re.M)
    return {parts[i]: parts[i + 1] for i in range(1, len(parts) - 1, 2)}


def documented(section: str) -> set[str]:
    """The names a Parameters section documents (`a, b : type` lines)."""
    names = set()
    for line in section.splitlines():
        m = re.match(r"^(\w+(?:, \w+)*)(?: :|$)", line)
        if m:
            names |= set(m.group(1).split(", "))
    return names


def problems(fn) -> list[str]:
    doc = inspect.getdoc(fn) or ""
    found = sections(doc)
    out = []
    params = [p for p in inspect.signature(fn).parameters.values()
              if p.name != "self" and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
    wanted = {p.name for p in params}
    if fn is SystemView.simulate:
        wanted |= set(SIMULATE_OPTIONS)  # its keyword options, each documented
    if wanted:
        missing = wanted - documented(found.get("Parameters", ""))
        if missing:
            out.append(f"Parameters does not document {sorted(missing)}")
    if "Returns" not in found:
        out.append("no Returns section")
    if ">>>" not in found.get("Examples", ""):
        out.append("no Examples section with an example")
    return out


@pytest.mark.parametrize("fn", PUBLIC, ids=lambda f: f.__qualname__)
def test_public_api_docstrings(fn):
    assert problems(fn) == []


@pytest.mark.parametrize("name", DELEGATED)
def test_the_problems_shortcuts_carry_the_systems_docstrings(name):
    assert getattr(Problem, name).__doc__ == getattr(SystemView, name).__doc__


def test_the_docstring_rules_can_fail():
    def bare(a, b=1):
        """Does something."""

    def partial(a, b=1):
        """Does something.

        Parameters
        ----------
        a : int
            A.

        Returns
        -------
        int
        """

    assert len(problems(bare)) == 3
    assert problems(partial) == ["Parameters does not document ['b']",
                                 "no Examples section with an example"]
