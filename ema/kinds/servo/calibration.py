"""``ema calibrate`` for a servo: learn what the document lacks, then find what the model still misses, name it,
add it, and report the error before and after.

1. **Learn.** Eq. 5.1 in the load frame (``ema.kinds.servo.inverse``) over every window at once: M, C,
   FDJ and the offset, each with its Newey–West std and unit (``learned``); the model's error is the
   identification benchmarks' own, 100·‖y − ŷ‖/‖y‖ on the decimated force.
2. **Find**, where there is something to find: rows where a force the log lacks disturbs the solution are left out
   (``ema.kinds.servo.inverse.disturbed_rows``), and the windows' residual must stand beyond what noise
   alone leaves, the same solution on ``COPIES`` noise-only copies (each window simulated in closed loop at the learned
   constants, its sensor read at another phase of its step), at a 1 % false alarm (``misfit_limit``). Then each
   effect of
   ``ema.kinds.servo.load_effects`` is solved on four fifths of every window and
   predicts the fifth left out, in turn (its nonlinear constant chosen the same way). An effect is taken only
   where it is physical (its constants' signs), predicts every fold better (a real effect shows in each part
   of a log, noise does not), cuts the held-out residual by ``MIN_HELD_OUT_DROP`` at least, and by ``NAME_Z``
   stds beyond what it cuts on the noise-only copies (its score, z, as every kind reports it: a term with a free
   constant gains on any log, and the copies show how much); then the next, on top of it, up to ``MAX_EFFECTS``.
3. **Add and report.** The learned list is one consistent model: the adopted effects' constants join it, a
   constant that differs with the direction of motion named ``_up`` and ``_down``. The document keeps them as
   the simulator takes them (``simulator_frame``: Eq. 5.1 reads a simulated pre-sliding smaller than it is). The
   error before and after is the inverse model's at the solution's constants, and the closed loop's at the
   simulator's: each window simulated, its force against the log's.

Where the document already holds the load's constants (a completed document read on a new run), the report
also gives the error of the document's model as it stands, in the inverse and in the closed loop.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ema.calibration.documents import (
    Candidate,
    HeldOut,
    Learned,
    NoiseFloor,
    ServoCalibration,
    Step,
)
from ema.calibration.limits import MAX_EFFECTS, NAME_Z, noise_z
from ema.calibration.plot import ResidualPlot, Series
from ema.estimate.assess.weighing import misfit_limit
from ema.estimate.stats import rms
from ema.kinds.servo.effect_readings import MIN_HELD_OUT_DROP, Reading, best_of, reading
from ema.kinds.servo.fold_errors import amplitudes, closed_loop_error_pct, document_check
from ema.kinds.servo.inverse import (
    UNITS,
    decimated,
)
from ema.kinds.servo.load_effects import LOAD_EFFECTS, ServoEffect, looked_for
from ema.kinds.servo.log_reading import ServoPrepared, document_effects, prepare_servo, refuse_reversed_signs
from ema.kinds.servo.stacked_solve import (
    COPIES,
    FOLDS,
    FRAME_PHASES,
    Solved,
    left_out_alike,
    noise_copies,
    problem,
    simulator_frame,
    solved,
    undisturbed,
)
from ema.model.actuator import Nominal, ServoActuator
from ema.model.checks import InputError
from ema.model.window import ServoWindow

CLOSED_LOOPS = COPIES + 2 * FRAME_PHASES + 2  # per window: noise copies, twins before and after, the errors
FORCES_ALONG_TRAVEL = ("position_force", "turn_ripple")  # effects that follow the position, not the speed
LEARNED_NAMES = {
    "fdj_n": "FDJ",
    "mass_kg": "mass",
    "viscous_ns_per_m": "viscous",
    "viscous_up_ns_per_m": "viscous_up",
    "viscous_down_ns_per_m": "viscous_down",
    "offset_n": "offset",
}


def null_drops(
    effect: ServoEffect, copies: Sequence[Sequence[ServoPrepared]], model: dict[str, float], without: np.ndarray
) -> np.ndarray:
    """(COPIES,) the held-out drop the effect gives on each noise-only copy (``without``: each copy's held-out residual
    with ``model`` alone), at its best grid value there as on the logs (the freedom of choosing is in the floor): what
    it gains where nothing is missing."""
    with_it = np.array([best_of(effect, twins, model)[1].held_out_rss.sum() for twins in copies])
    return 1.0 - with_it / without


def _candidate(read: Reading, base: Solved, null: np.ndarray) -> tuple[Candidate, bool]:
    """The reading as the report lists it, scored by its z against the noise-only copies' drops (``null``), and
    whether it earns its place (held by the logs, and that far beyond what noise alone gains)."""
    z = float(noise_z(read.drop, float(null.mean()), float(null.std(ddof=1))))
    solution, effect = read.solution, read.effect
    parameters = {name: solution.values[name] for name in solution.values if name not in base.values}
    if effect.constant is not None:
        parameters[effect.constant[0]] = read.value
    candidate = Candidate(
        effect=effect.name,
        follows="position_m" if effect.name in FORCES_ALONG_TRAVEL else "speed_mps",
        named=True,
        parameters=parameters,
        rms_reduction=float(1.0 - solution.error_pct / base.error_pct),
        held_out_drop=read.drop,
        score=z,
        plausible=read.plausible,
    )
    return candidate, read.held and z >= NAME_Z


def select(
    prepared: Sequence[ServoPrepared], base_model: dict[str, float], copies: Sequence[Sequence[ServoPrepared]]
) -> tuple[dict[str, float], list, list]:
    """The effects adopted on top of ``base_model``, every candidate considered (its score its z against the noise-only
    ``copies``), and the steps' reasons."""
    model, candidates, steps = dict(base_model), [], []
    current = solved(problem(prepared, model))
    for _ in range(MAX_EFFECTS):
        trials = []
        without = np.array([solved(problem(twins, model)).held_out_rss.sum() for twins in copies])
        for effect in looked_for(prepared[0].servo, model):
            read = reading(effect, prepared, model, current)
            candidate, earned = _candidate(read, current, null_drops(effect, copies, model, without))
            candidates.append(candidate)
            trials.append((read.drop, earned, effect, read.value, read.solution, candidate.score))
        earned_trials = [t for t in trials if t[1]]
        if not earned_trials:
            steps.append(Step(selected=None, reason=_nothing_earned(trials)))
            break
        drop, _, effect, value, solution, z = max(earned_trials, key=lambda t: t[0])
        model[effect.name], current = value, solution
        steps.append(
            Step(
                selected=effect.name,
                reason=f"{effect.description}: predicts every fifth of the log(s) left out better, "
                f"{100 * drop:.0f} % less held-out residual, {z:.0f} noise-floor stds beyond what noise-only copies "
                "gain; its constants are physical",
            )
        )
    return model, candidates, steps


