"""The operator's pages, rendered on the server from the documents the API serves (no second model of the data).

``/ui`` lists every actuator, most urgent first: its latest FDJ, η_O and η_A against nominal and thresholds,
its remaining life, the time of its last window and a status:

- **due**: a threshold is crossed, or the earliest plausible crossing comes within ``DUE_WITHIN`` (time units
  of its prognosis);
- **watch**: a crossing is predicted, wear is speeding up, its latest estimate lies outside its healthy range,
  or the model did not reproduce its latest window;
- **healthy**: none of these.

``/ui/actuators/{id}`` shows one actuator: a plot per parameter (``ema.service.svg``), the notes of its latest
windows, the prognosis's notes (sensors, J_M), its backtest, its calibration reports and its document.
Every page is plain HTML and inline SVG: it works on a network with no other host.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

from ema.calibration.documents import CalibrationReport
from ema.model.actuator import Actuator
from ema.prognosis.documents import PARAMETERS, Prognosis, RemainingLife, Stored, StoredActuator
from ema.service.svg import trend_plot

DUE_WITHIN = 25.0  # flight hours (or days): an earliest plausible crossing this close makes the actuator due
LATEST_NOTES = 5
Status = Literal["due", "watch", "healthy"]
STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #202124; }
table { border-collapse: collapse; } td, th { padding: 4px 10px; border-bottom: 1px solid #ddd; text-align: left; }
.due { background: #fce8e6; } .watch { background: #fef7e0; } .healthy { background: #e6f4ea; }
.badge { font-weight: 600; padding: 2px 8px; border-radius: 10px; }
.due .badge { color: #a50e0e; } .watch .badge { color: #b06000; } .healthy .badge { color: #137333; }
svg text { font-size: 11px; } svg .title { font-size: 13px; font-weight: 600; }
code { background: #f1f3f4; padding: 0 3px; }
"""


@dataclass(frozen=True)
class Row:
    """One actuator as the fleet page lists it."""

    actuator_id: str
    latest: Stored | None
    prognosis: Prognosis
    actuator: Actuator
    status: Status
    soonest: float | None  # the earliest plausible crossing of any parameter (None: none predicted)


def status_of(latest: Stored | None, prognosis: Prognosis, actuator: Actuator) -> tuple[Status, float | None]:
    """The actuator's status (module docstring) and its soonest plausible crossing."""
    lives = list(prognosis.remaining_life.values())
    soonest = min((life.rul_earliest for life in lives if life.rul_earliest is not None), default=None)
    if any(life.status == "already crossed" for life in lives) or (soonest is not None and soonest <= DUE_WITHIN):
        return "due", soonest
    predicted = any(life.status == "crossing predicted" or life.speeding_up for life in lives)
    return ("watch" if predicted or _off_healthy(latest, actuator) else "healthy"), soonest


def _off_healthy(latest: Stored | None, actuator: Actuator) -> bool:
    if latest is None:
        return False
    ranges = actuator.ranges
    fdj, eta_o = latest.estimates.FDJ.value, latest.estimates.eta_O
    outside = not ranges.fdj_nm[0] <= fdj <= ranges.fdj_nm[1]
    outside |= eta_o is not None and not ranges.eta_o[0] <= eta_o.value <= ranges.eta_o[1]
    return outside or not latest.fit_check.reproduced


def urgency(row: Row) -> tuple[int, float, str]:
    soonest = row.soonest if row.soonest is not None else 1e300
    return {"due": 0, "watch": 1, "healthy": 2}[row.status], soonest, row.actuator_id


def _page(title: str, body: str) -> str:
    return (
        f'<!doctype html><html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
        f'<link rel="icon" href="data:,"><style>{STYLE}</style></head><body>{body}</body></html>'
    )


def _estimate(stored: Stored | None, name: str, actuator: Actuator) -> str:
    entry = None if stored is None else getattr(stored.estimates, name)
    if entry is None:
        return "—"
    std = "" if entry.std is None else f" ± {entry.std:.2g}"
    threshold, direction = actuator.threshold(name)
    sign = ">" if direction == "above" else "<"
    return f"{entry.value:.4g}{std} <small>(nominal {entry.nominal:.3g}, fails {sign} {threshold:.3g})</small>"


def _life(life: RemainingLife | None, unit: str) -> str:
    if life is None:
        return "—"
    if life.status == "already crossed":
        return f"threshold {life.threshold:g} crossed"
    if life.rul is None:
        return "no degradation detected" if life.status == "no degradation detected" else life.status
    high = "open" if life.rul_high is None else f"{life.rul_high:.3g}"
    return f"{life.rul:.3g} {unit} (90 %: {life.rul_low:.3g}–{high}; earliest {life.rul_earliest:.3g})"


def _most_urgent_life(prognosis: Prognosis) -> RemainingLife | None:
    lives = [life for life in prognosis.remaining_life.values() if life.rul is not None]
    if lives:
        return min(lives, key=lambda life: life.rul_low or 0.0)
    return next(iter(prognosis.remaining_life.values()), None)


