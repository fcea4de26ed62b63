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


# a particle in a plane about a fixed centre, its potential and name to fill in (the
# scattering tests)
PLANE = """\
id: classic-{name}
source: test
title: a particle in a plane about a fixed centre
parameters:
  m: {{value: 1.3}}
  k: {{value: 0.7, positive: true}}
coordinates:
  r: {{positive: true}}
  theta: {{}}
kinetic: m*(rdot**2 + r**2*thetadot**2)/2
potential: {potential}
"""


# a pendulum whose pivot is driven up and down (Kapitza): the driven and periodic tests
KAPITZA = """\
id: lim-9404
source: test
title: pendulum on a pivot driven up and down (Kapitza)
parameters:
  m: {value: 1.0}
  l: {value: 1.0}
  a: {value: 0.1}
  omega: {value: 45.0}
  g: {value: 9.81}
coordinates:
  theta: {}
driven:
  y0: a*cos(omega*t)
particles:
  bob: {mass: m, position: [l*sin(theta), y0 - l*cos(theta)]}
gravity: {}
"""


# a harmonic oscillator, a double pendulum, and a bead on a hoop turning at a given rate
# (explicitly time-dependent); their `id:` lines are rewritten by load_analysis
DOUBLE = """\
id: lim-9302
source: test
title: double pendulum
parameters:
  m: {value: 1.0}
  l: {value: 1.0}
  g: {value: 1.0}
coordinates:
  a: {}
  b: {}
particles:
  p1: {mass: m, position: [l*sin(a), -l*cos(a)]}
  p2: {mass: m, position: [l*sin(a) + l*sin(b), -l*cos(a) - l*cos(b)]}
gravity: {}
"""
DRIVEN = """\
id: lim-9303
source: test
title: bead on a rotating hoop (explicitly time-dependent)
parameters:
  m: {value: 0.1}
  omega: {value: 6.0}
  b: {value: 0.5}
  g: {}
coordinates:
  theta: {}
particles:
  bead: {mass: m, position: [b*sin(theta)*cos(omega*t), b*sin(theta)*sin(omega*t), b*cos(theta)]}
gravity: {}
"""
OSCILLATOR = """\
id: lim-9103
source: test
title: oscillator
parameters:
  m: {value: 1.5}
  k: {value: 6.0}
coordinates:
  x: {}
kinetic: m*xdot**2/2
potential: k*x**2/2
"""


# a particle in a saddle potential turning at Omega: a linear system with periodic
# coefficients whose Floquet multipliers have a closed form (test_periodic, test_floquet_screen)
SADDLE = """\
id: lim-9406
source: test
title: particle in a rotating saddle
parameters:
  m: {value: 1.0}
  k: {value: 1.0}
  kappa: {value: 2.0}
  Omega: {value: 1.03}
coordinates:
  x: {}
  y: {}
kinetic: m*(xdot**2 + ydot**2)/2
potential: >-
  m*(k*(x*cos(Omega*t) + y*sin(Omega*t))**2
  - kappa*(-x*sin(Omega*t) + y*cos(Omega*t))**2)/2
"""
