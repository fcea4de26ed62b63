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


def _start(tree: Path, tmpdir: Path, *args: str) -> subprocess.Popen:
    env = dict(os.environ, TMPDIR=str(tmpdir), PYTHONPATH=os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
    return subprocess.Popen([sys.executable, "-m", "mechbook", "--root", str(tree), *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, start_new_session=True, preexec_fn=limited(4.0))


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


@pytest.mark.parametrize("command, delay", [(("check", "-j", "2", "--no-store"), 1.0),
                                            (("check", "-j", "2", "--no-store"), 8.0),
                                            (("report", "-j", "2", "--no-simulate"), 3.0),
                                            (("report", "-j", "2", "--no-simulate"), 10.0),
                                            (SWEEP, 3.5), (SWEEP, 4.5), (SWEEP, 8.0)])
def test_ctrl_c_ends_a_run_with_130_and_no_traceback(tree, short_tmp, command, delay):
    """At 1 s the fork server is still importing the engine; later the workers are busy."""
    tmpdir = short_tmp
    proc = _start(tree, tmpdir, *command)
    time.sleep(delay)
    family = _descendants(proc.pid) | {proc.pid}
    os.killpg(proc.pid, signal.SIGINT)  # what Ctrl-C in a terminal does
    out, err = proc.communicate(timeout=60)
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
    time.sleep(6)
    assert list(tmpdir.glob("pymp-*")), "the run made no folder: nothing tested"
    sig = getattr(signal, how.split()[-1])
    if how.startswith("group"):
        os.killpg(proc.pid, sig)
    else:
        os.kill(proc.pid, sig)
    proc.communicate(timeout=60)
    end = time.monotonic() + 10
    while list(tmpdir.glob("pymp-*")) and time.monotonic() < end:
        time.sleep(0.2)
    assert not list(tmpdir.glob("pymp-*"))


def test_the_next_run_removes_what_a_run_killed_with_its_fork_server_left(tree, short_tmp):
    """SIGKILL to the whole group leaves no process to clean up: the folder stays until
    the next run, which removes it (it is marked with the dead run's process id)."""
    tmpdir = short_tmp
    proc = _start(tree, tmpdir, "check", "-j", "2", "--no-store")
    time.sleep(6)
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