def _nothing_earned(trials: list) -> str:
    if not trials:
        return "every effect is in the model"
    best = max(trials, key=lambda t: t[0])
    return (
        f"no further effect earns its place: the best, {best[2].name}, cuts the held-out residual by "
        f"{100 * best[0]:.1f} % (at least {100 * MIN_HELD_OUT_DROP:.0f} % in every fold, {NAME_Z:g} noise-floor stds "
        "beyond what noise-only copies gain, with physical constants, is asked)"
    )


def learned(solution: Solved, model: dict[str, float], values: dict[str, float] | None = None) -> list[Learned]:
    """The model's constants (``values``, the solution's by default), each with the solution's std and its unit, in the
    document's words (``_up``/``_down`` by direction), the adopted effects' nonlinear constants beside them."""
    out = [
        Learned(name=LEARNED_NAMES.get(name, name), value=value, std=solution.stds[name], unit=UNITS[name])
        for name, value in (solution.values if values is None else values).items()
    ]
    for effect in LOAD_EFFECTS:
        if effect.name in model and effect.constant is not None:
            out.append(Learned(name=effect.constant[0], value=model[effect.name], std=0.0, unit=effect.constant[1]))
    return out


def completed(
    actuator: ServoActuator, prepared: ServoPrepared, solution: Solved, model: dict[str, float]
) -> ServoActuator:
    """The document with what the runs taught: the log's controller constants, the load's, the adopted effects,
    the nominal FDJ."""
    v, sd = solution.values, solution.stds
    split = "viscous_down_ns_per_m" in v
    up = "viscous_up_ns_per_m" if split else "viscous_ns_per_m"
    servo = prepared.servo.model_copy(
        update={
            "mass_kg": v["mass_kg"],
            "mass_std_kg": sd["mass_kg"],
            "viscous_ns_per_m": v[up],
            "viscous_std_ns_per_m": sd[up],
            "viscous_down_ns_per_m": v.get("viscous_down_ns_per_m"),
            "viscous_down_std_ns_per_m": sd.get("viscous_down_ns_per_m"),
            "force_offset_n": v["offset_n"],
            "force_offset_std_n": sd["offset_n"],
            "bandwidth_hz": prepared.bandwidth_hz,
            "effects": {name: value for name, value in model.items() if name != "viscous_down"},
            "effect_constants": amplitudes({name: v[name] for name in v if name not in LEARNED_NAMES}),
        }
    )
    nominal = Nominal(fdj_n=round(v["fdj_n"], 6), eta_o=actuator.nominal.eta_o if actuator.nominal else None)
    document = actuator.model_dump(by_alias=True) | {"servo": servo.model_dump(), "nominal": nominal.model_dump()}
    return ServoActuator.model_validate(document)


