"""A parameter's history and outlook as an SVG plot, drawn on the server: no script, no library, no CDN.

From the prognosis's ``Trend`` and ``RemainingLife`` alone (the documents the API serves): each window's
estimate with its ±2 std, the weighed laws' forecast (median and 90 % band), the threshold, and the
remaining life's 90 % interval as a shaded span.
"""

from __future__ import annotations

import html

import numpy as np

from ema.prognosis.documents import RemainingLife, Trend

WIDTH, HEIGHT = 760, 260
LEFT, RIGHT, TOP, BOTTOM = 70, 20, 28, 40


class Axes:
    """Data to pixels over the plot's inner box."""

    def __init__(self, x: tuple[float, float], y: tuple[float, float]) -> None:
        self.x0, self.x1 = x if x[1] > x[0] else (x[0] - 1.0, x[0] + 1.0)
        self.y0, self.y1 = y if y[1] > y[0] else (y[0] - 1.0, y[0] + 1.0)

    def px(self, x: float) -> float:
        return LEFT + (x - self.x0) / (self.x1 - self.x0) * (WIDTH - LEFT - RIGHT)

    def py(self, y: float) -> float:
        return HEIGHT - BOTTOM - (y - self.y0) / (self.y1 - self.y0) * (HEIGHT - TOP - BOTTOM)


def nice_ticks(low: float, high: float, count: int = 5) -> tuple[np.ndarray, int]:
    """Round ticks inside [low, high], about ``count`` of them, at 1, 2 or 5 times a power of ten; and the decimals
    that print them exactly."""
    raw = (high - low) / max(count - 1, 1)
    power = 10.0 ** np.floor(np.log10(raw))
    step = power * min((1.0, 2.0, 5.0, 10.0), key=lambda m: abs(np.log(m * power / raw)))
    first = np.ceil(low / step - 1e-9) * step
    ticks = np.arange(first, high + step * 1e-9, step)
    decimals = max(0, -int(np.floor(np.log10(step) + 1e-9)))
    return np.round(ticks, decimals + 2) + 0.0, decimals  # + 0.0: no "-0"


def _frame(axes: Axes, x_label: str, title: str) -> list[str]:
    parts = [
        f'<rect x="{LEFT}" y="{TOP}" width="{WIDTH - LEFT - RIGHT}" height="{HEIGHT - TOP - BOTTOM}" '
        'fill="white" stroke="#888"/>',
        f'<text x="{LEFT}" y="18" class="title">{html.escape(title)}</text>',
        f'<text x="{(LEFT + WIDTH - RIGHT) / 2}" y="{HEIGHT - 6}" text-anchor="middle">{html.escape(x_label)}</text>',
    ]
    xs, x_decimals = nice_ticks(axes.x0, axes.x1)
    for x in xs:
        parts.append(
            f'<text x="{axes.px(x):.1f}" y="{HEIGHT - BOTTOM + 15}" text-anchor="middle">{x:.{x_decimals}f}</text>'
        )
    ys, y_decimals = nice_ticks(axes.y0, axes.y1)
    for y in ys:
        parts.append(f'<text x="{LEFT - 6}" y="{axes.py(y) + 4:.1f}" text-anchor="end">{y:.{y_decimals}f}</text>')
        parts.append(
            f'<line x1="{LEFT}" x2="{WIDTH - RIGHT}" y1="{axes.py(y):.1f}" y2="{axes.py(y):.1f}" stroke="#eee"/>'
        )
    return parts


def _limits(trend: Trend, life: RemainingLife) -> Axes:
    times = [p.time for p in trend.points] + [p.time for p in trend.forecast]
    values = [p.value for p in trend.points] + [life.threshold]
    values += [p.value + sign * 2 * p.std for p in trend.points if p.std for sign in (-1, 1)]
    values += [p.high for p in trend.forecast] + [p.low for p in trend.forecast]
    last = max(p.time for p in trend.points)
    if life.rul_high is not None:
        times.append(last + life.rul_high)
    span = max(values) - min(values)
    return Axes((min(times), max(times)), (min(values) - 0.05 * span, max(values) + 0.05 * span))


def trend_plot(trend: Trend, life: RemainingLife, time_unit: str, status: str | None = None) -> str:
    """The SVG of one parameter: estimates ±2 std, forecast band and median, threshold, RUL interval; titled with
    ``status`` (``Prognosis.life_status``) where given, else the remaining life's own."""
    axes = _limits(trend, life)
    parts = _frame(axes, time_unit.replace("_", " "), f"{trend.parameter}: {status or life.status}")
    last = max(p.time for p in trend.points)
    if life.rul_low is not None:
        high = axes.x1 if life.rul_high is None else last + life.rul_high
        x = axes.px(last + life.rul_low)
        parts.append(
            f'<rect class="rul" x="{x:.1f}" y="{TOP}" width="{max(axes.px(high) - x, 1):.1f}" '
            f'height="{HEIGHT - TOP - BOTTOM}" fill="#f4c7c3"><title>remaining life, 90 %</title>'
            "</rect>"
        )
    if trend.forecast:
        upper = " ".join(f"{axes.px(p.time):.1f},{axes.py(p.high):.1f}" for p in trend.forecast)
        lower = " ".join(f"{axes.px(p.time):.1f},{axes.py(p.low):.1f}" for p in reversed(trend.forecast))
        parts.append(f'<polygon class="band" points="{upper} {lower}" fill="#fbd9a6" opacity="0.8"/>')
        median = " ".join(f"{axes.px(p.time):.1f},{axes.py(p.median):.1f}" for p in trend.forecast)
        parts.append(f'<polyline class="forecast" points="{median}" fill="none" stroke="#e8710a" stroke-width="2"/>')
    y = axes.py(life.threshold)
    parts.append(
        f'<line class="threshold" x1="{LEFT}" x2="{WIDTH - RIGHT}" y1="{y:.1f}" y2="{y:.1f}" '
        f'stroke="#c5221f" stroke-dasharray="6 4"><title>threshold {life.threshold:g}</title>'
        "</line>"
    )
    for p in trend.points:
        cx, cy = axes.px(p.time), axes.py(p.value)
        if p.std:
            parts.append(
                f'<line x1="{cx:.1f}" x2="{cx:.1f}" y1="{axes.py(p.value - 2 * p.std):.1f}" '
                f'y2="{axes.py(p.value + 2 * p.std):.1f}" stroke="#1a73e8"/>'
            )
        color = "#999" if p.outlier else "#1a73e8"
        parts.append(
            f'<circle class="estimate" cx="{cx:.1f}" cy="{cy:.1f}" r="3" fill="{color}">'
            f"<title>{html.escape(p.window_id)}: {p.value:.5g}</title></circle>"
        )
    body = "\n".join(parts)
    label = html.escape(f"{trend.parameter} over {time_unit}")
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" role="img" aria-label="{label}" viewBox="0 0 {WIDTH} {HEIGHT}" '
        f'width="{WIDTH}" height="{HEIGHT}">\n{body}\n</svg>'
    )
