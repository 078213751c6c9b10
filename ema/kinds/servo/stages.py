"""A servo's window -> ``ema-estimate/1``, every stage of the method on a log taken on the load side.

1. **prepare** (``ema.kinds.servo.log_reading``): the document completed by the log's constants, the controller
   checked against the logged command, the motion read;
2. **physics** (``ema.kinds.servo.inverse``): Eq. 5.1 in the load frame, F = M·q̈ + FDJ·sgn(q̇) + C·q̇ +
   F_offset, by least squares, Newey–West stds;
3. **simulate** (``ema.kinds.servo.loop_dataset``): the window's own set point run in closed loop, its controller
   at its rate, at constants drawn around the physics estimate; the held-out runs read by physics, which screens
   the window (its equation error against theirs, the rows a force the log lacks disturbs);
4. **learn**: the shallow network from the simulated force to the constants (the training runs carrying the
   window's misfit where the screen says the model misses part of it);
5. **assess** (``ema.estimate.assess.weighing``): both estimators on held-out simulations, blended per
   constant, the window's equation error against the simulations';
6. **check**: the window simulated in closed loop at the answer, its force and position against the log's;
7. **report**: the document, FDJ in N (the load's friction), the other constants beside it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

import ema.estimate.documents as doc
from ema.estimate.assess.weighing import Assessed, Candidates, assess, misfit_limit
from ema.estimate.config import PipelineConfig
from ema.estimate.documents.window_facts import WindowInfo
from ema.estimate.learn.estimator import NetworkRegressor, trained
from ema.estimate.report import learned_info
from ema.estimate.stats import MAX_RATIO, RESOLUTION_SHARE, rms
from ema.estimate.stopwatch import Stopwatch
from ema.kinds.servo.effect_readings import held_readings, widened
from ema.kinds.servo.inverse import (
    EITHER_SIGN,
    UNITS,
    InverseSolution,
    disturbed_rows,
    inverse_columns,
    load_motion,
    solve_inverse,
)
from ema.kinds.servo.log_reading import ServoPrepared, prepare_servo, refuse_reversed_signs
from ema.kinds.servo.loop_dataset import ServoData, carrying, lane_parameters, simulate_servo_dataset, window_misfit
from ema.model.actuator import ServoActuator
from ema.model.window import ServoWindow

MISFIT_SEED_OFFSET = 7919  # the misfit's shifts and signs draw from the window's seed plus this: a stream of their own
CHECK_PHASES = (0.0, 0.5)  # the position sensor's phases of its step the check simulates: the answer's, its twin's
FDJ = "fdj_n"
NOMINAL_FIELDS = {  # a constant of the inverse model -> the servo section's field of its nominal value
    "mass_kg": "mass_kg",
    "viscous_ns_per_m": "viscous_ns_per_m",
    "viscous_up_ns_per_m": "viscous_ns_per_m",
    "viscous_down_ns_per_m": "viscous_down_ns_per_m",
    "offset_n": "force_offset_n",
}


def physics_of(prepared: ServoPrepared, left_out: np.ndarray | None = None) -> InverseSolution:
    """Eq. 5.1 solved to the window with the document's effects (less the ``left_out`` rows)."""
    return solve_inverse(
        prepared.force_n, inverse_columns(prepared.motion, prepared.effects), prepared.motion, left_out
    )


