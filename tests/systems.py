"""Small test systems shared by several test files, as problem-file text."""

from __future__ import annotations

import re
from pathlib import Path

from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem


def pendulum(m: float, l: float, g: float | None = None, header: str = "") -> str:  # noqa: E741
    """A plane simple pendulum (bob on a massless rod from a fixed pivot), theta from the
    downward vertical; `g` None keeps the documented default. `header` goes first (id,
    source, title) for files loaded by path."""
    g_spec = "{}" if g is None else f"{{value: {g}}}"
    return f"""\
{header}parameters:
  m: {{value: {m}}}
  l: {{value: {l}}}
  g: {g_spec}
coordinates:
  theta: {{}}
particles:
  bob: {{mass: m, position: [l*sin(theta), -l*cos(theta)]}}
gravity: {{}}
"""


def load_analysis(tmp_path: Path, text: str, num: str) -> Analysis:
    """The analysis of `text` written as problem lim-<num> in a tree under tmp_path (its
    `id:` line rewritten to match the file's name)."""
    text = re.sub(r"^id: .*$", f"id: lim-{num}", text, count=1, flags=re.M)
    d = tmp_path / "problems" / "lim"
    d.mkdir(parents=True, exist_ok=True)
    (d / f"{num}.yaml").write_text(text)
    return Analysis(load_problem(d / f"{num}.yaml"))
