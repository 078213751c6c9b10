"""``ema-estimate/1``: the one definition of an estimate result.

The pipeline returns it, the service declares it as its response model, the CLI prints it, the
history stores it and the tests construct it; ``docs/schemas/ema-estimate-1.json`` is exported
from it. Fields may be added; those of a published version are never renamed or removed.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, model_validator

from ema.estimate.config import EarlierCheckWindows, PipelineConfig
from ema.estimate.documents.notes import AnyNote, Notes, OptionalNote
from ema.estimate.documents.notes import Note as Note  # every stage's notes, imported from here
from ema.estimate.documents.window_facts import RotaryWindowInfo, WindowInfo
from ema.model.document import Document

TARGETS = ("FDJ", "eta_O")  # what the estimators read; η_A follows by Eq. 3.4, FSD from FSJ

DIMENSIONLESS = "1"  # η's unit


class ParameterEstimate(Document):
    """One parameter of the window, with its uncertainty: ``std`` the whole of it, ``repeatability_std`` the part
    a comparison of windows read with one document judges a change on."""

    value: float
    std: float | None = Field(description="one standard deviation, in the parameter's unit; null: not assessed")
    nominal: float | None = Field(description="the actuator's value new (null: its document has none yet)")
    drift_pct: float | None = Field(
        description="100 · (value − nominal) / nominal (null without a nominal, and for a constant of either sign, "
        "such as a servo's force offset, whose change no share of it measures: compare value and nominal in stds)"
    )
    unit: str | None = Field(
        None,
        description="the value's unit: N·m for a friction at the motor shaft, N for one on the load (a servo), 1 for "
        "an efficiency (null: stored before units were given)",
    )
    repeatability_std: float | None = Field(
        None,
        description="the part of std a second window read with the same document would not share (the window's "
        "own noise and the run-to-run scatter of the state, not the document's constants): what a trend, a status "
        "and a comparison of windows judge a change on (null: stored before it was given; std then)",
    )
    weakly_determined: bool = Field(
        default=False,
        description="the window holds little of this parameter: its ±2 std spans more than 10 % of the healthy "
        "range (a short window, a slow log, a hinge load that barely varies), or Eq. 5.1 put η_O at an end of the "
        "physical search range (a bound rather than a value, FDJ read with it held there); the notes say so in words",
    )


class RatioEstimate(Document):
    value: float
    std: float | None = None


class Estimates(Document):
    FDJ: ParameterEstimate
    eta_O: ParameterEstimate | None = Field(description="null: the window carries no load (the notes say why)")
    eta_A: ParameterEstimate | None = Field(description="null with eta_O")
    FSJ: ParameterEstimate | None
    FSD: RatioEstimate | None = None
    constants: dict[str, ParameterEstimate] = Field(
        default_factory=dict,
        description="the other constants the window read beside its health, in the names of the actuator's document "
        "(a servo's mass_kg, viscous_ns_per_m, offset_n), each with its unit",
    )


STAGES = ("prepare", "physics", "simulate", "learn", "assess", "check", "report")  # the pipeline's, in order


class Timings(Document):
    """Seconds of each stage of the estimate, in order (``STAGES``), whatever the kind; a stage that did not run
    for this window (a low-rate window reads no simulations) is 0, and ``stages`` in the estimate says why."""

    prepare: float = Field(0.0, description="the window checked, repaired, aligned, its departures read")
    physics: float = Field(0.0, description="Eq. 5.1 solved by least squares")
    simulate: float = Field(0.0, description="the window's own dataset simulated")
    learn: float = Field(0.0, description="the network trained")
    assess: float = Field(0.0, description="both estimators on held-out simulations, weighed and blended")
    check: float = Field(0.0, description="the window simulated at the answer")
    report: float = Field(0.0, description="FSJ read at the answer, the notes and the document")
    total: float
    train: float | None = Field(None, description="deprecated alias of learn (ema-estimate/1 as first published)")
    predict: float | None = Field(None, description="deprecated alias of assess (ema-estimate/1 as first published)")

    @model_validator(mode="before")
    @classmethod
    def _stage_names(cls, values: Any) -> Any:
        """Stages under their names; a result stored under the first names (train, predict) read as such, and the
        old names given beside the new ones for one schema version."""
        if isinstance(values, dict):
            values = dict(values)
            for new, old in (("learn", "train"), ("assess", "predict")):
                if values.get(new) is None and values.get(old) is not None:
                    values[new] = values[old]
                if values.get(new) is not None and values.get(old) is None:
                    values[old] = values[new]
        return values

    def stages(self) -> dict[str, float]:
        """Each stage's seconds, in order, under its one name."""
        return {stage: getattr(self, stage) for stage in STAGES}


class MethodReport(Document):
    """How one parameter's value was reached: each estimator, its error on held-out simulations, the blend."""

    physics: float = Field(description="Eq. 5.1 least squares on the window")
    physics_bias: float = Field(
        description="its mean error on held-out simulations, shrunk by how well they resolve it (James–Stein); "
        "subtracted"
    )
    physics_std: float = Field(description="its block-jackknife std on the window")
    network: float | None = Field(description="the window's own network; null if it was not used")
    weight_network: float
    rms_error_physics: float = Field(description="on held-out simulations of this window")
    rms_error_network: float | None
    rms_error_blend: float
    network_note: OptionalNote = Field(None, description="why the network's answer was not used, or not alone")


