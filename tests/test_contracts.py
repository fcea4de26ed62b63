"""Types say what things are (issue: contracts by imitation): a system's contract
(model/protocol.py) kept by System and by Routh's reduced system, statuses as an enum that
writes as its plain value, one guard for the cross-checks, and crosscheck/ in small pieces."""

from __future__ import annotations

import ast
import json
from pathlib import Path

import pytest
import sympy as sp
from systems import load_analysis

from mechbook.core.timeout import Timeout
from mechbook.crosscheck.guard import guarded
from mechbook.errors import MechbookError, UnsupportedError
from mechbook.records import CROSSCHECK_STATUSES, STATUSES, CrossCheck, Outcome, Status

ROOT = Path(__file__).resolve().parents[1]

CENTRAL = """\
id: lim-9301
source: test
title: a particle in a plane, a central spring
parameters:
  m: {value: 1.0}
  k: {value: 2.0}
coordinates:
  r: {positive: true}
  phi: {}
kinetic: m/2*(rdot**2 + r**2*phidot**2)
potential: k/2*r**2
"""


# ---- the system contract ---------------------------------------------------------------------
def test_a_system_and_a_reduced_system_keep_the_same_contract(tmp_path):
    from mechbook.engine.steady import reduced_at
    from mechbook.model.protocol import SystemLike

    an = load_analysis(tmp_path, CENTRAL, "9301")
    sys = an.system()
    phi = sys.q[sys.coord_names.index("phi")]
    P = sp.Symbol("P", positive=True)
    red = reduced_at(sys, {phi: P})
    assert SystemLike in type(sys).__mro__ and SystemLike in type(red).__mro__  # explicitly
    assert (sys.reduced, red.reduced) == (False, True)
    assert sys.full is sys and red.full is sys
    assert sys.held_momenta == {} and sys.held == {}
    assert red.held_momenta == {phi: P} and list(red.held.values()) == [P]
    assert red.name == sys.name and red.domains == {}
    assert [str(q) for q in red.q] == ["r"]
    # members the Protocol declares are there, with values, on both
    declared = [n for n in SystemLike.__annotations__] + ["reduced", "full", "held_momenta",
                                                           "held", "dt", "numeric_values"]
    for obj in (sys, red):
        assert all(hasattr(obj, n) for n in declared), [n for n in declared
                                                        if not hasattr(obj, n)]


KIND_ATTRIBUTES = {"base", "held", "momenta", "domains", "reduced", "full", "held_momenta"}


@pytest.mark.parametrize("stage", ["engine", "verify", "crosscheck", "numerics"])
def test_no_system_kind_is_told_by_hasattr_or_getattr(stage):
    """`hasattr(sys, "base")`, `getattr(sys, "held", {})`: gone; the contract says it."""
    found = []
    for path in sorted((ROOT / "mechbook" / stage).rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                    and node.func.id in ("hasattr", "getattr") and len(node.args) >= 2
                    and isinstance(node.args[1], ast.Constant)
                    and node.args[1].value in KIND_ATTRIBUTES):
                found.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert not found, found


# ---- statuses --------------------------------------------------------------------------------
def test_statuses_are_the_schemas():
    schema = json.loads((ROOT / "mechbook" / "app" / "schemas" / "check-result.json")
                        .read_text(encoding="utf-8"))
    assert list(STATUSES) == schema["$defs"]["status"]["enum"]
    cross = schema["$defs"]["crosscheck"]["properties"]["status"]["enum"]
    assert list(CROSSCHECK_STATUSES) == cross
    assert {s.value for s in Status} == set(STATUSES) | set(CROSSCHECK_STATUSES)


def test_a_status_writes_as_its_plain_value():
    x = CrossCheck("modes:main", "frequencies", "main", Status.NA, detail="d",
                   modes=[{"status": Status.PASS}])
    assert json.dumps(x.as_dict()) == json.dumps({**x.as_dict(), "status": "n.a.",
                                                  "modes": [{"status": "pass"}]})
    assert f"{x.status}" == str(x.status) == "n.a." and x.status == "n.a."
    assert type(str(Status.PASS)) is str  # what HDF5 is given
    assert x.cell() == "n.a."
    assert CrossCheck("n", "newton", "main", Status.PASS, error=1e-12).cell() == "pass 1e-12"


def test_records_read_back_hold_statuses_and_refuse_unknown_ones():
    o = Outcome("p", "a", "eom", "cite", "erratum")
    assert o.status is Status.ERRATUM
    x = CrossCheck.from_dict({"name": "n", "kind": "k", "system": "s", "status": "n.a."})
    assert x.status is Status.NA and not x.failed
    assert CrossCheck("n", "k", "s", "error").failed
    with pytest.raises(ValueError):
        Outcome("p", "a", "eom", "cite", "passed")


# ---- the one guard ---------------------------------------------------------------------------
def test_the_guard_decides_na_error_and_result():
    ok = CrossCheck("x", "k", "s")
    with guarded(ok):
        ok.status, ok.detail = Status.PASS, "fine"
    assert (ok.status, ok.detail) == (Status.PASS, "fine") and ok.seconds >= 0
    na = CrossCheck("x", "k", "s")
    with guarded(na, reason="no linear system: "):
        raise UnsupportedError("time-dependent coefficients")
    assert (na.status, na.detail) == (Status.NA, "no linear system: time-dependent "
                                                 "coefficients")
    own = CrossCheck("x", "k", "s")
    with guarded(own):
        raise MechbookError("integration failed: step size too small")
    assert (own.status, own.detail) == (Status.ERROR, "integration failed: step size too small")
    fault = CrossCheck("x", "k", "s")
    with guarded(fault):
        raise KeyError("q")
    assert (fault.status, fault.detail) == (Status.ERROR, "KeyError: 'q'")
    strict = CrossCheck("x", "k", "s")
    with guarded(strict, unsupported=Status.ERROR):
        raise UnsupportedError("a shape without a closed form")
    assert (strict.status, strict.detail) == (Status.ERROR,
                                              "unsupported: a shape without a closed form")


def test_the_guard_lets_a_time_limit_through():
    x = CrossCheck("x", "k", "s")
    with pytest.raises(Timeout), guarded(x):
        raise Timeout("gave up")


def test_every_cross_check_uses_the_one_guard():
    """No cross-check module catches exceptions itself to decide its outcome: `except` in
    crosscheck/ only where a step's own fallback is meant (not around a whole check)."""
    allowed = {  # module: the exception types its helpers catch as part of their own work
        "points.py": {"UnsupportedError", "TypeError", "ValueError"},
        "newton.py": set(), "frequencies.py": set(), "response.py": set(),
        "simulated_motion.py": set(), "inertia.py": set(), "problem.py": set(),
        "conserved.py": {"MechbookError", "UnsupportedError"},
    }
    for name, ok in allowed.items():
        tree = ast.parse((ROOT / "mechbook" / "crosscheck" / name).read_text(encoding="utf-8"))
        caught = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ExceptHandler):
                types = node.type.elts if isinstance(node.type, ast.Tuple) else [node.type]
                caught |= {getattr(t, "id", getattr(t, "attr", "?")) for t in types}
        assert caught <= ok, (name, caught - ok)