def _as_simulated(
    prepared: Sequence[ServoPrepared], before: tuple[Solved, dict[str, float]], after: tuple[Solved, dict[str, float]]
) -> tuple[dict[str, float], dict[str, float]]:
    """The constants after, as the simulator takes them (``simulator_frame``), and the closed loop's error before
    and after, each at its model's constants as the simulator takes them."""
    frames = {"before": simulator_frame(prepared, before[0].values, before[1])}
    frames["after"] = (
        frames["before"] if after[1] == before[1] else simulator_frame(prepared, after[0].values, after[1])
    )
    closed = {
        "before": closed_loop_error_pct(prepared, frames["before"], before[1]),
        "after": closed_loop_error_pct(prepared, frames["after"], after[1]),
    }
    return frames["after"], closed


def _plot(prepared: Sequence[ServoPrepared], base: Solved, after: Solved, model: dict[str, float]) -> ResidualPlot:
    """The decimated force's residual before and after, against the speed (what the effects follow)."""
    speed = np.concatenate([decimated(p.motion.speed_mps, p.motion.decimation)[p.motion.sliding] for p in prepared])
    return ResidualPlot(
        title=f"calibration: {', '.join(model) or 'no effect named'}",
        x_label="speed of the load [m/s]",
        y_label="force the model leaves [N]",
        series=[
            Series("before", speed.tolist(), base.residual.tolist()),
            Series("after", speed.tolist(), after.residual.tolist()),
        ],
    )


def _own_controller(prepared: ServoPrepared) -> ServoPrepared:
    """``prepared``, unless its log was run under another controller than the document's: every step of a
    calibration simulates the document's, and would trace the controllers' difference to the load."""
    for note in prepared.notes:
        if note.code == "controller_mismatch":
            raise InputError(
                f"window {prepared.window.window_id}",
                f"{note.text}; a calibration needs a document whose controller the log follows",
            )
    return prepared


def calibrate_servo(
    windows: Sequence[ServoWindow], actuator: ServoActuator
) -> tuple[ServoCalibration, ServoActuator, ResidualPlot]:
    """The report (module docstring), the document completed with what the windows taught, and the figure."""
    started = time.perf_counter()
    prepared = [_own_controller(prepare_servo(w, actuator)) for w in windows]
    base_model = document_effects(prepared[0].servo)
    first = solved(problem(prepared, base_model))
    refuse_reversed_signs(first.values, first.stds)
    copies = noise_copies(prepared, first, base_model)
    prepared = undisturbed(prepared, copies, base_model)
    base = solved(problem(prepared, base_model))
    ratio = rms(base.residual) / float(np.median(copies.rms))
    limit = misfit_limit(copies.rms)
    if ratio > limit:
        model, candidates, steps = select(prepared, base_model, left_out_alike(copies, prepared))
    else:
        model, candidates = dict(base_model), []
        steps = [
            Step(
                selected=None,
                reason=f"the residual is {ratio:.2f}x what noise alone leaves, within the "
                f"{limit:.2f}x a log the model explains reaches: nothing to trace",
            )
        ]
    after = solved(problem(prepared, model))
    adopted = [name for name in model if name not in base_model]
    simulated, closed = _as_simulated(prepared, (base, base_model), (after, model))
    report = ServoCalibration(
        n_windows=len(windows),
        noise_floor=NoiseFloor(copies=COPIES, equation_error_ratio=ratio),
        residual_rms_before={"drive_force_n": rms(base.residual)},
        residual_rms_after={"drive_force_n": rms(after.residual)},
        candidates=candidates,
        selected_effect=adopted[0] if adopted else None,
        selected_effects=adopted,
        selected_parameters={k: v for k, v in after.values.items() if k not in base.values} or None,
        effects={name: model[name] for name in adopted},
        selection_steps=steps,
        held_out=HeldOut(
            rss_before=float(base.held_out_rss.sum()),
            rss_after=float(after.held_out_rss.sum()),
            adopted=bool(adopted),
            note=f"each fifth of every window predicted from the other four: {FOLDS} folds",
        ),
        estimates_before={"FDJ": base.values["fdj_n"]},
        estimates_after={"FDJ": after.values["fdj_n"]},
        stds_before={"FDJ": base.stds["fdj_n"]},
        stds_after={"FDJ": after.stds["fdj_n"]},
        learned=learned(after, model),
        as_simulated=learned(after, model, simulated),
        model_error_pct_before={"drive_force_n": base.error_pct, "drive_force_n_closed_loop": closed["before"]},
        model_error_pct_after={"drive_force_n": after.error_pct, "drive_force_n_closed_loop": closed["after"]},
        model_error_pct_document=document_check(prepared, actuator),
        timings_s={"total": time.perf_counter() - started},
    )
    document = completed(actuator, prepared[0], replace(after, values=simulated), model)
    return report, document, _plot(prepared, base, after, model)
