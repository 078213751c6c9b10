"""``ema-calibration/1``: the one definition of a calibration report (``docs/calibration.md``).

The loop returns it, ``POST /v1/calibrate`` declares it, ``ema calibrate`` prints it, the study
in benchmarks/ reads it; docs/schemas/ema-calibration-1.json is exported from it.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from ema.estimate.documents import Document


class Candidate(Document):
    effect: str = Field(description="a named effect, or 'friction vs <variable>' for a generic curve")
    follows: str = Field(description="the variable its trace follows")
    named: bool
    parameters: dict[str, float] = Field(description="at its best fit; a curve as value per grid point")
    rms_reduction: float = Field(description="1 − √(residual with it / without), in sample")
    held_out_drop: float = Field(description="fractional drop of the held-out residual")
    score: float = Field(description="z: held-out drop in noise-floor stds above what noise alone gives")
    plausible: bool = Field(description="the simulator can add it with these parameters")


class Step(Document):
    selected: str | None
    reason: str
    indistinguishable_from: list[str] = Field(default_factory=list)
    tie_break_output_error: dict[str, float] | None = None


class Unexplained(Document):
    """Structure no named effect fits, described rather than named."""

    adopted: bool = Field(
        False,
        description="the term is in the estimates after (it predicts held-out folds "
        "better and its estimates are identified), as a named effect would be",
    )
    variables: list[str] = Field(description="what the residual follows (several: the windows cannot tell which)")
    description: str
    shape: dict[str, float] = Field(description="extra friction [N·m] at grid points of the first variable")
    simulator_term: dict | None = Field(description="a FrictionTable the simulator can add; null where it has none")
    estimates_if_added: dict[str, float] | None = Field(
        description="FDJ and η_O re-estimated with the term; null where not identified (see estimates_withheld)"
    )
    estimates_withheld: str | None = Field(default=None, description="why estimates_if_added is null")
    residual_rms_if_added: float
    error_if_added: dict[str, float] | None = None


class NoiseFloor(Document):
    copies: int
    equation_error_ratio: float = Field(description="RMS of the measured Eq. 5.1 residual over the copies' mean")


class HeldOut(Document):
    """The model re-estimated on four folds, predicting the fifth, in turn: with the effects and without."""

    rss_before: float = Field(description="held-out residual sum of squares of the base model [N²·m²]")
    rss_after: float = Field(description="the same with the effects in")
    adopted: bool
    note: str


class CalibrationReport(Document):
    """``ema-calibration/1``."""

    schema_: Literal["ema-calibration/1"] = Field("ema-calibration/1", alias="schema")
    n_windows: int
    noise_floor: NoiseFloor
    residual_rms_before: dict[str, float]
    residual_rms_after: dict[str, float]
    candidates: list[Candidate]
    selected_effect: str | None = Field(description="the first effect named; null when noise explains the residual")
    selected_effects: list[str]
    selected_parameters: dict[str, float] | None
    effects: dict = Field(description="what the simulator adds: named effects' parameters and a friction table")
    selection_steps: list[Step]
    unexplained: Unexplained | None
    held_out: HeldOut
    estimates_before: dict[str, float]
    estimates_after: dict[str, float]
    error_before: dict[str, float] | None = None
    error_after: dict[str, float] | None = None
    error_pct_before: dict[str, float] | None = None
    error_pct_after: dict[str, float] | None = None
    timings_s: dict[str, float]
