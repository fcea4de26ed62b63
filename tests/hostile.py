"""Small trees of problems for the hostile-case tests (issue 21), and the help they share:
running the command line, a tmpfs where the system lets us mount one."""

from __future__ import annotations

import os
import shutil
import subprocess
import uuid
from contextlib import contextmanager
from pathlib import Path

from click.testing import CliRunner

from mechbook.app.cli import main

ROOT = Path(__file__).resolve().parents[1]

PENDULUM = """\
id: lim-{num}
source: a test problem
title: {title}
parameters:
  m: {{value: 1.5}}
  l: {{value: 0.5}}
  g: {{}}
coordinates:
  theta: {{}}
particles:
  bob:
    mass: {mass}
    position: [l*sin(theta), -l*cos(theta)]
gravity: {{}}
"""

KEY = """\
problem: lim-{num}
source: a test key
parts:
  - part: a
    cite: {cite}
    quantity: eom
    book: ["l*thetaddot + g*sin(theta) = 0"]
"""


def pendulum_tree(base: Path, nums=("2101",), title: str = "a test pendulum",
                  cite: str = "test", mass: str = "m") -> Path:
    """`base` holding problems/lim/<num>.yaml and answers/lim/<num>.yaml for each number
    (a pendulum whose single part checks in well under a second), and books.yaml."""
    (base / "problems" / "lim").mkdir(parents=True, exist_ok=True)
    (base / "answers" / "lim").mkdir(parents=True, exist_ok=True)
    shutil.copy(ROOT / "books.yaml", base / "books.yaml")
    for num in nums:
        (base / "problems" / "lim" / f"{num}.yaml").write_text(
            PENDULUM.format(num=num, title=title, mass=mass), encoding="utf-8")
        (base / "answers" / "lim" / f"{num}.yaml").write_text(
            KEY.format(num=num, cite=cite), encoding="utf-8")
    return base


def run(*args: str):
    """The command line in this process (stdout and stderr apart)."""
    return CliRunner().invoke(main, [str(a) for a in args])


def check(base: Path, *args: str):
    """`mechbook check` of the tree in this process (--serial, no cross-checks: fast)."""
    return run("--root", base, "check", "--serial", "--no-crosscheck", *args)


def can_mount() -> bool:
    return os.geteuid() == 0 and shutil.which("mount") is not None


@contextmanager
def tmpfs(where: Path, size: str = "1m", readonly: bool = False):
    """A small tmpfs mounted at `where` (read-only with `readonly`), unmounted after; the
    caller skips the test where mounting is not permitted (mount fails)."""
    where.mkdir(parents=True, exist_ok=True)
    name = f"mechbook-{uuid.uuid4().hex[:6]}"
    subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", name, str(where)],
                   check=True, capture_output=True)
    try:
        if readonly:
            subprocess.run(["mount", "-o", "remount,ro", str(where)], check=True,
                           capture_output=True)
        yield where
    finally:
        subprocess.run(["umount", "-l", str(where)], capture_output=True)


MEMORY_GB = 2.0  # the address space a command of the tests may take (issue 33)


def limited(memory_gb: float = MEMORY_GB):
    """A preexec_fn: the child's address space bounded (a read without bound then fails in
    the child, never fills the machine) and SIGINT, SIGHUP and SIGTERM at their defaults (a
    shell that runs the tests in the background ignores SIGINT for its children, `nohup` or
    a CI runner SIGHUP, and a child inherits what is ignored: a test that ends a run with
    SIGHUP would find it running on)."""
    import resource
    import signal

    def setup() -> None:
        limit = int(memory_gb * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        for signum in (signal.SIGINT, signal.SIGHUP, signal.SIGTERM):
            signal.signal(signum, signal.SIG_DFL)

    return setup


def mechbook(*args, cwd: Path | None = None, timeout: float = 300, env: dict | None = None,
             memory_gb: float = MEMORY_GB, stdin=subprocess.DEVNULL):
    """A real `mechbook` process (this checkout's), its memory bounded: CompletedProcess
    (text); subprocess.TimeoutExpired if it runs past `timeout` (a hang)."""
    import sys

    full = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]), **(env or {}))
    return subprocess.run([sys.executable, "-m", "mechbook", *[str(a) for a in args]],
                          cwd=cwd, capture_output=True, text=True, timeout=timeout, env=full,
                          preexec_fn=limited(memory_gb), stdin=stdin)
