"""A sample of the fuzz run (`make fuzz` runs 10,000 cases, tests/fuzz.py) and property
tests of the safe parser with Hypothesis: every input ends in success or a MechbookError —
never a traceback, never a hang past the time limit, never memory past the bound."""

from __future__ import annotations

import time

import pytest
import sympy as sp
from fuzz import BAD, KINDS, fuzz, generate, seeds, summary
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mechbook.errors import ExpressionError
from mechbook.model.expr import parse

SAMPLE = 120  # cases in `make test` (all kinds); `make fuzz` runs 10,000


@pytest.mark.slow
def test_a_sample_of_the_fuzz_run_has_no_traceback_hang_or_bomb(tmp_path):
    results = fuzz(SAMPLE, seed=20260101, jobs=2, keep=tmp_path / "kept", chunk=SAMPLE)
    assert len(results) == SAMPLE
    bad = [r for r in results if r.status in BAD]
    assert not bad, summary(results) + "\n" + "\n".join(
        f"case {r.index} ({r.kind}): {r.status}: {r.message[:300]}" for r in bad)
    statuses = {r.status for r in results}
    assert {"ok", "refused"} <= statuses  # the generator makes good and bad files


@pytest.mark.slow
def test_every_kind_is_generated_and_deterministic():
    pool = seeds()
    cases = [generate(i, 5, pool, list(KINDS)) for i in range(400)]
    assert {c.kind for c in cases} == set(KINDS)
    again = generate(17, 5, pool, list(KINDS))
    assert again.files == cases[17].files and again.kind == cases[17].kind


@pytest.mark.slow
def test_the_harness_reports_a_hang_and_a_crash(tmp_path, monkeypatch):
    """The harness can fail: a case that runs past the limit on the real batch machinery is
    a hang, one that raises a plain exception is a crash, one that raises a MechbookError
    is refused."""
    import fuzz as harness

    import mechbook.app.authoring.validate as validate
    from mechbook.app.running.batch import Batch, BatchOptions
    from mechbook.errors import SpecError

    batch = Batch(tmp_path, BatchOptions(jobs=1, timeout=2, memory_mb=0),
                  task=_sleep, failed=harness.stopped)
    ((status, message, _),) = batch.run(["validate:x"])
    assert status == "hang" and "time limit" in message

    monkeypatch.setattr(validate, "validate_file", lambda path: 1 / 0)
    status, message, _ = harness.run_one("validate:x", tmp_path, None, lambda s: None)
    assert status == "crash" and "ZeroDivisionError" in message and "Traceback" in message

    def refuse(path):
        raise SpecError("bad", path, 3)

    monkeypatch.setattr(validate, "validate_file", refuse)
    assert harness.run_one("validate:x", tmp_path, None, lambda s: None)[:2] == \
        ("refused", "x:3: bad")


def _sleep(item, base, options, stage):
    time.sleep(30)


# ---- the parser, property-tested -----------------------------------------------------------

NAMES = {"x": sp.Symbol("x", real=True), "m": sp.Symbol("m", positive=True),
         "k": sp.Symbol("k", positive=True)}
ATOMS = st.sampled_from(["x", "m", "k", "0", "1", "2", "-1", "0.5", "1e30", "1e-30", "pi",
                         "10**30", "t", "E", "I", "oo", "__x", "x.y"])
FUNCS = st.sampled_from(["sin", "cos", "tan", "cot", "sec", "csc", "asin", "acos", "atan",
                         "sinh", "cosh", "tanh", "asinh", "acosh", "atanh", "exp", "log",
                         "sqrt", "Abs", "sign", "cbrt", "eval", "open"])
OPS = st.sampled_from(["+", "-", "*", "/", "**", "<", "==", "and", "//", "%", "@", ","])


def _expr(depth: int):
    if depth == 0:
        return ATOMS
    sub = _expr(depth - 1)
    return st.one_of(
        ATOMS,
        st.tuples(sub, OPS, sub).map(lambda t: f"({t[0]}){t[1]}({t[2]})"),
        st.tuples(FUNCS, sub).map(lambda t: f"{t[0]}({t[1]})"),
        st.tuples(sub, sub).map(lambda t: f"atan2({t[0]}, {t[1]})"),
        sub.map(lambda s: f"-({s})"),
    )


