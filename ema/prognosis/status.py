"""An actuator's status: what an operator acts on, earned by evidence.

- **due**: a threshold is crossed, or the earliest plausible crossing comes within ``DUE_WITHIN``;
- **watch**: a crossing is predicted, wear is speeding up, a trend moves away from the failure level it is
  watched against (friction that falls: ``moving_away``), the latest estimate lies outside the healthy range,
  or the model did not reproduce the latest window;
- **healthy**: none of these;
- **not enough history**: fewer than ``MIN_STATUS_WINDOWS`` windows, or windows spread over less than the
  prognosis's ``MIN_SPAN``: no trend can say "due" yet (the latest window alone may still say "watch").

Without that evidence the status is never "due", however far the latest window lies past a threshold
(it is "watch" then). A forecast in window order (windows with no time base) never makes an actuator due
before its threshold is crossed: a count of windows is not a date.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from ema.model.actuator import ActuatorDocument
from ema.prognosis.documents import MIN_SPAN, ActuatorSummary, Prognosis, RemainingLife, Stored, Threshold

Status = Literal["due", "watch", "healthy", "not enough history"]
DUE_WITHIN = {"flight_hours": 25.0, "days": 25.0}  # an earliest plausible crossing this close makes it due
MIN_STATUS_WINDOWS = 5  # fewer: "not enough history" (a status judges a trend, not a few windows)
URGENCY = {"due": 0, "watch": 1, "prognosis failed": 2, "pending": 3, "not enough history": 4, "healthy": 5}


def lacking_evidence(prognosis: Prognosis, windows: int) -> str | None:
    """Why ``windows`` windows cannot support a trend's status yet (or no trend can: FDJ has no level to trend
    towards), or None where they can."""
    trend = prognosis.trends.get("FDJ")
    levelless = next((n.text for n in prognosis.notes if n.code == "no_threshold" and n.parameter == "FDJ"), None)
    if trend is None and levelless is not None:
        return levelless
    n = windows if trend is None else trend.n
    span = 0.0 if trend is None or not trend.points else float(np.ptp([p.time for p in trend.points]))
    unit = prognosis.time_unit.replace("_", " ")
    needed = (
        f"a status needs {MIN_STATUS_WINDOWS} windows spread over at least {MIN_SPAN[prognosis.time_unit]:g} {unit}"
    )
    if n < MIN_STATUS_WINDOWS:
        return f"{n} window(s): {needed}"
    if span < MIN_SPAN[prognosis.time_unit]:
        return f"{n} windows over {span:.3g} {unit}: {needed}"
    return None


def off_healthy(latest: Stored | None, actuator: ActuatorDocument) -> bool:
    """The latest estimate lies outside the healthy range (where the document's nominal sets one), or the model
    did not reproduce its window."""
    if latest is None:
        return False
    if actuator.nominal is None:
        return not latest.check.reproduced
    ranges = actuator.ranges
    fdj, eta_o = latest.estimates.FDJ.value, latest.estimates.eta_O
    outside = not ranges.fdj_nm[0] <= fdj <= ranges.fdj_nm[1]
    outside |= eta_o is not None and not ranges.eta_o[0] <= eta_o.value <= ranges.eta_o[1]
    return outside or not latest.check.reproduced


def status_of(
    latest: Stored | None, prognosis: Prognosis, actuator: ActuatorDocument, windows: int
) -> tuple[Status, float | None, str]:
    """(status, the soonest plausible crossing, why) of an actuator with ``windows`` stored (module docstring)."""
    lives = list(prognosis.remaining_life.values())
    lacking = lacking_evidence(prognosis, windows)
    if lacking is not None:
        if off_healthy(latest, actuator):
            return "watch", None, f"the latest window lies outside the healthy range or was not reproduced; {lacking}"
        return "not enough history", None, lacking
    if any(life.status == "already crossed" for life in lives):
        return "due", 0.0, "a threshold is crossed"
    soonest = min((life.rul_earliest for life in lives if life.rul_earliest is not None), default=None)
    within = DUE_WITHIN.get(prognosis.time_unit)
    if soonest is not None and within is not None and soonest <= within:
        return "due", soonest, f"the earliest plausible crossing is within {within:g} {prognosis.time_unit}"
    watched = _watched(lives)
    if watched:
        return "watch", soonest, watched
    away = [note.parameter for note in prognosis.notes if note.code == "moving_away"]
    if away:
        moves = "moves away from its failure level" if len(away) == 1 else "move away from their failure levels"
        return "watch", soonest, f"{' and '.join(map(str, away))} {moves}: a change all the same"
    if off_healthy(latest, actuator):
        return "watch", soonest, "the latest window lies outside the healthy range or was not reproduced"
    return "healthy", soonest, "no threshold near and no degradation detected"


def _watched(lives: list[RemainingLife]) -> str | None:
    """Which parameters a crossing is predicted for, and which speed up towards their level (or None)."""
    predicted = [life.parameter for life in lives if life.status == "crossing predicted"]
    faster = [life.parameter for life in lives if life.speeding_up and life.parameter not in predicted]
    said = [f"{' and '.join(predicted)}: a crossing is predicted"] if predicted else []
    said += (
        [f"{' and '.join(faster)}: the latest windows move towards the level faster than the trend"] if faster else []
    )
    return "; ".join(said) or None


def most_urgent_life(prognosis: Prognosis) -> RemainingLife | None:
    lives = [life for life in prognosis.remaining_life.values() if life.rul is not None]
    if lives:
        return min(lives, key=lambda life: life.rul_low or 0.0)
    return next(iter(prognosis.remaining_life.values()), None)


def when(stored: Stored) -> str | None:
    """When a window was logged, as it says: its flight hours, else its recorded_at (None: neither)."""
    if stored.window.flight_hours is not None:
        return f"{stored.window.flight_hours:.6g} flight hours"
    return stored.window.recorded_at


def summary(
    prognosis: Prognosis, latest: Stored | None, windows: int, actuator: ActuatorDocument, version: int | None
) -> ActuatorSummary:
    """The actuator's line in the fleet view: ``windows`` stored, ``latest`` the last of them."""
    actuator_id = prognosis.actuator_id
    status, soonest, reason = status_of(latest, prognosis, actuator, windows)
    names = ("FDJ", "eta_O", "eta_A")
    entries = {} if latest is None else {name: getattr(latest.estimates, name) for name in names}
    levels = {name: limits for name in names if (limits := actuator.limits(name))}
    return ActuatorSummary(
        actuator_id=actuator_id,
        status=status,
        reason=reason,
        windows=windows,
        time_unit=prognosis.time_unit if windows else None,
        soonest=soonest,
        remaining_life=most_urgent_life(prognosis),
        latest_window_id=None if latest is None else latest.window_id,
        latest_when=None if latest is None else when(latest),
        estimates={name: None if e is None else e.value for name, e in entries.items()},
        stds={name: None if e is None else e.std for name, e in entries.items()},
        units={name: e.unit for name, e in entries.items() if e is not None and e.unit is not None},
        repeatability_stds={name: None if e is None else e.repeatability_std for name, e in entries.items()},
        nominal={name: e.nominal for name, e in entries.items() if e is not None and e.nominal is not None},
        thresholds={name: Threshold(level=limits[0][0], direction=limits[0][1]) for name, limits in levels.items()},
        thresholds_below={
            name: Threshold(level=level, direction=way) for name, limits in levels.items() for level, way in limits[1:]
        },
        reproduced=None if latest is None else latest.check.reproduced,
        document=actuator.name,
        document_version=version,
    )


def failed(
    actuator_id: str, windows: int, actuator: ActuatorDocument, version: int | None, error: str
) -> ActuatorSummary:
    """The line of an actuator whose prognosis could not be computed: its own error, not the fleet's."""
    return ActuatorSummary(
        actuator_id=actuator_id,
        status="prognosis failed",
        reason=error,
        windows=windows,
        document=actuator.name,
        document_version=version,
    )
