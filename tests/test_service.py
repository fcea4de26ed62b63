"""The check service below the command line (mechbook.app.running.service): ids resolved once, the
store's valid outcomes reused, the runs back in the order of the ids; the Python API checks
the model it loaded; options that would be dropped silently are refused."""

from __future__ import annotations

import pytest
from hostile import ROOT, pendulum_tree, run

import mechbook
import mechbook.app.running.simrun as simrun
import mechbook.app.sweep as sweep
from mechbook.app.running.batch import BatchOptions
from mechbook.app.running.run import RunOptions
from mechbook.app.running.service import CheckOptions, CheckService, resolve_ids
from mechbook.errors import MechbookError


def _options(store, **kw) -> CheckOptions:
    batch = BatchOptions(serial=True, run=RunOptions(crosscheck=False))
    return CheckOptions(store, batch=batch, **kw)


def test_named_ids_are_checked_and_a_bad_file_of_the_tree_is_an_error_run(tmp_path):
    base = pendulum_tree(tmp_path, nums=("2101", "2102"))
    with pytest.raises(MechbookError, match="bad problem id"):
        resolve_ids(["lim-../x"], base)
    with pytest.raises(MechbookError, match=r"no problem lim-2103 \(no file"):
        resolve_ids(["lim-2103"], base)
    (base / "problems" / "lim" / "21_04.yaml").write_text("id: x\n", encoding="utf-8")
    ids, refused = resolve_ids([], base)
    assert ids == ["lim-2101", "lim-2102", "lim-21_04"] and set(refused) == {"lim-21_04"}
    assert "does not look like a problem number" in refused["lim-21_04"].error
    assert resolve_ids([], tmp_path / "empty")[0] == []
    with pytest.raises(MechbookError, match="no problems under"):
        CheckService(tmp_path / "empty", _options("m.h5")).resolve()


def test_a_check_writes_the_store_and_the_next_reads_it_back(tmp_path):
    base = pendulum_tree(tmp_path, nums=("2101", "2102"))
    seen = []
    service = CheckService(base, _options("results/m.h5"))
    first = service.run(service.resolve(["lim-2102", "lim-2101"]), seen.append)
    assert [r.pid for r in first.runs] == ["lim-2102", "lim-2101"]
    assert first.store == base / "results" / "m.h5" and first.stored and first.written == 2
    assert sorted(r.pid for r in seen) == ["lim-2101", "lim-2102"] and first.cached == []
    again = CheckService(base, _options("results/m.h5"))
    second = again.run(again.resolve([]))
    assert second.cached == ["lim-2101", "lim-2102"] and second.written == 0
    assert [(r.pid, [o.status for o in r.outcomes]) for r in second.runs] == \
        [(r.pid, [o.status for o in r.outcomes]) for r in reversed(first.runs)]
    fresh = CheckService(base, _options("results/m.h5", write=False))
    third = fresh.run(fresh.resolve([]))
    assert third.cached == [] and not third.stored and third.store_lines() == []


def test_the_api_checks_the_model_it_loaded(tmp_path):
    """Problem.check used to load the problem again by id: a file changed (here: broken)
    since `load` was checked instead of the problem in hand."""
    base = pendulum_tree(tmp_path)
    problem = mechbook.load("lim-2101", base)
    (base / "problems" / "lim" / "2101.yaml").write_text("id: [\n", encoding="utf-8")
    result = problem.check(crosscheck=False)
    assert result.error is None and result.ok, result


@pytest.mark.parametrize("args, says", [
    (["check", "lim-2031", "--serial", "-j", "2"], "--jobs would have no effect"),
    (["check", "lim-2031", "--serial", "--timeout", "5", "--memory", "10"],
     "--timeout, --memory would have no effect"),
    (["simulate", "lim-2031", "--method", "RK4", "--rtol", "1e-6"],
     "--rtol does not apply to the fixed method RK4; it takes --step"),
    (["simulate", "lim-2031", "--method", "leapfrog", "--points", "50"], "--points"),
    (["simulate", "lim-2031", "--step", "0.1"], "--step does not apply to the scipy method "
                                                "DOP853 (the default)"),
    (["simulate", "lim-2031", "--method", "taylor", "--atol", "1e-9"], "it takes --rtol"),
    (["simulate", "lim-2031", "--serial", "--timeout", "5"], "--timeout would have no"),
    (["sweep", "lim-2031", "--param", "omega=1:2:3", "--timeout", "5"],
     "--timeout limits a block on a cluster worker"),
    (["sweep", "lim-2031", "--param", "omega=1:2:3", "--scheduler", "tcp://nowhere:1",
      "-j", "2"], "-j counts local processes"),
])
def test_an_option_that_would_be_dropped_is_refused(monkeypatch, args, says):
    monkeypatch.delenv("MECHBOOK_SCHEDULER", raising=False)
    monkeypatch.setattr(simrun, "run_simulation", _must_not_run)
    monkeypatch.setattr(sweep, "run_sweep", _must_not_run)
    result = run("--root", ROOT, *args, "--no-store")
    assert result.exit_code == 4, result.output
    assert says in " ".join(result.output.split()), result.output


def _must_not_run(*args, **kwargs):
    raise AssertionError("the run started although an option was refused")


def test_option_choices_are_read_from_their_owners():
    from mechbook.app.cli import main
    from mechbook.core.compile import BACKENDS
    from mechbook.numerics.integrators import FIXED_METHODS, METHODS, SCIPY_METHODS
    from mechbook.numerics.methods import ALIASES, CHOICES

    def choices(command: str, option: str) -> tuple:
        param = next(p for p in main.commands[command].params if option in p.opts)
        return tuple(param.type.choices)

    assert choices("simulate", "--method") == CHOICES
    assert set(CHOICES) | set(ALIASES) == set(METHODS) == \
        set(SCIPY_METHODS) | set(FIXED_METHODS) | {"taylor"}
    assert choices("simulate", "--backend") == choices("sweep", "--backend") == BACKENDS
    assert choices("sweep", "--quantity") == sweep.QUANTITIES
