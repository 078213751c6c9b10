"""The notes of ``ema-estimate/1`` (and of the documents that quote it): a stable code a client matches, the
same in words. Codes may be added; a published one is never renamed or removed."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BeforeValidator, Field

from ema.model.document import Document

NoteCode = Literal[
    # what preparation did to the window, or found in it
    "command_clipped",
    "current_lag",
    "hinge_lag",
    "glitches_repaired",
    "stale_sensor",
    "kinematic_gain",
    "sensor_offset",
    "sensor_zero_carried",
    "sensor_zero_unheld",
    "sensor_zero_unseen",
    "drive_constants",
    "current_units",
    "inertia_from_history",
    "hinge_gain",
    "hinge_vs_aircraft",
    "hinge_vs_aircraft_undecided",
    "aircraft_check_skipped",
    "viscosity",
    "viscosity_unseen",
    "viscosity_leaning",
    "hinge_out_of_step",
    "default_actuator",
    "on_ground",
    "no_load",
    "low_rate",
    "current_at_zero_torque",
    "current_per_nm",
    "controller_mismatch",
    "added_command",
    "unlogged_force",
    "fdj_departed",
    "load_extrapolated",
    "command_saturated",
    "resampled",
    "motor_off",
    "position_quantized",
    # how the answer was reached, and how far to trust it
    "network_absent",
    "network_too_few_checks",
    "network_out_of_box",
    "network_disagrees",
    "network_not_better",
    "physics_only",
    "model_misfit",
    "misfit_learned",
    "model_form",
    "not_reproduced",
    "weakly_determined",
    "eta_o_at_bound",
    "eta_o_unread",
    "fdj_not_friction",
    "irreversible",
    "fsj_read",
    "fsj_no_break_away",
    "fsj_below_fdj",
    # the prognosis
    "no_estimates",
    "time_from_storage",
    "time_by_window_order",
    "prognosis_failed",
    "gauge_off_model",
    "gauge_drift",
    "inertia_changed",
    "inertia_scatter",
    "speeding_up",
    "no_threshold",
    "moving_away",
    # a note stored by an earlier version, as a sentence only
    "unspecified",
]


class Note(Document):
    """Something a reader of a document should know: a stable ``code`` a client or a test matches, and the
    same in words."""

    code: NoteCode
    text: str
    parameter: str | None = Field(None, description="the parameter or signal it concerns, where it is one")


def _sentences_as_notes(value: Any) -> Any:
    """A note stored as a sentence (before notes had codes) is read as ``unspecified``."""
    if isinstance(value, str):
        return {"code": "unspecified", "text": value}
    if isinstance(value, list):
        return [_sentences_as_notes(item) for item in value]
    return value


AnyNote = Annotated[Note, BeforeValidator(_sentences_as_notes)]
Notes = Annotated[list[Note], BeforeValidator(_sentences_as_notes)]
OptionalNote = Annotated[Note | None, BeforeValidator(_sentences_as_notes)]