class Check(Document):
    """The check stage: the answer checked against the measured window itself."""

    reproduced: bool = Field(description="the model at these estimates reproduces the window within its noise")
    equation_error_ratio: float = Field(
        description="RMS of the window's Eq. 5.1 residual over what sensor noise alone leaves in simulations (≈ 1)"
    )
    equation_error_limit: float | None = Field(
        None,
        description="the ratio a window the model explains exceeds 1 % of the time (the held-out simulations' own "
        "spread): beyond it the note model_misfit says the model lacks something (null: not tested)",
    )
    output_error_ratio: dict[str, float] = Field(
        description="per signal: RMS(measured − simulated at the estimates) over the noise-only floor"
    )
    output_error_pct: dict[str, float] = Field(
        default_factory=dict,
        description="per signal: 100·‖measured − simulated‖/‖measured‖, the identification benchmarks' error "
        "(a servo's; empty where not computed)",
    )
    mean_abs_error: dict[str, float] = Field(
        default_factory=dict,
        description="per signal: mean |measured − simulated at the estimates|, in the signal's unit (a geared servo's "
        "position, rad; empty where not computed)",
    )
    uncertainty_inflation: float = Field(description="factor applied to the stds for what the model did not reproduce")
    notes: Notes = Field(default_factory=list)


class DatasetInfo(Document, EarlierCheckWindows):
    n_simulations: int
    n_timesteps: int
    inputs: list[str]
    check_simulations: int = Field(description="the held-out simulations that score the estimators")
    noise_estimated: dict[str, float]
    box: dict[str, tuple[float, float]] = Field(description="the FDJ and η_O intervals the simulations were drawn in")


class LearnedInfo(Document):
    """What the learn stage's network did: its epochs, why it stopped, its errors, its size."""

    epochs: int
    stop_reason: str
    val_mse: float
    test_mse: float
    members: int
    hidden_units: int


class ActuatorRead(Document):
    """The ``ema-actuator/1`` document a window was read with."""

    name: str
    version: int | None = Field(None, description="the service's stored version (null: given in-process)")
    default: bool = Field(False, description="no document was given for the actuator: the thesis's was used")


class Estimate(Document):
    """``ema-estimate/1``."""

    schema_: Literal["ema-estimate/1"] = Field("ema-estimate/1", alias="schema")
    actuator_id: str
    window_id: str
    actuator: ActuatorRead = Field(
        default_factory=lambda: ActuatorRead(name="thesis elevator EMA (Table 3.1)", default=True),
        description="the actuator's document it was read with (results stored before documents: the thesis's)",
    )
    estimates: Estimates
    fsj_note: AnyNote = Field(description="how FSJ was read, or why not")
    irreversible: bool = Field(description="η_A < 0: the load can never back-drive the transmission (thesis Case 1C)")
    notes: Notes = Field(default_factory=list, description="what a reader of this answer should know")
    timings_s: Timings
    stages: dict[str, str] = Field(
        default_factory=dict,
        description="each stage of the pipeline (STAGES): 'run', or 'skipped: ' and why (a window logged under 1 kHz "
        "is read quasi-statically: no simulation, network or check against a 1 µs simulation)",
    )
    dataset: DatasetInfo | None = Field(description="the window's own simulations (null: skipped, see stages)")
    learned: LearnedInfo | None = Field(
        None, description="what the learn stage's network did (null: skipped, see stages)"
    )
    training: LearnedInfo | None = Field(
        None, description="deprecated alias of learned (ema-estimate/1 before the stage's name)"
    )
    methods: dict[str, MethodReport]
    check: Check = Field(description="the window simulated at the answer, against the log (the check stage)")
    fit_check: Check | None = Field(None, description="deprecated alias of check (ema-estimate/1 as first published)")
    window: WindowInfo | RotaryWindowInfo = Field(
        description="what the reading did with the window: every kind's facts, and a rotary window's prepare stage"
    )
    config: PipelineConfig

    @model_validator(mode="before")
    @classmethod
    def _under_their_stages(cls, values: Any) -> Any:
        """The check and the network's learning under their stages' names; a result stored under the earlier ones
        (``fit_check``, ``training``) read as such, and the old names given beside the new ones for one schema
        version."""
        if isinstance(values, dict):
            values = dict(values)
            for new, old in (("check", "fit_check"), ("learned", "training")):
                values.setdefault(new, values.get(old))
                if values.get(old) is None:
                    values[old] = values[new]
        return values


def parameter(
    value: float,
    std: float | None,
    nominal: float | None,
    weak: bool = False,
    *,
    unit: str | None,
    repeatability_std: float | None = None,
    either_sign: bool = False,
) -> ParameterEstimate:
    """One parameter's estimate; its repeatability std is the whole std unless the document's constants share a
    part of it (a stepper's: ``ema.estimate.quasistatic.stretches``). A constant of ``either_sign`` (an offset)
    has no drift in %: near zero, a share of its nominal is noise."""
    drift = None
    if nominal is not None and nominal != 0 and not either_sign:
        drift = 100.0 * (value - nominal) / nominal
    repeatable = std if repeatability_std is None else repeatability_std
    return ParameterEstimate(
        value=value,
        std=std,
        nominal=nominal,
        drift_pct=drift,
        weakly_determined=weak,
        unit=unit,
        repeatability_std=repeatable,
    )