def held_out_physics(prepared: ServoPrepared, data: ServoData, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(K, T) the physics solution of each held-out simulation, (K,) its residual RMS and (K, rows) its residual by
    decimated row."""
    rate, values, rms, by_row = prepared.window.sample_rate_hz, [], [], []
    load = prepared.window.signals.get("load_n")
    for position, force in zip(data.runs.position_m[n:], data.runs.drive_force_n[n:], strict=True):
        motion = load_motion(position, rate, prepared.bandwidth_hz, prepared.loop.resolution_m)
        pushed = force if load is None else force - load
        solution = solve_inverse(pushed[motion.samples], inverse_columns(motion, prepared.effects), motion)
        values.append([solution.values[name] for name in data.targets])
        rms.append(solution.residual_rms_n)
        by_row.append(solution.residual_by_row)
    return np.array(values), np.array(rms), np.array(by_row)


def undisturbed(
    prepared: ServoPrepared, physics: InverseSolution, disturbed: np.ndarray
) -> tuple[InverseSolution, doc.Note | None]:
    """The physics solution again without the rows a force the log does not carry disturbs (``disturbed``: the
    window's residual beyond what its simulations leave there, ``disturbed_rows``), and a note saying how long they
    last."""
    if not disturbed.any():
        return physics, None
    seconds = int(disturbed.sum()) * prepared.motion.decimation / prepared.window.sample_rate_hz
    note = doc.Note(
        code="unlogged_force",
        parameter="drive_force_n",
        text=f"{seconds:.2f} s of the window hold a force far beyond what the model leaves there, which the log does "
        "not carry (a push on the load, a disturbance in the drive): left out of Eq. 5.1",
    )
    return physics_of(prepared, disturbed), note


@dataclass(frozen=True)
class Screened:
    """What the held-out simulations say of the window before the network learns: their physics solutions
    (K, T), the window's physics without the rows a force the log lacks disturbs (a note where it left some out),
    and its equation error over theirs with the limit past which the model misses part of it."""

    check_physics: np.ndarray
    physics: InverseSolution
    disturbed: doc.Note | None
    ratio: float
    limit: float
    left_out: np.ndarray  # (rows,) bool: the rows left out of the window's physics

    @property
    def misses(self) -> bool:
        """The model misses part of the window: its equation error beyond what its simulations reach."""
        return self.ratio > self.limit


def screened(prepared: ServoPrepared, physics: InverseSolution, data: ServoData, n: int) -> Screened:
    """The window screened by its ``n``-th and later (held-out) simulations (``Screened``)."""
    check_physics, check_rms, check_by_row = held_out_physics(prepared, data, n)
    left_out = disturbed_rows(physics.residual_by_row, check_by_row)
    physics, disturbed = undisturbed(prepared, physics, left_out)
    ratio = physics.residual_rms_n / float(np.median(check_rms))
    return Screened(check_physics, physics, disturbed, ratio, misfit_limit(check_rms), left_out)


def misfit_carried(
    prepared: ServoPrepared, data: ServoData, held: Screened, seed: int
) -> tuple[ServoData, doc.Note | None]:
    """``data`` as the network learns from it: carrying the window's own misfit where the model misses part of the
    window (``ema.kinds.servo.loop_dataset``), with a note of its size; else as simulated."""
    if not held.misses:
        return data, None
    misfit = window_misfit(prepared, held.physics, data.inputs.shape[1])
    share = 100.0 * rms(misfit) / max(rms(data.window_inputs), 1e-300)
    note = doc.Note(
        code="misfit_learned",
        text=f"the network learned its constants beside the window's own misfit ({rms(misfit):.3g} N RMS over "
        f"{len(misfit)} bins, {share:.1f} % of the force), added to every simulation at a random shift and sign: "
        "what the model misses of this window costs the network in its held-out errors, not in its answer",
    )
    return carrying(data, misfit, seed), note


def learned(data: ServoData, config: PipelineConfig) -> NetworkRegressor:
    n = config.n_simulations
    return trained(data.inputs[:n], data.normalize(data.truth[:n]), config)


def assessed(held: Screened, data: ServoData, network: NetworkRegressor, n: int) -> Assessed:
    """The assessed answer from the physics solution the held-out simulations screened (``held``: without the rows
    a force the log lacks disturbs; a note says so) and the network."""
    physics, check_physics = held.physics, held.check_physics
    unit = network.predict_unit(np.vstack([data.inputs[n:], data.window_inputs]))
    values = data.denormalize(unit)
    names = data.targets
    candidates = Candidates(
        physics={name: physics.values[name] for name in names},
        physics_std={name: physics.stds[name] for name in names},
        network={name: float(values[-1, i]) for i, name in enumerate(names)},
        network_unit=unit[-1],
        check_truth={name: data.truth[n:, i] for i, name in enumerate(names)},
        check_physics={name: check_physics[:, i] for i, name in enumerate(names)},
        check_network={name: values[:-1, i] for i, name in enumerate(names)},
        targets=names,
        physics_std_source="residual",
    )
    answer = assess(candidates, held.ratio, held.limit)
    said = [note for note in (held.disturbed, *answer.notes) if note is not None]
    return replace(answer, notes=said)


def _relative_error_pct(measured: np.ndarray, simulated: np.ndarray) -> float:
    return float(100.0 * np.linalg.norm(measured - simulated) / max(float(np.linalg.norm(measured)), 1e-300))


def closed_loop_check(prepared: ServoPrepared, answer: Assessed, ratio: float, limit: float) -> doc.Check:
    """The window simulated in closed loop at the answer: its force and position against the log's, in %, and the
    force's misfit over what the model's own noise allows: the same loop simulated again with its position sensor
    at another phase of its step differs from the first by that much (``noise_floor``). Two logs of one model
    differ so; a log the model reproduces differs from its simulation by as much, within ``MAX_RATIO``."""
    window, kept = prepared.window, prepared.motion.samples
    s = window.signals
    lanes = np.repeat(lane_parameters(answer.values, prepared.effects)[None, :], len(CHECK_PHASES), axis=0)
    runs = prepared.closed_loop(lanes, np.array(CHECK_PHASES))
    measured, simulated = s["drive_force_n"][kept], runs.drive_force_n[0, kept]
    force_ratio = rms(measured - simulated) / noise_floor(measured, runs.drive_force_n[:, kept])
    reproduced = force_ratio <= MAX_RATIO
    notes = list(answer.notes)
    if not reproduced:
        notes.append(
            doc.Note(
                code="not_reproduced",
                text=f"simulated in closed loop at these estimates, the drive's force differs from the log's by "
                f"{force_ratio:.1f}x what the model's own noise allows ({_relative_error_pct(measured, simulated):.1f} "
                "% of the force): the model lacks something this window holds (ema calibrate traces it)",
            )
        )
    return doc.Check(
        reproduced=reproduced,
        equation_error_ratio=ratio,
        equation_error_limit=limit,
        output_error_ratio={"drive_force_n": force_ratio},
        output_error_pct={
            "drive_force_n": _relative_error_pct(measured, simulated),
            "position_m": _relative_error_pct(s["position_m"][kept], runs.position_m[0, kept]),
        },
        uncertainty_inflation=answer.inflation,
        notes=notes,
    )


def noise_floor(measured: np.ndarray, twins: np.ndarray) -> float:
    """RMS [N] by which two simulations of one loop differ, ``twins`` (2, N) run with the position sensor at two
    phases of its step (the quantization a log carries), and never under ``RESOLUTION_SHARE`` of the force: how
    far a log the model reproduces may lie from its simulation."""
    return float(np.hypot(rms(twins[0] - twins[1]), RESOLUTION_SHARE * rms(measured))) or 1e-300


def _estimates(
    actuator: ServoActuator, prepared: ServoPrepared, physics: InverseSolution, answer: Assessed
) -> doc.Estimates:
    """FDJ in N against the document's nominal (none before ema calibrate), the other constants beside it (an
    effect's that the simulator lacks as the physics solution read it)."""
    nominal = None if actuator.nominal is None else actuator.nominal.fdj
    values, stds = {**physics.values, **answer.values}, {**physics.stds, **answer.stds}
    constants = {}
    for name in values:
        if name == FDJ:
            continue
        servo = prepared.servo
        document = getattr(servo, NOMINAL_FIELDS.get(name, ""), None) or servo.effect_constants.get(name)
        constants[name] = doc.parameter(
            values[name], stds[name], document, unit=UNITS[name], either_sign=name in EITHER_SIGN
        )
    return doc.Estimates(
        FDJ=doc.parameter(answer.values[FDJ], answer.stds[FDJ], nominal, unit=UNITS[FDJ]),
        eta_O=None,
        eta_A=None,
        FSJ=None,
        constants=constants,
    )


def _report(
    prepared: ServoPrepared,
    physics: InverseSolution,
    data: ServoData,
    network: NetworkRegressor,
    answer: Assessed,
    check: doc.Check,
    *,
    actuator: ServoActuator,
    read_with: doc.ActuatorRead,
    config: PipelineConfig,
) -> doc.Estimate:
    window, first = prepared.window, network.members_[0]
    return doc.Estimate(
        actuator_id=window.actuator_id,
        window_id=window.window_id,
        actuator=read_with,
        estimates=_estimates(actuator, prepared, physics, answer),
        fsj_note=doc.Note(
            code="fsj_no_break_away",
            text="a servo's static friction is not read: its drive never lets the load rest under a rising force",
        ),
        irreversible=False,
        notes=[*prepared.notes, *check.notes],
        timings_s=doc.Timings(total=0.0),  # the caller's stopwatch sets them
        stages=dict.fromkeys(doc.STAGES, "run"),
        dataset=doc.DatasetInfo(
            n_simulations=config.n_simulations,
            n_timesteps=data.inputs.shape[1],
            inputs=["drive_force_n"],
            check_simulations=config.check_simulations,
            noise_estimated={"position_resolution_m": prepared.loop.resolution_m},
            box={name: (float(lo), float(hi)) for name, lo, hi in zip(data.targets, data.low, data.high, strict=True)},
        ),
        learned=learned_info(first, config),
        methods={"FDJ" if name == FDJ else name: report for name, report in answer.methods.items()},
        check=check,
        window=WindowInfo.logged(
            window,
            window.content_sha256(),
            processed_rate_hz=window.sample_rate_hz / prepared.motion.decimation,
            command_clipped_fraction=0.0,
            sliding_fraction=float(np.mean(prepared.motion.sliding)),
        ),
        config=config,
    )


def estimate_servo(
    window: ServoWindow,
    config: PipelineConfig,
    *,
    actuator: ServoActuator,
    read_with: doc.ActuatorRead,
    on_stage: Callable[[str], None] | None = None,
) -> doc.Estimate:
    """The ``ema-estimate/1`` result of a servo's window, every stage run and timed (module docstring)."""
    watch, n = Stopwatch(on_stage), config.n_simulations
    with watch("prepare", "completing the document from the log, checking its controller"):
        prepared = prepare_servo(window, actuator)
    with watch("physics", "solving Eq. 5.1 on the load side"):
        physics = physics_of(prepared)
        refuse_reversed_signs(physics.values, physics.stds)
    with watch("simulate", f"simulating {config.total_simulations} runs of the window's set point in closed loop"):
        data = simulate_servo_dataset(prepared, physics, config)
        held = screened(prepared, physics, data, n)
    with watch("learn", f"learning {config.members} network(s) of {config.hidden_units} neurons"):
        data, carried = misfit_carried(prepared, data, held, config.seed + MISFIT_SEED_OFFSET)
        network = learned(data, config)
    with watch("assess", "weighing the estimators on held-out simulations"):
        answer, physics = assessed(held, data, network, n), held.physics
        # which effect the model lacks, one log cannot tell: the stds hold each one's reading
        answer, form = widened(answer, *held_readings(prepared, held.left_out)) if held.misses else (answer, None)
        answer = replace(answer, notes=[*answer.notes, *(note for note in (carried, form) if note)])
    with watch("check", "simulating the window at the answer"):
        check = closed_loop_check(prepared, answer, held.ratio, held.limit)
    with watch("report", "writing the report"):
        document = _report(
            prepared, physics, data, network, answer, check, actuator=actuator, read_with=read_with, config=config
        )
    return document.model_copy(update={"timings_s": watch.timings()})
