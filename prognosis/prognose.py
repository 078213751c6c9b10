"""An actuator's stored estimates -> its ``Prognosis``: a trend per parameter and a remaining life each."""

from __future__ import annotations

import datetime as dt
from collections.abc import Sequence

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from prognosis.documents import PARAMETERS, Prognosis, Stored, Trend
from prognosis.rul import remaining_life
from prognosis.trend import fit_trend
from sim.params import DEFAULT_RANGES, eta_a_from_eta_o
from training.documents import Note
from training.history import combined_inertia, inertia_change_note
from training.prepare.departures.aircraft_check import TOLERANCE

SENSOR_STDS = 3.0  # stds by which a sensor's level or drift must stand out to be said


class Thresholds(BaseModel):
    """Where each parameter ends the actuator's useful life (the service's settings may move them)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    fdj_above_nm: float = Field(1.5 * DEFAULT_RANGES.nominal_fdj_nm, gt=0, description="FDJ +50 % of nominal")
    eta_o_below: float = Field(0.70, gt=0, lt=1)
    eta_a_below: float = Field(float(eta_a_from_eta_o(0.70)), lt=1, description="Eq. 3.4 at η_O = 0.70")

    def of(self, parameter: str) -> tuple[float, str]:
        return {
            "FDJ": (self.fdj_above_nm, "above"),
            "eta_O": (self.eta_o_below, "below"),
            "eta_A": (self.eta_a_below, "below"),
        }[parameter]


def _times(stored: Sequence[Stored]) -> tuple[np.ndarray, str, Note | None]:
    """Flight hours where every window has them, else days from the windows' or the storage's dates."""
    if all(s.window.flight_hours is not None for s in stored):
        return np.array([s.window.flight_hours for s in stored], dtype=float), "flight_hours", None
    if all(s.window.recorded_at is not None for s in stored):
        stamps, note = [s.window.recorded_at for s in stored], None
    else:
        text = "windows carry no recorded_at: time is when they were stored"
        stamps, note = [s.stored_at for s in stored], Note(code="time_from_storage", text=text)
    seconds = np.array([dt.datetime.fromisoformat(str(t)).timestamp() for t in stamps])
    return (seconds - seconds.min()) / 86_400.0, "days", note


def prognose(actuator_id: str, stored: Sequence[Stored], thresholds: Thresholds | None = None) -> Prognosis:
    """Trends and remaining lives of FDJ, η_O and η_A over ``stored`` (any order)."""
    if not stored:
        return Prognosis(actuator_id=actuator_id, time_unit="days", trends={}, remaining_life={},
                         notes=[Note(code="no_estimates", text="no estimates stored for this actuator")])  # fmt: skip
    times, unit, note = _times(stored)
    ids = [s.window_id for s in stored]
    trends, lives = {}, {}
    for name in PARAMETERS:
        entries = [getattr(s.estimates, name) for s in stored]
        values = np.array([e.value for e in entries])
        stds = np.array([np.nan if e.std is None else e.std for e in entries])
        trends[name] = fit_trend(name, times, values, stds, ids)
        lives[name] = remaining_life(trends[name], *(thresholds or Thresholds()).of(name))
    sensors, said = sensor_trends(stored, times, unit)
    inertias = [s.window.inertia_read for s in stored if s.window.inertia_read is not None]
    changed = inertia_change_note(inertias)
    return Prognosis(actuator_id=actuator_id, time_unit=unit, trends=trends, remaining_life=lives,  # type: ignore[arg-type]
                     sensors=sensors, inertia=combined_inertia(inertias),
                     notes=[n for n in (note, *said, changed) if n])  # fmt: skip


def sensor_trends(stored: Sequence[Stored], times: np.ndarray, unit: str) -> tuple[dict[str, Trend], list[Note]]:
    """The trend of the strain gauge's gain against the aircraft model over the windows that read it (two
    at least), and notes where its level stands off 1 beyond the model's tolerance or it drifts
    (``SENSOR_STDS`` stds)."""
    read = [(t, s.window.hinge_aircraft_ratio, s.window.hinge_aircraft_ratio_std, s.window_id)
            for t, s in zip(times, stored, strict=True) if s.window.hinge_aircraft_ratio is not None]  # fmt: skip
    if len(read) < 2:
        return {}, []
    t, values, stds, ids = zip(*read, strict=True)
    trend = fit_trend("hinge_aircraft_ratio", np.array(t), np.array(values), np.array(stds, dtype=float), list(ids))
    notes = []
    if abs(trend.level - 1.0) > TOLERANCE + SENSOR_STDS * trend.level_std:
        notes.append(Note(code="gauge_off_model", parameter="hinge_moment_nm", text=
            f"the hinge moment's strain gauge reads {trend.level:.3f} ± {trend.level_std:.3f}x the aircraft model over "
            f"{trend.n} windows, beyond the model's {100 * TOLERANCE:.0f} % tolerance: recalibrate the gauge, or the "
            "airframe's C_hδ is off (each estimate divides the gauge's gain out where its window is long enough)"
        ))
    if trend.slope_std is not None and abs(trend.slope_per_unit) > SENSOR_STDS * trend.slope_std:
        notes.append(Note(code="gauge_drift", parameter="hinge_moment_nm", text=
            f"the hinge moment's strain gauge drifts against the aircraft model by {trend.slope_per_unit:+.2g} "
            f"± {trend.slope_std:.2g} per {unit.replace('_', ' ').rstrip('s')}"
        ))
    return {"hinge_aircraft_ratio": trend}, notes
