"""`mechbook check` at scale: worker processes, time limits, the incremental store, resuming
after a kill, progress on a terminal, and one part's trouble kept in its part."""

from __future__ import annotations

import json
import os
import pty
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from mechbook.app.cli import main

pytestmark = pytest.mark.slow  # worker-spawning batch runs

ROOT = Path(__file__).resolve().parents[1]
MECHBOOK = [sys.executable, "-m", "mechbook"]  # this tree's mechbook, whatever is installed


def tree(tmp_path: Path, ids: list[str]) -> Path:
    """A mechbook tree holding copies of some real problems and their answer keys."""
    for pid in ids:
        book, num = pid.split("-", 1)
        for sub in ("problems", "answers"):
            (tmp_path / sub / book).mkdir(parents=True, exist_ok=True)
            shutil.copy(ROOT / sub / book / f"{num}.yaml", tmp_path / sub / book / f"{num}.yaml")
    return tmp_path


def stored(path: Path) -> list[str]:
    with h5py.File(path, "r") as f:
        return sorted(f["problems"].keys())


def test_parallel_run_matches_serial_run_and_keeps_the_given_order(tmp_path):
    ids = ["lim-2031", "lim-2028", "lim-2040"]
    base = tree(tmp_path, ids)
    runner = CliRunner()
    par = runner.invoke(main, ["--root", str(base), "check", *ids, "-j", "2", "--no-store",
                               "--format", "json"])
    ser = runner.invoke(main, ["--root", str(base), "check", *ids, "--serial", "--no-store",
                               "--format", "json"])
    assert par.exit_code == 0 and ser.exit_code == 0, par.output + ser.output

    def rows(out: str) -> list[tuple]:
        return [(pr["id"], p["part"], p["quantity"], p["status"])
                for pr in json.loads(out)["problems"] for p in pr["parts"]]

    assert rows(par.stdout) == rows(ser.stdout)
    firsts = [r[0] for r in rows(par.stdout)]
    assert sorted(set(firsts), key=firsts.index) == ids  # the output follows the given order


def test_a_problem_over_the_time_limit_is_an_error_naming_its_stage(tmp_path):
    """An equilibrium search SymPy cannot finish quickly (the plate of Lim 2057 on exact
    springs, asked for its equilibria by equations: simplifying its conditions and solving
    them take their full time limits, over 10 s) runs past an 8 s limit: the problem is
    reported as an error that names the part it was in, and the next problem still runs
    (a fast one, well inside the limit even on a loaded machine)."""
    base = tree(tmp_path, ["lim-2057", "lim-2031"])
    (base / "answers/lim/2057.yaml").write_text("""\
problem: lim-2057
source: a test
parts:
  - part: slow
    cite: a test
    quantity: equilibrium
    system: planar
    book: {where: ["X = 0"]}
""")
    result = CliRunner().invoke(main, ["--root", str(base), "check", "lim-2057", "lim-2031",
                                       "--timeout", "8", "-j", "1", "--no-store"])
    assert result.exit_code == 1
    line = next(ln for ln in result.output.splitlines() if ln.startswith("lim-2057"))
    assert "ERROR" in line and "time limit of 8 s" in line and "part slow (equilibrium)" in line
    assert sum(" pass " in ln for ln in result.output.splitlines()
               if ln.startswith("lim-2031")) == 6


