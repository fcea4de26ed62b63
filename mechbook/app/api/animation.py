"""A simulation's motion for a notebook: `Simulation.animate()` and the picture of `plot()`.

Jupyter shows an object by its rich representations (`_repr_html_`, `_repr_png_`): the
animation is the report's own (mechbook.app.report.animation's frames, drawn on a canvas by
the report's script, offline, no library), so a notebook and the report show the same
motion; the plot is the same figure `plot(path)` writes, as PNG bytes, nothing written.
"""

from __future__ import annotations

import html
import json
from functools import cache
from importlib import resources


@cache
def _script() -> str:
    return resources.files("mechbook.app.report").joinpath("assets", "animate.js") \
        .read_text("utf-8")


class Animation:
    """The bodies moving as simulated (the plane of the two axes they move along most),
    with springs, rigid links, pivots and each rigid body's outline.

    Attributes
    ----------
    motion : dict
        The frames: times ``t``, each body's ``path``, ``springs``, ``links``, ``pivots``,
        ``outlines``, the ``axes`` drawn and the ``box`` they fill.

    Examples
    --------
    >>> run = mechbook.load("lim-2031").simulate(t_end=5)      # doctest: +SKIP
    >>> run.animate()               # a notebook shows it; .html() is the markup  # doctest: +SKIP
    """

    def __init__(self, motion: dict, title: str):
        self.motion, self.title = motion, title

    @property
    def frames(self) -> int:
        """How many frames the animation has."""
        return len(self.motion["t"])

    def html(self) -> str:
        """The animation as a self-contained HTML fragment (canvas, frames, script)."""
        data = json.dumps(self.motion).replace("</", "<\\/")
        return (f'<figure class="animation"><canvas width="440" height="300" '
                f'aria-label="{html.escape(self.title)}: the bodies moving as simulated">'
                '</canvas><div><button type="button">pause</button> '
                '<span class="time"></span></div>'
                f'<script type="application/json" class="motion">{data}</script>'
                f"<figcaption>{html.escape(self.title)}</figcaption></figure>"
                f"<script>{_script()}</script>")

    def _repr_html_(self) -> str:
        return self.html()

    def __repr__(self) -> str:
        return f"<animation of {self.title}: {self.frames} frames>"


class Picture:
    """A figure for a notebook's inline display: Jupyter shows its PNG.

    Attributes
    ----------
    png : bytes
        The image.
    """

    def __init__(self, png: bytes, title: str):
        self.png, self.title = png, title

    def _repr_png_(self) -> bytes:
        return self.png

    def __repr__(self) -> str:
        return f"<plot of {self.title}: {len(self.png)} bytes of PNG>"