def _check(text: str, relations: bool) -> None:
    start = time.perf_counter()
    try:
        out = parse(text, NAMES, relations)
    except ExpressionError:
        pass
    else:
        assert isinstance(out, sp.Basic)
        assert not out.has(sp.zoo, sp.nan, sp.oo, -sp.oo, sp.I), (text, out)
    assert time.perf_counter() - start < 5.0, text


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_expr(4), st.booleans())
def test_parser_on_generated_expressions(text, relations):
    _check(text, relations)


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet=st.sampled_from(list("xmk0129.e()+-*/<>=,_ abcsinqrtlogp[]{}'\"\\")),
               max_size=60), st.booleans())
def test_parser_on_random_text(text, relations):
    _check(text, relations)


@pytest.mark.parametrize("text", ["(x)**((10**30)**(10**30))", "exp(exp(exp(exp(100))))",
                                  "sqrt(-m)", "cbrt(-1)*x", "(x<1)**2", "-" * 500 + "x"])
def test_parser_examples_hypothesis_found_or_was_given(text):
    _check(text, True)


# ---- the kinds of issue 21 can fail ------------------------------------------------------------
def test_the_store_kind_reports_silent_data_loss(tmp_path, monkeypatch):
    """A side file that silently keeps nothing, behind a store that cannot be written:
    the case is 'lost', not 'refused'."""
    import fuzz_faults as faults

    import mechbook.app.store.unsaved as unsaved

    spec = {"records": 2, "strings": ["x"], "file": "none", "inject": "readonly", "seed": 3}
    assert faults.run_store(tmp_path / "a", spec)[0] == "refused"
    monkeypatch.setattr(unsaved.SideFile, "keep", lambda self, kind, payload: None)
    status, message = faults.run_store(tmp_path / "b", spec)
    assert status == "lost" and "not stored and not kept" in message


@pytest.mark.slow
def test_the_symlink_kind_reports_a_leak(tmp_path, monkeypatch):
    """Problem files followed wherever their links go: the marker outside is read."""
    import fuzz_faults as faults
    from fuzz import _pid, write_case

    import mechbook.model.catalog as catalog

    case = generate(0, 1, seeds(), ["symlinks"])
    case.spec = {"link": "outside"}
    where = write_case(case, tmp_path / "case")
    pid = _pid(case.target)
    assert faults.run_symlink(where, pid)[0] == "refused"
    monkeypatch.setattr(catalog, "_stays_inside", lambda path, top: path)
    assert faults.run_symlink(where, pid)[0] == "leak"


def test_the_options_kind_reports_an_unbounded_option(monkeypatch):
    """An option that takes any float (as `--timeout` did) accepts NaN: 'unsafe'."""
    import click
    import fuzz_faults as faults

    from mechbook.app.cli import main

    spec = {"command": "check", "option": "--timeout", "value": "nan"}
    assert faults.run_options(spec)[0] == "refused"
    param = next(p for p in main.commands["check"].params if "--timeout" in p.opts)
    monkeypatch.setattr(param, "type", click.FLOAT)
    assert faults.run_options(spec)[0] == "unsafe"


# ---- the kinds of issue 33 can fail ------------------------------------------------------------
def test_the_restore_kind_reports_a_write_outside_the_tree(tmp_path, monkeypatch):
    """A restore that takes a side file's store on trust (as 0834a76 did) writes where the
    file says: 'outside'."""
    import fuzz_surfaces as surfaces

    from mechbook.app.store import restore

    spec = {"lines": 1, "seed": 7, "special": None, "store": "absolute-outside",
            "mutate": "none"}
    (tmp_path / "case-1").mkdir()
    assert surfaces.run_restore(tmp_path / "case-1", spec)[0] == "refused"
    monkeypatch.setattr(restore, "_target", lambda named, store, base: named)
    (tmp_path / "case-2").mkdir()
    status, message = surfaces.run_restore(tmp_path / "case-2", spec)
    assert status == "outside" and "absolute.h5" in message


