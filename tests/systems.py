"""Small test systems shared by several test files, as problem-file text."""

from __future__ import annotations


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
