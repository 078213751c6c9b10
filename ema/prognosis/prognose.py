"""An actuator's stored estimates -> its ``Prognosis``: a trend per parameter and a remaining life each."""

from __future__ import annotations

import datetime as dt
import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ema.estimate.documents import Note, ParameterEstimate
from ema.kinds import prognosis_parts, sensor_gains
from ema.kinds.base import SensorGain
from ema.model.actuator import ActuatorDocument
from ema.prognosis.backtest import backtest
from ema.prognosis.documents import (
    MIN_SPAN,
    PARAMETERS,
    Prognosis,
    RemainingLife,
    Stored,
    TimeUnit,
    Trend,
    prognosis_class,
)
from ema.prognosis.outlook import Outlook, outlook
from ema.prognosis.trend import Series, trend_of

SENSOR_STDS = 3.0  # stds by which a sensor's level or drift must stand out to be said
AWAY_STDS = 3.0  # stds by which a trend's slope away from its failure level must stand out to be said


def _times(stored: Sequence[Stored]) -> tuple[np.ndarray, TimeUnit, Note | None]:
    """Flight hours where every window gives them, else days from their ``recorded_at``, else their order.

    When a window was stored is not when it was logged: a batch posted in a second would read as a collapse.
    Without a time base the windows are trended in their order, and the remaining life counts windows.
    """
    if all(s.window.flight_hours is not None for s in stored):
        return np.array([s.window.flight_hours for s in stored], dtype=float), "flight_hours", None
    if all(s.window.recorded_at is not None for s in stored):
        seconds = np.array([dt.datetime.fromisoformat(str(s.window.recorded_at)).timestamp() for s in stored])
        return (seconds - seconds.min()) / 86_400.0, "days", None
    timeless = sum(s.window.flight_hours is None and s.window.recorded_at is None for s in stored)
    said = (
        f"none of the {len(stored)} window(s) gives flight_hours or recorded_at"
        if timeless == len(stored)
        else f"the windows share no time base ({timeless} of the {len(stored)} give neither flight_hours nor "
        "recorded_at, or some give only one and others only the other)"
    )
    text = f"{said}: trended by the order they were stored in, so a remaining life counts windows, not time"
    order = np.argsort([s.id for s in stored], kind="stable")
    return np.argsort(order).astype(float), "windows", Note(code="time_by_window_order", text=text)


def prognose(
    actuator_id: str, stored: Sequence[Stored], actuator: ActuatorDocument, *, backtested: bool = True
) -> Prognosis:
    """Trends and remaining lives of FDJ, η_O and η_A over ``stored`` (any order), to ``actuator``'s
    thresholds; a parameter a window did not read (η_O without a load) is left out of its trend."""
    if not stored:
        own, _ = prognosis_parts(actuator, [])
        return prognosis_class(own)(
            actuator_id=actuator_id,
            time_unit="windows",
            trends={},
            remaining_life={},
            notes=[Note(code="no_estimates", text="no estimates stored for this actuator")],
            **own,
        )
    times, unit, note = _times(stored)
    outlooks = {
        name: seen
        for name in PARAMETERS
        if (seen := _outlook(name, stored, times, actuator, unit, backtested)) is not None
    }
    sensors, said = sensor_trends(stored, times, unit, actuator.load_model_tolerance)
    constants = constant_trends(stored, times)
    own, own_notes = prognosis_parts(actuator, [s.window for s in stored])  # its kind's parts (a rotary's J_M)
    faster = [speeding_note(name) for name, seen in outlooks.items() if seen.life.speeding_up]
    away = [away_note(name, seen, actuator, unit) for name, seen in outlooks.items()]
    levelless = [no_level_note(name, actuator) for name in PARAMETERS if _read(name, stored) and name not in outlooks]
    notes = [n for n in (note, *faster, *away, *levelless, *said, *own_notes) if n]
    return prognosis_class(own)(
        actuator_id=actuator_id,
        time_unit=unit,
        trends={n: o.trend for n, o in outlooks.items()},
        remaining_life={n: o.life for n, o in outlooks.items()},
        sensors=sensors,
        constants=constants,
        **own,
        notes=notes,
        backtest={n: o.backtest for n, o in outlooks.items()},
    )


def _outlook(
    name: str, stored: Sequence[Stored], times: np.ndarray, actuator: ActuatorDocument, unit: TimeUnit, backtested: bool
) -> Outlook | None:
    """``name``'s outlook over the windows that read it, or None where none did: against the level it crosses first
    where the document gives two (FDJ above and below), its changes judged on each window's repeatability std."""
    series = _series(name, stored, times, [getattr(s.estimates, name) for s in stored])
    limits = actuator.limits(name)
    if series is None or not limits:
        return None
    span = MIN_SPAN[unit]
    each = {(level, way): outlook(series, threshold=level, direction=way, min_span=span) for level, way in limits}
    (threshold, direction), seen = min(each.items(), key=lambda item: _urgency(item[1].life))
    if not backtested:
        return seen
    tested = backtest(series, threshold=threshold, direction=direction, min_span=span)
    return replace(seen, backtest=tested)


def _read(name: str, stored: Sequence[Stored]) -> bool:
    return any(getattr(s.estimates, name) is not None for s in stored)


def no_level_note(name: str, actuator: ActuatorDocument) -> Note | None:
    """Why a parameter the windows read has no trend, where the reason is that it has no failure level to trend
    towards (``ActuatorDocument.limits``), and how to give it one."""
    if actuator.limits(name):
        return None
    field = actuator.facts.friction_field("fdj_above") if name == "FDJ" else "eta_o_below"
    return Note(
        code="no_threshold",
        parameter=name,
        text=f"{name} has no failure level to trend towards: the actuator's document gives no thresholds.{field} "
        "and no nominal (ema calibrate on healthy windows learns it: --out-actuator, then store that document)",
    )