def test_the_init_kind_reports_a_write_through_a_link(tmp_path, monkeypatch):
    """Files written by following what is there (0834a76's init): 'outside'."""
    import fuzz_surfaces as surfaces

    from mechbook.app.authoring import init

    spec = {"plant": "linked-folder", "seed": 1, "name": "tree"}
    (tmp_path / "case-1").mkdir()
    assert surfaces.run_init(tmp_path / "case-1", spec)[0] == "refused"

    def naive(target):
        for dest in init.FILES.values():
            path = target / dest
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text("x")
        return []

    monkeypatch.setattr(init, "init_tree", naive)
    (tmp_path / "case-2").mkdir()
    assert surfaces.run_init(tmp_path / "case-2", spec)[0] == "outside"


def test_the_hdf5_kind_reports_a_leak_through_an_external_link(tmp_path, monkeypatch):
    """A store whose links are followed (as on 0834a76) reads a file outside it: 'leak'."""
    import fuzz_surfaces as surfaces

    from mechbook.app.store import bounds as store_bounds
    from mechbook.app.store import reader as store_read

    spec = {"fault": "external", "records": 1, "seed": 4}
    (tmp_path / "case-1").mkdir()
    assert surfaces.run_hdf5(tmp_path / "case-1", spec)[0] == "ok"  # moved aside, rebuilt
    for module in (store_bounds, store_read):
        monkeypatch.setattr(module, "member", lambda group, name: group[name])
    (tmp_path / "case-2").mkdir()
    assert surfaces.run_hdf5(tmp_path / "case-2", spec)[0] == "leak"


# ---- the kinds of issue 44 can fail ------------------------------------------------------------
def test_the_schema_kind_reports_a_write_through_a_link(tmp_path, monkeypatch):
    """9a86c12's `schema --write` (write_text through whatever is there): 'outside'."""
    import fuzz_surfaces44 as surfaces44

    from mechbook.app.authoring import editor

    spec = {"plant": "outside-link", "name": "problem.json", "dir": "schemas"}
    (tmp_path / "case-1").mkdir()
    assert surfaces44.run_schema(tmp_path / "case-1", spec)[0] == "refused"

    def naive(directory):
        directory.mkdir(parents=True, exist_ok=True)
        for name in editor.NAMES:
            (directory / f"{name}.json").write_text(editor.text(name), encoding="utf-8")
        return []

    monkeypatch.setattr(editor, "write_schemas", naive)
    (tmp_path / "case-2").mkdir()
    assert surfaces44.run_schema(tmp_path / "case-2", spec)[0] == "outside"


def test_the_api_kind_reports_a_raw_exception(tmp_path, monkeypatch):
    """An argument that reaches the engine unchecked (9a86c12's `params=[...]`): 'crash'."""
    import fuzz_surfaces44 as surfaces44

    from mechbook.app.api import args as api_args

    spec = {"call": "p.frequencies(numeric=True, params={v})", "value": "[('m', 2)]"}
    (tmp_path / "case-1").mkdir()
    assert surfaces44.run_api(tmp_path / "case-1", spec)[0] == "refused"
    monkeypatch.setattr(api_args, "mapping", lambda name, value: value)
    (tmp_path / "case-2").mkdir()
    assert surfaces44.run_api(tmp_path / "case-2", spec)[0] == "crash"


def test_the_velocity_kind_refuses_what_is_not_linear(tmp_path):
    import fuzz_surfaces44 as surfaces44

    (tmp_path / "case-1").mkdir()
    status, message = surfaces44.run_velocity(tmp_path / "case-1",
                                              {"kind": "constraint", "expr": "1*(Abs(xdot))"})
    assert status == "refused" and "not linear in the velocities" in message, message
    (tmp_path / "case-2").mkdir()
    status, message = surfaces44.run_velocity(
        tmp_path / "case-2", {"kind": "constraint",
                              "expr": "-1e-12*(xdot*sin(theta)) + 1e-12*(ydot*cos(theta))"})
    assert status == "ok", message
