"""An actuator's stored estimates -> its ``Prognosis``: a trend per parameter and a remaining life each."""

from __future__ import annotations

import datetime as dt
from collections.abc import Sequence

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from prognosis.documents import PARAMETERS, Prognosis, Stored
from prognosis.rul import remaining_life
from prognosis.trend import fit_trend
from sim.params import DEFAULT_RANGES, eta_a_from_eta_o


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


def _times(stored: Sequence[Stored]) -> tuple[np.ndarray, str, str | None]:
    """Flight hours where every window has them, else days from the windows' or the storage's dates."""
    if all(s.window.flight_hours is not None for s in stored):
        return np.array([s.window.flight_hours for s in stored], dtype=float), "flight_hours", None
    if all(s.window.recorded_at is not None for s in stored):
        stamps, note = [s.window.recorded_at for s in stored], None
    else:
        stamps, note = [s.stored_at for s in stored], "windows carry no recorded_at: time is when they were stored"
    seconds = np.array([dt.datetime.fromisoformat(str(t)).timestamp() for t in stamps])
    return (seconds - seconds.min()) / 86_400.0, "days", note


def prognose(actuator_id: str, stored: Sequence[Stored], thresholds: Thresholds | None = None) -> Prognosis:
    """Trends and remaining lives of FDJ, η_O and η_A over ``stored`` (any order)."""
    if not stored:
        return Prognosis(actuator_id=actuator_id, time_unit="days", trends={}, remaining_life={},
                         notes=["no estimates stored for this actuator"])  # fmt: skip
    times, unit, note = _times(stored)
    ids = [s.window_id for s in stored]
    trends, lives = {}, {}
    for name in PARAMETERS:
        entries = [getattr(s.estimates, name) for s in stored]
        values = np.array([e.value for e in entries])
        stds = np.array([np.nan if e.std is None else e.std for e in entries])
        trends[name] = fit_trend(name, times, values, stds, ids)
        lives[name] = remaining_life(trends[name], *(thresholds or Thresholds()).of(name))
    return Prognosis(actuator_id=actuator_id, time_unit=unit, trends=trends, remaining_life=lives,  # type: ignore[arg-type]
                     notes=[note] if note else [])  # fmt: skip
