"""A rotary window's stages' outputs -> its ``ema-estimate/1`` document: values, stds, what each stage found, in
words ("% of range" and "weakly determined" as every kind says them: ``ema.estimate.report``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ema.estimate.assess.weighing import Assessed
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import (
    DIMENSIONLESS,
    STAGES,
    TARGETS,
    ActuatorRead,
    Check,
    DatasetInfo,
    Estimate,
    Estimates,
    Note,
    RatioEstimate,
    Timings,
    parameter,
)
from ema.estimate.documents.window_facts import InertiaReading, RotaryWindowInfo, SensorZero
from ema.estimate.report import learned_info, share_of_range, weakly_determined
from ema.estimate.stats import rms
from ema.kinds.rotary.dataset import Data
from ema.kinds.rotary.physics.friction import FrictionSolution, sliding_mask
from ema.kinds.rotary.physics.static_friction import StaticFriction
from ema.kinds.rotary.prepare.conditioning import Prepared, conditioning_done, conditioning_notes
from ema.kinds.rotary.prepare.departures.drive_constants import KERNEL_FREE_RATE_HZ
from ema.kinds.rotary.simulator.hinge import denoised_hinge_nm
from ema.model.actuator import RotaryActuator

if TYPE_CHECKING:  # SciPy's optimizers: a window read without a network (quasi-static) never loads it
    from ema.kinds.rotary.network import NetworkEstimator


def _estimates(
    answer: Assessed, fsj: StaticFriction, eta_o_bound: bool, actuator: RotaryActuator, loaded: bool
) -> Estimates:
    """FDJ and η_O as assessed, η_A by Eq. 3.4 with the actuator's gear ratio (its std through the derivative),
    FSJ and FSD if read; each weakly determined where its std says so, and both where Eq. 5.1 put η_O at a
    bound (``eta_o_bound``): FDJ was read with η_O held there. Without a load (``loaded``) η_O and η_A are
    none: no load, no efficiency."""
    ranges, nominal = actuator.ranges, actuator.health
    eta_o, eta_o_std = answer.values["eta_O"], answer.stds["eta_O"]
    slope = float((actuator.eta_a(eta_o + 1e-6) - actuator.eta_a(eta_o - 1e-6)) / 2e-6)
    fdj = answer.values["FDJ"]
    ratio = None
    if fsj.value_nm is not None and fsj.std_nm is not None:
        relative = np.hypot(fsj.std_nm / fsj.value_nm, answer.stds["FDJ"] / fdj)
        ratio = RatioEstimate(value=fsj.value_nm / fdj, std=fsj.value_nm / fdj * relative)
    # η_A is η_O's through Eq. 3.4, and as weak; a bound of the search is no value, whatever its std: the solution
    # stops there for a reason it does not know (a unit, a departure), and FDJ with it where the window is loaded
    weak_eta = weakly_determined("eta_O", eta_o_std, ranges) or eta_o_bound
    weak_fdj = weakly_determined("FDJ", answer.stds["FDJ"], ranges) or (eta_o_bound and loaded)
    friction = actuator.facts.friction_unit
    eta_a = parameter(
        float(actuator.eta_a(eta_o)),
        abs(slope) * eta_o_std,
        float(actuator.eta_a(nominal.efficiency)),
        weak_eta,
        unit=DIMENSIONLESS,
    )
    return Estimates(
        FDJ=parameter(fdj, answer.stds["FDJ"], nominal.fdj, weak_fdj, unit=friction),
        eta_O=parameter(eta_o, eta_o_std, nominal.eta_o, weak_eta, unit=DIMENSIONLESS) if loaded else None,
        eta_A=eta_a if loaded else None,
        FSJ=None
        if fsj.value_nm is None
        else parameter(fsj.value_nm, fsj.std_nm, nominal.fsj or fsj.value_nm, unit=friction),
        FSD=ratio,
    )


def _notes(prepared: Prepared, physics: FrictionSolution, estimates: Estimates, check: Check) -> list[Note]:
    notes = [*check.notes, *conditioning_notes(prepared)]
    ranges = prepared.document.ranges
    for name in TARGETS:
        entry = getattr(estimates, name)
        if entry is not None and weakly_determined(name, entry.std, ranges):
            low, high = ranges.of(name)
            spread = share_of_range(name, 2 * entry.std, ranges)
            notes.append(
                Note(
                    code="weakly_determined",
                    parameter=name,
                    text=(
                        f"{name} is weakly determined by this window: ±2 std spans {100 * spread:.0f} % of the healthy "
                        f"range ({low:g}–{high:g}); a short window, a slow log or a hinge load that barely varies "
                        "holds little of it (trend it with its std)"
                    ),
                )
            )
    if estimates.eta_O is None:
        notes.append(
            Note(
                code="no_load",
                parameter="eta_O",
                text=(
                    "the window carries no load (its hinge moment at the motor moves the friction by under "
                    f"{100 * NO_LOAD_SHARE:g} % of the nominal FDJ at any efficiency): η_O and η_A cannot show, and "
                    "are not read; FDJ is read alone"
                ),
            )
        )
    elif physics.at_search_edge[0]:
        notes.append(
            Note(
                code="eta_o_at_bound",
                parameter="eta_O",
                text=(
                    "η_O lies at an end of the physical search range: read it as a bound, not a value, and FDJ, read "
                    "with "
                    "η_O held there, as weakly determined"
                ),
            )
        )
    if estimates.FDJ.value <= 0:
        text = "FDJ ≤ 0 is not a friction: the model does not describe this window (see check)"
        notes.append(Note(code="fdj_not_friction", parameter="FDJ", text=text))
    if estimates.eta_A is not None and estimates.eta_A.value < 0:
        text = "η_A < 0: the transmission is irreversible (the load cannot back-drive it; thesis Case 1C)"
        notes.append(Note(code="irreversible", parameter="eta_A", text=text))
    return notes


NO_LOAD_SHARE = 0.02  # a load term under this share of the nominal FDJ: the window carries no load


def carries_load(prepared: Prepared) -> bool:
    """Whether a window on the ground carries a load that can show η_O: its opposing term (1/η_O − 1)·|H/n| at
    the nominal η_O, its RMS over the samples Eq. 5.1 reads, reaches ``NO_LOAD_SHARE`` of the nominal FDJ. A
    pre-flight sweep logs only its gauge's noise there, a bench load more. In flight the air always loads the
    surface: a window that holds little of it says η_O is weakly determined instead."""
    document, w = prepared.document, prepared.window
    if not w.on_ground:
        return True
    load_nm = denoised_hinge_nm(w.signals["hinge_moment_nm"], w.signals["position_deg"], w.sample_rate_hz)
    sliding = sliding_mask(w.signals, w.sample_rate_hz, document.params)
    if not np.any(sliding):
        return True  # nothing slides: the physics solution refuses the window, not this rule
    term = (1.0 / document.health.efficiency - 1.0) * rms(load_nm[sliding] / document.gear_ratio)
    return bool(term >= NO_LOAD_SHARE * document.health.fdj)


def _window_info(prepared: Prepared, data: Data, digest: str) -> RotaryWindowInfo:
    """The window as logged, and what conditioning did to it."""
    w, offset, drive = prepared.window, prepared.departures.offset, prepared.departures.drive
    zero = SensorZero(
        window_id=w.window_id, hinge_nm=offset.hinge_nm, current_a=offset.current_a, torque_std_nm=offset.zero_std_nm
    )
    inertia = None
    # told apart from γ by the window itself, and moving both ways: a window moving one way holds too little to
    # read J_M for the actuator (a one-way window reads it poorly), and the history keeps it;
    # and processed fast enough that the kernel reads no bias every window would share (``KERNEL_FREE_RATE_HZ``)
    unbiased = w.sample_rate_hz >= KERNEL_FREE_RATE_HZ
    if drive.inertia_kgm2 and not prepared.departures.inertia_from and not offset.one_way and unbiased:
        std = drive.stds["inertia_kgm2"] / drive.spec.inertia_kgm2
        inertia = InertiaReading(factor=drive.inertia_factor, std=std, window_ids=[w.window_id])
    return RotaryWindowInfo.logged(
        w,
        digest,
        n_samples=prepared.original_samples,  # as logged, before averaging
        duration_s=prepared.original_samples / prepared.original_rate_hz,
        sample_rate_hz=prepared.original_rate_hz,
        processed_rate_hz=w.sample_rate_hz,
        **conditioning_done(prepared),
        sliding_fraction=float(np.mean(data.sliding)),
        sensor_zero=zero if offset.read else None,
        sensor_zero_from=offset.carried_from,
        inertia_read=inertia,
    )


def estimate_document(
    *,
    prepared: Prepared,
    physics: FrictionSolution,
    data: Data,
    network: NetworkEstimator,
    answer: Assessed,
    check: Check,
    fsj: StaticFriction,
    config: PipelineConfig,
    digest: str,
    read_with: ActuatorRead,
) -> Estimate:
    """The document of one window's run (its timings are the caller's to fill in: the report is a stage too);
    ``digest``: the window's content as posted (``Window.content_sha256``), ``read_with``: the actuator's document
    it was read with."""
    w = prepared.window
    loaded = carries_load(prepared)
    estimates = _estimates(answer, fsj, bool(physics.at_search_edge[0]), prepared.document, loaded)
    first = network.members_[0]
    notes = _notes(prepared, physics, estimates, check)
    if read_with.default:
        text = f"read with the default actuator ({read_with.name}): no ema-actuator/1 document was given for "
        notes.insert(0, Note(code="default_actuator", text=text + w.actuator_id))
    return Estimate(
        actuator_id=w.actuator_id,
        window_id=w.window_id,
        actuator=read_with,
        estimates=estimates,
        fsj_note=fsj.reason,
        irreversible=estimates.eta_A is not None and estimates.eta_A.value < 0,
        notes=notes,
        timings_s=Timings(total=0.0),
        stages=dict.fromkeys(STAGES, "run"),
        dataset=DatasetInfo(
            n_simulations=config.n_simulations,
            n_timesteps=data.inputs.shape[1],
            inputs=["residual_torque, sliding samples"],
            check_simulations=config.check_simulations,
            noise_estimated=data.noise.as_dict(),
            box={"FDJ": data.box.fdj_nm, "eta_O": data.box.eta_o},
        ),
        learned=learned_info(first, config),
        methods=answer.methods,
        check=check,
        window=_window_info(prepared, data, digest),
        config=config,
    )