def _urgency(life: RemainingLife) -> tuple[int, float]:
    """Which of a parameter's levels (above, below) comes first: one crossed, then the soonest predicted."""
    return (0 if life.status == "already crossed" else 1, life.rul if life.rul is not None else math.inf)


def _one(unit: str) -> str:
    """One of the prognosis's time unit, in words: flight_hours -> flight hour."""
    return unit.replace("_", " ").rstrip("s")


def speeding_note(name: str) -> Note:
    return Note(
        code="speeding_up",
        parameter=name,
        text=(
            f"{name}'s latest windows move towards its threshold faster than its whole history does: wear speeding "
            "up? The remaining life weighs the laws that accelerate by how well they predicted the later windows; "
            "plan for the earliest plausible crossing"
        ),
    )


def away_note(name: str, seen: Outlook, actuator: ActuatorDocument, unit: TimeUnit) -> Note | None:
    """A note where ``name``'s whole history moves away from the level its remaining life watches, its slope
    ``AWAY_STDS`` stds from flat: a change all the same (friction that falls, an efficiency that rises), which a
    remaining life watching one way can only call no degradation; and the level that would watch it, where the
    document gives none that way."""
    trend, life = seen.trend, seen.life
    if life.status != "no degradation detected" or trend.slope_std is None:
        return None
    away = -trend.slope_per_unit if life.direction == "above" else trend.slope_per_unit
    if away <= AWAY_STDS * trend.slope_std:
        return None
    other = "below" if life.direction == "above" else "above"
    watched = any(way == other for _, way in actuator.limits(name))
    field = actuator.facts.friction_field(f"fdj_{other}") if name == "FDJ" else None
    hint = "" if watched or field is None else f"; a level {other} (thresholds.{field}) would trend towards it"
    units = f" {actuator.facts.friction_unit}" if name == "FDJ" else ""
    return Note(
        code="moving_away",
        parameter=name,
        text=f"{name} {'falls' if other == 'below' else 'rises'} by {away:.2g} ± {trend.slope_std:.2g}{units} per "
        f"{_one(unit)} over {trend.n} windows: a change all the same, which the remaining "
        f"life to its level {life.direction} ({life.threshold:.4g}{units}) cannot call a degradation{hint}",
    )


def constant_trends(stored: Sequence[Stored], times: np.ndarray) -> dict[str, Trend]:
    """The trend of each constant the windows read beside the health (``Estimates.constants``) over the windows
    that read it (two at least), each judged on its repeatability std as the health is."""
    names = dict.fromkeys(name for s in stored for name in s.estimates.constants)
    trends = {}
    for name in names:
        series = _series(name, stored, times, [s.estimates.constants.get(name) for s in stored])
        if series is not None and len(series.values) >= 2:
            trends[name] = trend_of(series)
    return trends


def _series(
    name: str, stored: Sequence[Stored], times: np.ndarray, entries: Sequence[ParameterEstimate | None]
) -> Series | None:
    """``name``'s readings over the windows whose entry (``entries``, one per window) holds one (None: none does),
    each with its repeatability std (its whole std where it gives none; NaN where neither is known)."""
    read = [(t, e, s.window_id) for t, s, e in zip(times, stored, entries, strict=True) if e is not None]
    if not read:
        return None
    values = np.array([e.value for _, e, _ in read])
    stds = np.array([np.nan if (std := e.repeatability_std or e.std) is None else std for _, e, _ in read])
    return Series(name, np.array([t for t, _, _ in read]), values, stds, [i for _, _, i in read])


def sensor_trends(
    stored: Sequence[Stored], times: np.ndarray, unit: str, tolerance: float
) -> tuple[dict[str, Trend], list[Note]]:
    """The trend of each sensor's gain against its model (``ema.kinds.sensor_gains``) over the windows that read
    it (two at least), and notes where its level stands off 1 beyond the model's ``tolerance`` or it drifts
    (``SENSOR_STDS`` stds)."""
    trends: dict[str, Trend] = {}
    notes: list[Note] = []
    for gain in sensor_gains():
        read = [(t, *r, s.window_id) for t, s in zip(times, stored, strict=True) if (r := gain.read(s.window))]
        if len(read) < 2:
            continue
        t, values, stds, ids = zip(*read, strict=True)
        trend = trend_of(Series(gain.name, np.array(t), np.array(values), np.array(stds, dtype=float), list(ids)))
        trends[gain.name] = trend
        notes += _gain_notes(gain, trend, tolerance, unit)
    return trends, notes


def _gain_notes(gain: SensorGain, trend: Trend, tolerance: float, unit: str) -> list[Note]:
    """Where a sensor's gain stands off its model beyond ``tolerance``, or drifts, each by ``SENSOR_STDS`` stds."""
    notes = []
    if abs(trend.level - 1.0) > tolerance + SENSOR_STDS * trend.level_std:
        notes.append(
            Note(
                code="gauge_off_model",
                parameter=gain.signal,
                text=f"{gain.sensor} reads {trend.level:.3f} ± {trend.level_std:.3f}x {gain.model} over {trend.n} "
                f"windows, beyond the model's {100 * tolerance:.0f} % tolerance: {gain.remedy}",
            )
        )
    if trend.slope_std is not None and abs(trend.slope_per_unit) > SENSOR_STDS * trend.slope_std:
        notes.append(
            Note(
                code="gauge_drift",
                parameter=gain.signal,
                text=f"{gain.sensor} drifts against {gain.model} by {trend.slope_per_unit:+.2g} "
                f"± {trend.slope_std:.2g} per {_one(unit)}",
            )
        )
    return notes
