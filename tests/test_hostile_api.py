"""Issue 44, items 2 and 4: the Python API given hostile values. Each case runs in a child
Python whose address space is bounded to 2 GB and whose wall clock is bounded (a hang, a
7 TiB allocation or a traceback of another type is a failure); every refusal is mechbook's
own error (`MechbookError`) naming the argument."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest
from hostile import ROOT, limited, pendulum_tree

PROLOGUE = """
import json, sys
import mechbook
from mechbook.errors import MechbookError
p = mechbook.load("lim-2101", root_dir=sys.argv[1])
def report(fn):
    try:
        fn()
    except MechbookError as exc:
        print(json.dumps({"kind": "mechbook", "type": type(exc).__name__, "message": str(exc)}))
    except BaseException as exc:
        print(json.dumps({"kind": "other", "type": type(exc).__name__, "message": str(exc)}))
    else:
        print(json.dumps({"kind": "none"}))
"""


def _api(tree, call: str, timeout: float = 90) -> dict:
    code = PROLOGUE + f"report(lambda: {call})\n"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
    done = subprocess.run([sys.executable, "-c", code, str(tree)], capture_output=True,
                          text=True, timeout=timeout, env=env, preexec_fn=limited())
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    return pendulum_tree(tmp_path_factory.mktemp("api"))


CASES = [
    ("p.simulate(t_end=float('inf'))", "t_end"),
    ("p.simulate(t_end=float('nan'))", "t_end"),
    ("p.simulate(t_end=-1)", "t_end"),
    ("p.simulate(t_end='5')", "t_end"),
    ("p.simulate(t_end=10**400)", "t_end"),
    ("p.simulate(t_end=1, points=10**12)", "points"),
    ("p.simulate(t_end=1, points=1.5)", "points"),
    ("p.simulate(t_end=1, rtol=float('nan'))", "rtol"),
    ("p.simulate(t_end=1, step=0)", "step"),
    ("p.simulate(t_end=1, max_step=float('inf'))", "max_step"),
    ("p.simulate(t_end=1, atol=-1)", "atol"),
    ("p.simulate(t_end=1, params={'m': 10**400})", "params['m']"),
    ("p.simulate(t_end=1, params=[('m', 2)])", "params"),
    ("p.simulate(t_end=1, init={'theta': 10**400})", "init['theta']"),
    ("p.simulate(t_end=1, init=[1.0])", "init"),
    ("p.simulate(t_end=1, method=3)", "method"),
    ("p.frequencies(numeric=True, params={'m': 10**400})", "params['m']"),
    ("p.frequencies(numeric=True, params=[1, 2])", "params"),
    ("p.frequencies(about=[0])", "about"),
    ("p.frequencies(about={'theta': float('nan')})", "about['theta']"),
    ("p.modes(params={'m': float('inf')})", "params['m']"),
    ("p.ode_function(params=['m'])", "params"),
    ("p.ode_function().initial(init={'theta': 10**400})", "init['theta']"),
    ("p.system(3)", "name"),
    ("mechbook.load(42)", "problem_id"),
    ("mechbook.results(3.5)", "store"),
]


@pytest.mark.parametrize(("call", "argument"), CASES, ids=[c for c, _ in CASES])
def test_a_hostile_argument_is_mechbooks_error_naming_it(tree, call, argument):
    got = _api(tree, call)
    assert got["kind"] == "mechbook", got
    assert got["message"].startswith(f"{argument}:") or f"{argument}" in got["message"], got


def test_results_of_a_fifo_is_refused_without_blocking(tree, tmp_path):
    fifo = tmp_path / "store.h5"
    os.mkfifo(fifo)
    got = _api(tree, f"mechbook.results({str(fifo)!r})", timeout=60)
    assert got["kind"] == "mechbook", got
    assert "FIFO" in got["message"]


def test_good_arguments_still_work(tree):
    code = PROLOGUE + textwrap.dedent("""
        run = p.simulate(t_end=1, points=11, params={"m": 2}, init={"theta": 0.1})
        w = p.frequencies(numeric=True, params={"l": 0.25})
        print(json.dumps({"n": len(run.run.trajectory.t), "w": w}))
    """)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
    done = subprocess.run([sys.executable, "-c", code, str(tree)], capture_output=True,
                          text=True, timeout=120, env=env, preexec_fn=limited())
    assert done.returncode == 0, done.stderr[-2000:]
    got = json.loads(done.stdout.strip().splitlines()[-1])
    assert got["n"] == 11
    # the small-oscillation frequency sqrt(g/l): g = 9.81 (the default of `g: {}`), l = 0.25
    assert got["w"] == pytest.approx([(9.81 / 0.25) ** 0.5], rel=1e-9)
