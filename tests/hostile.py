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
