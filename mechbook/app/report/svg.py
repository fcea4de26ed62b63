"""Small charts as inline SVG: lines over t, a phase portrait, measured against linear.

A PNG from matplotlib cost a page a third of a second each and a worker a second of
imports; these are a few kilobytes of text written in milliseconds, scale with the page,
and need nothing fetched. Each chart has axes with a few round ticks, a title (`<title>`
for screen readers too) and a legend above the plotting area, never on the curves.
"""

from __future__ import annotations

import html
import math

import numpy as np

COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2",
           "#17becf")
W, H = 420, 240  # the chart's size in CSS pixels (H grows by the legend's lines)
PAD = (46, 12, 8, 34)  # left, right, top (above the legend), bottom
LEGEND_LINE = 14  # px per line of the legend
CHAR = 6.6  # px per character of a legend label (the chart's 11 px sans-serif, generous)


def _ticks(lo: float, hi: float, count: int = 4) -> list[float]:
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi <= lo:
        return [lo]
    step = 10 ** math.floor(math.log10((hi - lo) / count))
    for factor in (1, 2, 5, 10):
        if (hi - lo) / (step * factor) <= count:
            step *= factor
            break
    first = math.ceil(lo / step) * step
    return [first + i * step for i in range(int((hi - first) / step) + 1)]


def _fmt(x: float, step: float) -> str:
    """A tick's label with as many decimals as the step between ticks needs (a minus sign,
    not a hyphen)."""
    if x == 0:
        return "0"
    if abs(x) >= 1e5 or abs(x) < 1e-3:
        return f"{x:.3g}".replace("-", "\u2212")
    decimals = max(0, -math.floor(math.log10(step))) if step > 0 else 3
    return f"{x:.{min(decimals, 8)}f}".replace("-", "\u2212")


def _range(values: list[np.ndarray]) -> tuple[float, float]:
    finite = np.concatenate([v[np.isfinite(v)] for v in values]) if values else np.array([])
    if not len(finite):
        return 0.0, 1.0
    lo, hi = float(finite.min()), float(finite.max())
    if hi - lo < 1e-12 * max(1.0, abs(hi)):
        lo, hi = lo - max(1.0, abs(lo)) * 0.1, hi + max(1.0, abs(hi)) * 0.1
    pad = 0.05 * (hi - lo)
    return lo - pad, hi + pad


def _legend(labels: list[str], left: int, width: int) -> list[list[tuple[int, float]]]:
    """The legend's lines: (series index, x offset) per entry, entries wrapped to `width`."""
    lines: list[list[tuple[int, float]]] = [[]]
    x = 0.0
    for i, label in enumerate(labels):
        size = 22 + CHAR * len(label) + 12  # swatch, label, gap
        if lines[-1] and x + size > width:
            lines.append([])
            x = 0.0
        lines[-1].append((i, left + x))
        x += size
    return lines


