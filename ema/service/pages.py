"""The operator's pages, rendered on the server from the documents the API serves (no second model of the data).

``/ui`` lists the actuators most urgent first (``ema.prognosis.status``: due, watch, prognosis failed, not
enough history, healthy), a page at a time, filtered by status or by tail: each with its latest FDJ, η_O
and η_A against nominal and thresholds, its remaining life and when its last window was logged.
``/ui/actuators/{id}`` shows one actuator: a plot per parameter (``ema.service.svg``), the notes of its
latest windows, the prognosis's notes, its backtest, its calibration reports and its document.
Every page is plain HTML and inline SVG: it works on a network with no other host. Every id in a link
is URL-encoded, every text HTML-escaped.
"""

from __future__ import annotations

import html
import urllib.parse
from collections.abc import Sequence

from ema.calibration.documents import CalibrationReport
from ema.prognosis.documents import ActuatorSummary, Prognosis, RemainingLife, Stored, StoredActuator
from ema.prognosis.status import URGENCY, status_of
from ema.service.svg import trend_plot

LATEST_NOTES = 5
PARAMETER_NAMES = {"FDJ": "FDJ", "eta_O": "η_O", "eta_A": "η_A"}
STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #202124; }
table { border-collapse: collapse; } td, th { padding: 4px 10px; border-bottom: 1px solid #ddd; text-align: left; }
.due { background: #fce8e6; } .watch { background: #fef7e0; } .healthy { background: #e6f4ea; }
.badge { font-weight: 600; padding: 2px 8px; border-radius: 10px; }
.due .badge { color: #a50e0e; } .watch .badge { color: #b06000; } .healthy .badge { color: #137333; }
svg text { font-size: 11px; } svg .title { font-size: 13px; font-weight: 600; }
code { background: #f1f3f4; padding: 0 3px; } nav a { margin-right: 0.8em; }
"""


PENDING_REFRESH_S = 5  # while a line is pending, the fleet's page reloads itself this often; never otherwise


def _page(title: str, body: str, refresh_s: int | None = None) -> str:
    refresh = "" if refresh_s is None else f'<meta http-equiv="refresh" content="{refresh_s}">'
    return (
        f'<!doctype html><html lang="en"><head><meta charset="utf-8">{refresh}<title>{html.escape(title)}</title>'
        f'<link rel="icon" href="data:,"><style>{STYLE}</style></head><body>{body}</body></html>'
    )


def missing_page(actuator_id: str) -> str:
    """The page of an actuator nothing is stored of (a 404): said, with the way back to the fleet."""
    body = (
        f"<h1>{html.escape(actuator_id)}</h1><p>No window or document is stored for this actuator: check its id "
        'against the fleet.</p><p><a href="/ui">all actuators</a></p>'
    )
    return _page(f"ema: {actuator_id}: not found", body)


def actuator_link(actuator_id: str) -> str:
    """The link to an actuator's page: its id URL-encoded in the path (a ``?`` or ``#`` stays the id's)."""
    path = "/ui/actuators/" + urllib.parse.quote(actuator_id, safe="/")
    return f'<a href="{html.escape(path, quote=True)}">{html.escape(actuator_id)}</a>'


def _cell(line: ActuatorSummary, name: str) -> str:
    value = line.estimates.get(name)
    if value is None:
        return "—"
    std = line.repeatability_stds.get(name) or line.stds.get(name)  # a change between windows is judged on it
    unit = line.units.get(name, "1")
    shown = f"{value:.4g}" + ("" if std is None else f" ± {std:.2g}") + ("" if unit == "1" else f" {unit}")
    nominal = line.nominal.get(name)
    limits = [] if nominal is None else [f"nominal {nominal:.3g}"]
    for threshold in (line.thresholds.get(name), line.thresholds_below.get(name)):
        if threshold is not None:
            limits.append(f"fails {'>' if threshold.direction == 'above' else '<'} {threshold.level:.3g}")
    return html.escape(shown) + (f" <small>({html.escape(', '.join(limits))})</small>" if limits else "")


def life_text(life: RemainingLife | None, unit: str, status: str | None = None) -> str:
    """A remaining life in words, with its unit; ``status``: its status as the prognosis words it
    (``Prognosis.life_status``), where one is at hand."""
    if life is None:
        return "—"
    if life.status == "already crossed":
        return f"threshold {life.threshold:g} crossed"
    if life.rul is None:
        return status or life.status
    high = "open" if life.rul_high is None else f"{life.rul_high:.3g}"
    return f"{life.rul:.3g} {unit} (90 %: {life.rul_low:.3g}–{high} {unit}; earliest {life.rul_earliest:.3g} {unit})"


def _query(**values: str | int | None) -> str:
    kept = {name: value for name, value in values.items() if value not in (None, "")}
    return "/ui" + ("?" + urllib.parse.urlencode(kept) if kept else "")


def _navigation(total: int, page: int, pages: int, status: str | None, tail: str | None) -> str:
    shown = [f'<a href="{html.escape(_query(tail=tail))}">all</a>']
    shown += [f'<a href="{html.escape(_query(status=s, tail=tail))}">{s}</a>' for s in URGENCY]
    steps = []
    if page > 1:
        steps.append(f'<a href="{html.escape(_query(status=status, tail=tail, page=page - 1))}">previous</a>')
    if page < pages:
        steps.append(f'<a href="{html.escape(_query(status=status, tail=tail, page=page + 1))}">next</a>')
    form = (
        '<form method="get" action="/ui" style="display:inline">'
        f'<input name="tail" placeholder="tail, e.g. tail-123" value="{html.escape(tail or "", quote=True)}">'
        + (f'<input type="hidden" name="status" value="{html.escape(status, quote=True)}">' if status else "")
        + "<button>filter</button></form>"
    )
    counts = f"{total} actuator(s); page {page} of {pages}."
    return f"<nav>status: {' '.join(shown)} {form}</nav><p>{counts} {' '.join(steps)}</p>"


def fleet_page(
    lines: Sequence[ActuatorSummary],
    *,
    page: int,
    pages: int,
    total: int,
    pending: Sequence[str],
    status: str | None,
    tail: str | None,
) -> str:
    """One page of the fleet, most urgent first, each actuator linking to its page."""
    parts = ["<h1>Actuators</h1>", _navigation(total, page, pages, status, tail)]
    if pending:
        parts.append(
            f"<p>{len(pending)} actuator(s) stored windows since their line was computed; their prognoses are being "
            f"brought up to date (shown as they were, or pending): this page reloads itself every {PENDING_REFRESH_S} "
            "s until none is.</p>"
        )
    head = "".join(f"<th>{html.escape(h)}</th>" for h in ["actuator", "status", *PARAMETER_NAMES.values()])
    parts.append(f"<table><tr>{head}<th>remaining life</th><th>last window</th></tr>")
    for line in lines:
        unit = (line.time_unit or "").replace("_", " ")
        badge = line.status
        cells = [
            actuator_link(line.actuator_id),
            f'<span class="badge" title="{html.escape(line.reason, quote=True)}">{html.escape(badge)}</span>',
            *(_cell(line, name) for name in PARAMETER_NAMES),
            html.escape(line.reason) if line.status == "prognosis failed" else life_text(line.remaining_life, unit),
            html.escape(line.latest_when or line.latest_window_id or "—"),
        ]
        css = line.status.split()[0]
        parts.append(f'<tr class="{css}">' + "".join(f"<td>{cell}</td>" for cell in cells) + "</tr>")
    parts.append("</table>")
    return _page("ema: actuators", "\n".join(parts), PENDING_REFRESH_S if pending else None)


def _notes_list(notes: Sequence[tuple[str, str, str]]) -> str:
    """Notes as a list, each (code, text) once with the windows that carry it."""
    if not notes:
        return "<p>none</p>"
    grouped: dict[tuple[str, str], list[str]] = {}
    for source, code, text in notes:
        grouped.setdefault((code, text), []).append(source)
    items = "".join(
        f"<li><code>{html.escape(code)}</code> {html.escape(', '.join(sources))}: {html.escape(text)}</li>"
        for (code, text), sources in grouped.items()
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
        rows.append(
            f"<tr><td>{html.escape(stored_at)}</td><td>{html.escape(effect)}</td><td>{html.escape(change)}</td></tr>"
        )
    head = "<table><tr><th>stored</th><th>effect</th><th>estimates before → after</th></tr>"
    return head + "".join(rows) + "</table>"


def _read_with(history: Sequence[Stored], document: StoredActuator | None) -> str:
    """Which document the latest window was read with, and which one is stored now (they may differ)."""
    stored_now = (
        "none stored (windows are read with the default)"
        if document is None
        else (f"{html.escape(document.document.name)}, version {document.version}")
    )
    if not history:
        return f"document: {stored_now}"
    read = history[-1].actuator
    used = "the default" if read.default else f"version {read.version}" if read.version is not None else "given"
    return f"latest window read with {html.escape(read.name)} ({used}); document stored now: {stored_now}"


def _backtest(prognosis: Prognosis, name: str, unit: str) -> str:
    points = prognosis.backtest.get(name, [])
    if not points:
        return ""
    rows = "".join(
        f"<tr><td>{p.time:.4g} {unit}</td><td>{p.windows}</td><td>{html.escape(p.status)}</td><td>"
        f"{'—' if p.crossing is None else f'{p.crossing:.4g} {unit}'}</td><td>"
        f"{'—' if p.later_inside is None else f'{100 * p.later_inside:.0f} %'}</td></tr>"
        for p in points
    )
    return (
        "<table><tr><th>backtest at</th><th>windows</th><th>said</th><th>crossing then (from the first window)</th>"
        f"<th>later windows inside its band</th></tr>{rows}</table>"
    )


def actuator_page(
    actuator_id: str,
    history: Sequence[Stored],
    prognosis: Prognosis,
    document: StoredActuator | None,
    reports: Sequence[tuple[str, CalibrationReport]],
) -> str:
    """One actuator: its status, plots, notes, backtest, calibrations and document."""
    from ema.model.actuator import THESIS

    unit = prognosis.time_unit.replace("_", " ")
    actuator = THESIS if document is None else document.document
    status, _, reason = status_of(history[-1] if history else None, prognosis, actuator, len(history))
    parts = [
        '<p><a href="/ui">all actuators</a></p>',
        f"<h1>{html.escape(actuator_id)}</h1>",
        f'<p class="{status.split()[0]}"><span class="badge">{status}</span> {html.escape(reason)}; '
        f"{len(history)} window(s), time in {unit}</p>",
        f"<p>{_read_with(history, document)}</p>",
    ]
    for name, trend in prognosis.trends.items():
        life = prognosis.remaining_life[name]
        heading = PARAMETER_NAMES[name] + (f" [{actuator.facts.friction_unit}]" if name == "FDJ" else "")
        worded = prognosis.life_status(name)
        parts.append(f"<h2>{html.escape(heading)}</h2><p>{html.escape(life_text(life, unit, worded))}</p>")
        said = [("prognosis", n.code, n.text) for n in prognosis.notes if n.parameter == name]
        parts += [_notes_list(said)] if said else []
        if trend.points:
            parts.append(trend_plot(trend, life, prognosis.time_unit, worded))
        parts.append(_backtest(prognosis, name, unit))
    latest = [(s.window_id, n.code, n.text) for s in history[-LATEST_NOTES:] for n in s.notes]
    sensors = [("prognosis", n.code, n.text) for n in prognosis.notes if n.parameter not in prognosis.trends]
    parts += [
        "<h2>Notes of the latest windows</h2>",
        _notes_list(latest),
        "<h2>Sensors and the actuator</h2>",
        _notes_list(sensors),
        "<h2>Calibrations</h2>",
        _calibrations(reports),
    ]
    return _page(f"ema: {actuator_id}", "\n".join(parts))
