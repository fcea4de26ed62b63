"""Issue 33, interrupted and killed runs: Ctrl-C (SIGINT to the terminal's whole process
group, as a terminal sends it) during `check -j 2` or `report` ends with exit status 130 and
one line, never a KeyboardInterrupt traceback from the run, its workers or the fork server;
and a run killed any way leaves no `pymp-*` folder in the temporary directory. Real
processes in a session of their own, real signals, a temporary directory of the test's."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
from hostile import ROOT, limited

pytestmark = pytest.mark.slow


SWEEP = ("sweep", "lim-2031", "--quantity", "stability", "--about", "theta=pi", "--param",
         "omega=0.5:10:3000", "--param", "b=0.1:1:3000", "--no-store", "-j", "2")


@pytest.fixture
def short_tmp() -> Path:
    """A temporary directory of the test's own, with a short path: the fork server's
    socket lives in it, and a socket's path is at most 107 bytes (pytest's tmp_path under
    xdist is longer than that leaves room for)."""
    path = Path(tempfile.mkdtemp(prefix="mbt-", dir="/tmp"))
    yield path
    shutil.rmtree(path, ignore_errors=True)


@pytest.fixture
def tree(tmp_path) -> Path:
    """The whole book (enough work for two workers for half a minute)."""
    base = tmp_path / "tree"
    base.mkdir()
    for name in ("problems", "answers"):
        shutil.copytree(ROOT / name, base / name)
    shutil.copy(ROOT / "books.yaml", base / "books.yaml")
    return base


def _start(tree: Path, tmpdir: Path, *args: str, ignore_hangups: bool = False
           ) -> subprocess.Popen:
    """A run in a session of its own; with `ignore_hangups`, started as `nohup` starts it."""
    env = dict(os.environ, TMPDIR=str(tmpdir), PYTHONPATH=os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
    setup = limited(4.0)

    def preexec() -> None:
        setup()
        if ignore_hangups:
            signal.signal(signal.SIGHUP, signal.SIG_IGN)

    return subprocess.Popen([sys.executable, "-m", "mechbook", "--root", str(tree), *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, start_new_session=True, preexec_fn=preexec)


def _workers(run: subprocess.Popen, want: int, timeout: float = 90.0) -> list[int]:
    """The process ids of the run's `want` workers (the fork server's live children), once
    there are that many; fails after `timeout` seconds (a loaded machine takes a while to
    import the engine in the fork server)."""
    import psutil

    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            servers = [p for p in psutil.Process(run.pid).children()
                       if "multiprocessing.forkserver" in " ".join(p.cmdline())]
            live = [c.pid for s in servers for c in s.children()
                    if c.status() != psutil.STATUS_ZOMBIE]
        except psutil.NoSuchProcess:
            live = []
        if len(live) >= want:
            return live
        assert run.poll() is None, "the run ended before its workers started"
        time.sleep(0.1)
    raise AssertionError(f"the run did not start {want} workers in {timeout:g} s")


def _descendants(pid: int) -> set[int]:
    import psutil

    try:
        return {p.pid for p in psutil.Process(pid).children(recursive=True)}
    except psutil.NoSuchProcess:
        return set()


def _alive(pids: set[int]) -> set[int]:
    import psutil

    return {p for p in pids if psutil.pid_exists(p)
            and psutil.Process(p).status() != psutil.STATUS_ZOMBIE}


def _sweep_at(run: subprocess.Popen, share: float) -> str:
    """What the sweep wrote on stderr until `share` of its blocks were evaluated (its
    progress lines, `[7/14] blocks evaluated (2.1 s)`); fails if it ended first (a hang
    here is pytest-timeout's)."""
    import re

    seen = []
    for line in iter(run.stderr.readline, ""):
        seen.append(line)
        found = re.match(r"\[(\d+)/(\d+)\] blocks evaluated", line)
        if found and int(found[1]) >= share * int(found[2]):
            return "".join(seen)
    raise AssertionError("the sweep ended before it was interrupted: " + "".join(seen))


@pytest.mark.parametrize("command, delay", [(("check", "-j", "2", "--no-store"), 1.0),
                                            (("check", "-j", "2", "--no-store"), 8.0),
                                            (("report", "-j", "2", "--no-simulate"), 3.0),
                                            (("report", "-j", "2", "--no-simulate"), 10.0),
                                            (SWEEP, 1.5), (SWEEP, "workers"),
                                            (SWEEP, "half the blocks"),
                                            (SWEEP, "every block")])
def test_ctrl_c_ends_a_run_with_130_and_no_traceback(tree, short_tmp, command, delay):
    """At 1 s the fork server is still importing the engine; later the workers are busy
    ("workers": the moment both are at work, whatever the machine's load). A sweep's
    moments are read from its progress lines, not timed: "half the blocks" (blocks in
    flight: a worker killed while it sends its block leaves half a message in the pipe,
    where the run hung after its "interrupted" line, now and then, until kill_pool closed
    its end; tests/test_batch.py makes that moment by hand) and "every block"
    (the float64 result checked against 30 digits and the book's answer: on 8d0ecdc the
    accuracy sample sorted all nine million grid points again in one C call, 7 s quiet,
    over a minute on a loaded CI machine, where Ctrl-C waited)."""
    tmpdir = short_tmp
    proc = _start(tree, tmpdir, *command)
    seen = ""
    if delay == "workers":
        _workers(proc, 2)
    elif isinstance(delay, str):
        seen = _sweep_at(proc, 0.5 if delay == "half the blocks" else 1.0)
    else:
        time.sleep(delay)
    assert proc.poll() is None, "the run ended before it was interrupted: nothing tested"
    family = _descendants(proc.pid) | {proc.pid}
    os.killpg(proc.pid, signal.SIGINT)  # what Ctrl-C in a terminal does
    out, err = proc.communicate(timeout=60)
    err = seen + err
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert err.rstrip().endswith("interrupted"), err
    end = time.monotonic() + 10
    while _alive(family) and time.monotonic() < end:
        time.sleep(0.2)
    assert not _alive(family), "processes of the run outlived it"
    assert not list(tmpdir.glob("pymp-*"))


@pytest.mark.parametrize("how", ["SIGKILL", "SIGTERM", "group SIGTERM", "group SIGHUP"])
def test_a_killed_run_leaves_no_pymp_folder(tree, short_tmp, how):
    """On 0834a76 every kill left the fork server's socket folder behind (only a run that
    exits removes it); now the fork server, which ends with its run, removes it."""
    tmpdir = short_tmp
    proc = _start(tree, tmpdir, "check", "-j", "2", "--no-store")
    _workers(proc, 2)  # at work (6 s of sleep did the same, burning CPU on a quiet machine)
    assert list(tmpdir.glob("pymp-*")), "the run made no folder: nothing tested"
    sig = getattr(signal, how.split()[-1])
    if how.startswith("group"):
        os.killpg(proc.pid, sig)
    else:
        os.kill(proc.pid, sig)
    proc.communicate(timeout=60)
    assert proc.returncode == -sig, "the run was not ended by the signal"
    end = time.monotonic() + 10
    while list(tmpdir.glob("pymp-*")) and time.monotonic() < end:
        time.sleep(0.2)
    assert not list(tmpdir.glob("pymp-*"))


def _server_starting(run: subprocess.Popen, tmpdir: Path, timeout: float = 60.0) -> int:
    """The fork server's process id as soon as it exists (with its socket's folder made):
    it is then still starting its interpreter or importing the engine."""
    import psutil

    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            servers = [p for p in psutil.Process(run.pid).children()
                       if "multiprocessing.forkserver" in " ".join(p.cmdline())]
        except psutil.NoSuchProcess:
            servers = []
        if servers and list(tmpdir.glob("pymp-*")):
            return servers[0].pid
        assert run.poll() is None, "the run ended before its fork server started"
        time.sleep(0.01)
    raise AssertionError(f"no fork server in {timeout:g} s")


@pytest.mark.parametrize("how", ["SIGHUP", "SIGTERM"])
def test_a_group_signal_while_the_fork_server_starts_leaves_nothing(tree, short_tmp, how):
    """A hangup (or SIGTERM) to the whole group while the fork server starts: before
    issue 42's fix it died of it before forkstart could end it (or, importing the engine,
    before it knew its socket), and left its folder on a loaded machine, where the start
    takes longer than the 6 s test_a_killed_run_leaves_no_pymp_folder waited."""
    import psutil

    sig = getattr(signal, how)
    proc = _start(tree, short_tmp, "check", "-j", "2", "--no-store")
    server = _server_starting(proc, short_tmp)
    assert not psutil.Process(server).children(), "the server was up: nothing tested"
    family = _descendants(proc.pid)
    os.killpg(proc.pid, sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == -sig, err
    end = time.monotonic() + 10
    while (_alive(family) or list(short_tmp.glob("pymp-*"))) and time.monotonic() < end:
        time.sleep(0.2)
    assert not _alive(family), "processes of the run outlived it"
    assert not list(short_tmp.glob("pymp-*"))


@pytest.mark.parametrize("settle", [0.0, 2.0])
def test_a_run_hung_up_after_a_worker_died_ends_and_leaves_nothing(tree, short_tmp, settle):
    """Issue 42's flake: a worker dies (killed here), the run starts another in its place,
    and a hangup to the whole group arrives while the replacement is being forked
    (`settle` 0) or once it works (2 s): the run, its fork server and every worker end at
    once, and no pymp folder stays."""
    proc = _start(tree, short_tmp, "check", "-j", "2", "--no-store")
    first = _workers(proc, 2)
    os.kill(first[0], signal.SIGKILL)
    if settle:
        _workers(proc, 2)  # the replacement is there
        time.sleep(settle)
    family = _descendants(proc.pid)
    os.killpg(proc.pid, signal.SIGHUP)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGHUP, err
    end = time.monotonic() + 10
    while (_alive(family) or list(short_tmp.glob("pymp-*"))) and time.monotonic() < end:
        time.sleep(0.2)
    assert not _alive(family), "processes of the run outlived it"
    assert not list(short_tmp.glob("pymp-*"))


def test_a_run_that_ignores_hangups_keeps_its_workers_through_one(tree, short_tmp):
    """A run started under `nohup` ignores SIGHUP, and so do its fork server and workers:
    on 4c46ee6 the workers died of the hangup their run ignored (each problem in work an
    error, "the worker process died"), the run forked a new server and checked on, and
    test_a_killed_run_leaves_no_pymp_folder[group SIGHUP], run by a runner that ignores
    SIGHUP, waited a whole book's check for a run it thought killed."""
    # two problems that keep a worker each for well over the second below (~2 s each on
    # a quiet machine; the scattering ones this test used take a third of that now)
    ids = ("classic-coin-rolling-upright", "classic-pendulum-on-vibrating-pivot")
    proc = _start(tree, short_tmp, "check", *ids, "-j", "2", "--no-store",
                  ignore_hangups=True)
    workers = set(_workers(proc, 2))
    os.killpg(proc.pid, signal.SIGHUP)
    time.sleep(1.0)
    assert proc.poll() is None, "the run ended on a hangup it ignores"
    assert _alive(workers) == workers, "its workers died of a hangup the run ignores"
    out, err = proc.communicate(timeout=300)
    assert "died" not in err, err
    assert proc.returncode == 0, err
    assert not list(short_tmp.glob("pymp-*"))


def test_the_next_run_removes_what_a_run_killed_with_its_fork_server_left(tree, short_tmp):
    """SIGKILL to the whole group leaves no process to clean up: the folder stays until
    the next run, which removes it (it is marked with the dead run's process id)."""
    tmpdir = short_tmp
    proc = _start(tree, tmpdir, "check", "-j", "2", "--no-store")
    _workers(proc, 2)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.communicate(timeout=60)
    left = list(tmpdir.glob("pymp-*"))
    assert len(left) == 1
    foreign = tmpdir / "pymp-not-ours"  # another program's folder: never touched
    foreign.mkdir()
    again = _start(tree, tmpdir, "check", "lim-2031", "-j", "1", "--no-store",
                   "--no-crosscheck")
    _, err = again.communicate(timeout=300)
    assert again.returncode == 0, err
    assert not left[0].exists()
    assert foreign.exists()


def test_a_local_sweep_leaves_nothing_in_the_temporary_directory(tree, short_tmp):
    """A sweep's pool workers wrote their scratch copies of the tree (mechbook-tree-*) to
    the temporary directory and never removed them (they end by os._exit, and their atexit
    never runs); they now go into the run's own folder, which goes with the run."""
    proc = _start(tree, short_tmp, "sweep", "lim-2031", "--quantity", "stability",
                  "--about", "theta=pi", "--param", "omega=0.5:10:1000", "--param",
                  "b=0.1:1:1400", "--no-store", "-j", "2")  # blocks enough for a pool
    out, err = proc.communicate(timeout=600)
    assert proc.returncode == 0, err
    assert "2 local processes" in out + err, out + err
    time.sleep(1)
    assert list(short_tmp.iterdir()) == []