def chart(series: list[tuple], title: str, xlabel: str, ylabel: str) -> str:
    """An SVG chart of (label, x, y) series drawn as lines, or (label, x, y, "dots"); the
    legend above the plotting area (class `legend`), which is the rect of class `plot`."""
    xs = [np.asarray(s[1], float) for s in series]
    ys = [np.asarray(s[2], float) for s in series]
    x0, x1 = _range(xs)
    y0, y1 = _range(ys)
    left, right, pad_top, bottom = PAD
    legend = _legend([str(s[0]) for s in series], left, W - left - right)
    top = pad_top + LEGEND_LINE * len(legend) + 6
    height = H + top - 22  # the plotting area keeps its height
    pw, ph = W - left - right, height - top - bottom

    def px(x):
        return left + (x - x0) / (x1 - x0) * pw

    def py(y):
        return top + (1 - (y - y0) / (y1 - y0)) * ph

    out = [f'<svg class="chart" viewBox="0 0 {W} {height}" width="{W}" height="{height}" '
           f'role="img" xmlns="http://www.w3.org/2000/svg"><title>{html.escape(title)}'
           "</title>",
           f'<rect class="plot" x="{left}" y="{top}" width="{pw}" height="{ph}" fill="#fff" '
           'stroke="#999"/>']
    xt, yt = _ticks(x0, x1), _ticks(y0, y1)
    xstep = xt[1] - xt[0] if len(xt) > 1 else 0.0
    ystep = yt[1] - yt[0] if len(yt) > 1 else 0.0
    for t in xt:
        out.append(f'<text x="{px(t):.1f}" y="{height - bottom + 13}" '
                   f'text-anchor="middle">{_fmt(t, xstep)}</text>')
    for t in yt:
        out.append(f'<line x1="{left}" x2="{left + pw}" y1="{py(t):.1f}" y2="{py(t):.1f}" '
                   'stroke="#eee"/>')
        out.append(f'<text x="{left - 4}" y="{py(t) + 4:.1f}" text-anchor="end">'
                   f"{_fmt(t, ystep)}</text>")
    for i, (_label, x, y, *style) in enumerate(series):
        marks = style == ["dots"]
        colour = COLOURS[i % len(COLOURS)]
        x, y = np.asarray(x, float), np.asarray(y, float)
        keep = np.isfinite(x) & np.isfinite(y)
        if len(x) > 600:  # enough points for the eye
            step = len(x) // 600 + 1
            sub = np.zeros(len(x), bool)
            sub[::step] = True
            keep &= sub
        pts = " ".join(f"{px(a):.1f},{py(b):.1f}" for a, b in zip(x[keep], y[keep],
                                                                   strict=True))
        if marks:
            out += [f'<circle cx="{px(a):.1f}" cy="{py(b):.1f}" r="3.5" fill="{colour}"/>'
                    for a, b in zip(x[keep], y[keep], strict=True)]
        elif pts:
            out.append(f'<polyline points="{pts}" fill="none" stroke="{colour}" '
                       'stroke-width="1.3"/>')
    out += _legend_svg(series, legend, pad_top)
    out.append(f'<text x="{left + pw / 2:.0f}" y="{height - 4}" text-anchor="middle">'
               f"{html.escape(xlabel)}</text>")
    out.append(f'<text x="12" y="{top + ph / 2:.0f}" text-anchor="middle" '
               f'transform="rotate(-90 12 {top + ph / 2:.0f})">{html.escape(ylabel)}</text>')
    out.append("</svg>")
    return "".join(out)


def _legend_svg(series: list[tuple], legend: list, pad_top: int) -> list[str]:
    """Each series' swatch (a line, or a dot for dots) and label, line by line."""
    out = []
    for row, entries in enumerate(legend):
        y = pad_top + LEGEND_LINE * row + 10
        for i, x in entries:
            label, style = series[i][0], (series[i][3] if len(series[i]) > 3 else None)
            colour = COLOURS[i % len(COLOURS)]
            swatch = (f'<circle cx="{x + 8:.1f}" cy="{y - 4}" r="3.5" fill="{colour}"/>'
                      if style == "dots" else
                      f'<line x1="{x:.1f}" x2="{x + 16:.1f}" y1="{y - 4}" y2="{y - 4}" '
                      f'stroke="{colour}" stroke-width="2"/>')
            out.append(f'<g class="legend">{swatch}<text x="{x + 22:.1f}" y="{y}">'
                       f"{html.escape(str(label))}</text></g>")
    return out


def frequencies_chart(modes: list[dict], title: str) -> str | None:
    """Each mode's frequency measured in the nonlinear simulation against the linear one,
    with the line measured = linear."""
    points = [(float(m["linear"]), float(m["measured"])) for m in modes
              if "measured" in m and m.get("kind") != "zero"]
    if len(points) < 2:  # one mode: the table's relative difference says it all
        return None
    lin = np.array([p[0] for p in points])
    meas = np.array([p[1] for p in points])
    line = np.array([min(lin.min(), meas.min()), max(lin.max(), meas.max())])
    return chart([("measured = linear", line, line), ("each mode", lin, meas, "dots")],
                 title, "ω of the linear system", "ω measured in the simulation")