def test_the_store_is_written_as_problems_finish_and_survives_sigkill(tmp_path):
    """A real `mechbook check` is killed with SIGKILL while it works on its last problem:
    the store holds every problem finished before, is readable, and a second run answers
    those from the store and computes only the rest."""
    ids = ["lim-2028", "lim-2029", "lim-2031", "lim-2043"]  # the last takes several seconds
    base = tree(tmp_path, ids)
    store = base / "results" / "mechbook.h5"
    proc = subprocess.Popen([*MECHBOOK, "--root", str(base), "check", *ids, "-j", "1"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, cwd=ROOT,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if store.exists() and len(stored(store)) == 3:
                break
            assert proc.poll() is None, "the run ended before it could be killed"
            time.sleep(0.05)
        else:
            pytest.fail("the first three problems were never stored")
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=10)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # the orphaned worker, if still running
        except ProcessLookupError:
            pass
    assert stored(store) == ids[:3]
    assert not list(store.parent.glob("*.tmp"))  # no half-written copy left to trip on
    again = CliRunner().invoke(main, ["--root", str(base), "check", *ids, "-j", "1"])
    assert again.exit_code == 0, again.output
    for pid in ids[:3]:
        assert f"{pid} " in again.output
    assert again.output.count("(cached") == 3
    assert stored(store) == ids


def test_progress_bar_on_a_terminal_and_plain_lines_otherwise(tmp_path):
    base = tree(tmp_path, ["lim-2028", "lim-2031"])
    plain = subprocess.run([*MECHBOOK, "--root", str(base), "check", "--no-store"],
                           capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert plain.returncode == 0, plain.stderr
    assert "[1/2] lim-2028" in plain.stderr or "[1/2] lim-2031" in plain.stderr
    leader, follower = pty.openpty()
    proc = subprocess.Popen([*MECHBOOK, "--root", str(base), "check", "--no-store"],
                            stdout=subprocess.DEVNULL, stderr=follower, close_fds=True, cwd=ROOT)
    os.close(follower)
    seen = b""
    while True:
        try:
            chunk = os.read(leader, 4096)
        except OSError:  # the terminal closed: the run is over
            break
        if not chunk:
            break
        seen += chunk
    proc.wait(timeout=300)
    os.close(leader)
    text = seen.decode(errors="replace")
    assert proc.returncode == 0
    assert "checking" in text and "2/2" in text and "[1/2]" not in text


CENTRAL = """\
id: lim-2099
source: a test
title: a particle in an attractive inverse-square field
parameters:
  m: {value: 1.3}
  k: {value: 2.0}
  r0: {value: 0.7}
coordinates:
  r: {}
  theta: {}
particles:
  p: {mass: m, position: [r*cos(theta), r*sin(theta)]}
potential: -k/r
"""

CENTRAL_KEY = """\
problem: lim-2099
source: a test
abbreviations:
  w: sqrt(k/(m*r0**3))
parts:
  - part: momentum
    cite: a test
    quantity: conserved
    book: m*r**2*thetadot
  - part: orbit
    cite: a test
    quantity: frequencies
    steady: {theta: w}
    about: {r: r0}
    book: [w]
"""


def test_a_system_without_equilibria_checks_its_parts(tmp_path):
    """No static equilibrium exists (the force pulls inward everywhere): nothing the parts
    did not ask for (an equilibrium search, a stored summary) may turn the problem into an
    error. The radial frequency about a circular orbit equals the orbital one (Kepler)."""
    for sub, text in (("problems", CENTRAL), ("answers", CENTRAL_KEY)):
        (tmp_path / sub / "lim").mkdir(parents=True)
        (tmp_path / sub / "lim" / "2099.yaml").write_text(text)
    result = CliRunner().invoke(main, ["--root", str(tmp_path), "check", "lim-2099"])
    assert result.exit_code == 0, result.output
    rows = [ln for ln in result.output.splitlines() if ln.startswith("lim-2099")]
    assert len(rows) == 2 and all(" pass " in ln for ln in rows), result.output
    store = tmp_path / "results" / "mechbook.h5"
    assert stored(store) == ["lim-2099"]


GC_STATE = """\
import sys
sys.path.insert(0, {tests!r})
from pathlib import Path
from mechbook.app.running.batch import Batch, BatchOptions
import json
import test_batch
print(json.dumps(Batch(Path("."), BatchOptions(jobs=2, timeout=600, memory_mb=0),
                       task=test_batch.gc_state).run(["a", "b"])))
"""


def gc_state(item, base, options, stage):
    """A task that reports its worker's garbage collector: frozen objects, thresholds."""
    import gc

    return (gc.get_freeze_count(), gc.get_threshold())


def test_workers_start_with_the_imported_engine_frozen_out_of_the_collector(tmp_path):
    """batch.settle: the fork server freezes what it imported (mechbook.app.running.frozen), so
    each worker starts with ~10⁵ objects the collector never walks again, and young
    collections rarer; the process that runs the batch keeps its own collector as it was."""
    import gc

    from mechbook.app.running.batch import GC_THRESHOLDS

    before = (gc.get_freeze_count(), gc.get_threshold())
    out = subprocess.run([sys.executable, "-c", GC_STATE.format(tests=str(ROOT / "tests"))],
                         capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert out.returncode == 0, out.stderr
    states = json.loads(out.stdout)
    assert len(states) == 2
    for frozen, thresholds in states:
        assert frozen > 50_000 and tuple(thresholds) == GC_THRESHOLDS
    assert (gc.get_freeze_count(), gc.get_threshold()) == before


def _echo(value):
    return value


def test_a_killed_pool_ends_its_manager_thread_mid_message():
    """A worker killed while it wrote a large result left a part of a message in the result
    pipe: the pool's manager thread read the header and waited for the rest for ever (this
    process holds the pipe's write end too, so no end of file came), and the interpreter's
    exit joined that thread: a sweep interrupted in its last block hung after its
    "interrupted" line (seen at Ctrl-C 3.5 s into tests/test_interrupts.py's sweep). The
    half message is written here by hand; kill_pool must end the thread all the same."""
    import struct
    from concurrent.futures import ProcessPoolExecutor

    from mechbook.app.running.batch import kill_pool

    pool = ProcessPoolExecutor(1)
    try:
        assert pool.submit(_echo, 7).result(timeout=60) == 7
        os.write(pool._result_queue._writer.fileno(), struct.pack("!i", 1000) + b"x" * 10)
        time.sleep(0.5)  # the manager thread is reading the rest of the message now
        manager = pool._executor_manager_thread
        assert manager.is_alive()
        kill_pool(pool)
        manager.join(timeout=20)
        assert not manager.is_alive(), "the pool's manager thread still waits on its pipe"
    finally:
        kill_pool(pool)