def _when(stored: Stored) -> str:
    """When the window was logged: its flight hours where it gives them, else its date (or when it was stored)."""
    if stored.window.flight_hours is not None:
        return f"{stored.window.flight_hours:.4g} flight hours"
    return html.escape((stored.window.recorded_at or stored.stored_at)[:19].replace("T", " "))


def fleet_page(rows: Sequence[Row]) -> str:
    """The fleet: one row per actuator, most urgent first, each linking to its page."""
    lines = [
        "<h1>Actuators</h1>",
        f"<p>{len(rows)} actuator(s); most urgent first.</p>",
        "<table><tr><th>actuator</th><th>status</th><th>FDJ [N·m]</th><th>η_O</th><th>η_A</th>"
        "<th>remaining life</th><th>last window</th></tr>",
    ]
    for row in sorted(rows, key=urgency):
        unit = row.prognosis.time_unit.replace("_", " ")
        last = "—" if row.latest is None else _when(row.latest)
        link = f'<a href="/ui/actuators/{html.escape(row.actuator_id, quote=True)}">{html.escape(row.actuator_id)}</a>'
        cells = [
            link,
            f'<span class="badge">{row.status}</span>',
            *(_estimate(row.latest, name, row.actuator) for name in PARAMETERS),
            _life(_most_urgent_life(row.prognosis), unit),
            last,
        ]
        lines.append(f'<tr class="{row.status}">' + "".join(f"<td>{cell}</td>" for cell in cells) + "</tr>")
    lines.append("</table>")
    return _page("ema: actuators", "\n".join(lines))


def _notes_list(notes: Sequence[tuple[str, str, str]]) -> str:
    if not notes:
        return "<p>none</p>"
    items = "".join(
        f"<li><code>{html.escape(code)}</code> {html.escape(source)}: {html.escape(text)}</li>"
        for source, code, text in notes
    )
    return f"<ul>{items}</ul>"


def _calibrations(reports: Sequence[tuple[str, CalibrationReport]]) -> str:
    if not reports:
        return "<p>none stored</p>"
    rows = []
    for stored_at, report in reports:
        effect = report.selected_effect or "nothing beyond the noise"
        change = ", ".join(
            f"{k} {report.estimates_before[k]:.4g} → {report.estimates_after[k]:.4g}" for k in report.estimates_before
        )
        rows.append(f"<tr><td>{html.escape(stored_at)}</td><td>{html.escape(effect)}</td><td>{change}</td></tr>")
    head = "<table><tr><th>stored</th><th>effect</th><th>estimates before → after</th></tr>"
    return head + "".join(rows) + "</table>"


def actuator_page(
    actuator_id: str,
    history: Sequence[Stored],
    prognosis: Prognosis,
    document: StoredActuator | None,
    actuator: Actuator,
    reports: Sequence[tuple[str, CalibrationReport]],
) -> str:
    """One actuator: its plots, notes, backtest, calibrations and document."""
    unit = prognosis.time_unit.replace("_", " ")
    status, _ = status_of(history[-1] if history else None, prognosis, actuator)
    parts = [
        '<p><a href="/ui">all actuators</a></p>',
        f"<h1>{html.escape(actuator_id)}</h1>",
        f'<p class="{status}"><span class="badge">{status}</span> {len(history)} window(s), time in {unit}; '
        f"read with {html.escape(actuator.name)}"
        f"{'' if document is None else f' (version {document.version})'}</p>",
    ]
    for name, trend in prognosis.trends.items():
        life = prognosis.remaining_life[name]
        parts.append(f"<h2>{name}</h2><p>{_life(life, unit)}</p>")
        if trend.points:
            parts.append(trend_plot(trend, life, prognosis.time_unit))
        backtest = prognosis.backtest.get(name, [])
        if backtest:
            rows = "".join(
                f"<tr><td>{p.time:.4g}</td><td>{p.windows}</td><td>{p.status}</td><td>"
                f"{'—' if p.crossing is None else f'{p.crossing:.4g}'}</td><td>"
                f"{'—' if p.later_inside is None else f'{100 * p.later_inside:.0f} %'}</td></tr>"
                for p in backtest
            )
            parts.append(
                "<table><tr><th>backtest at</th><th>windows</th><th>said</th><th>crossing then</th>"
                f"<th>later windows inside its band</th></tr>{rows}</table>"
            )
    latest = [(s.window_id, n.code, n.text) for s in history[-LATEST_NOTES:] for n in s.notes]
    sensors = [("prognosis", n.code, n.text) for n in prognosis.notes]
    parts += [
        "<h2>Notes of the latest windows</h2>",
        _notes_list(latest),
        "<h2>Sensors and the actuator</h2>",
        _notes_list(sensors),
        "<h2>Calibrations</h2>",
        _calibrations(reports),
    ]
    return _page(f"ema: {actuator_id}", "\n".join(parts))
