"""A geared servo's window -> ``ema-estimate/1``, every stage of the method at the output shaft.

1. **prepare** (``ema.kinds.geared.log_reading``): the log's constants and the document's, the supply repaired, the
   log's faults said;
2. **physics** (``ema.kinds.geared.output_error``): FDJ, η_O and η_A solved so that the window's set point, run in
   closed loop, follows its logged position; stds from the residual, its correlation counted;
3. **simulate** (``ema.kinds.geared.dataset``): the set point run at health drawn around that reading, each run
   logged as the window was (the encoder's step, the window's own misfit); the held-out runs read by physics;
4. **learn**: the shallow network from the simulated position error to the health;
5. **assess** (``ema.estimate.assess.weighing``): both estimators on the held-out runs, blended per parameter;
6. **check**: the window simulated at the answer, its position against the log's, in rad, against how far the
   calibrated model leaves a healthy run (the document's ``position_error_rad``);
7. **report**: FDJ in N·m at the output, η_O and η_A, each std widened by the document's repeatability (what a
   healthy run of this servo reads beyond its own noise).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

import ema.estimate.documents as doc
from ema.estimate.assess.weighing import Assessed, Candidates, assess, misfit_limit
from ema.estimate.config import PipelineConfig
from ema.estimate.documents.window_facts import WindowInfo
from ema.estimate.learn.estimator import NetworkRegressor, trained
from ema.estimate.report import learned_info, weakly_determined
from ema.estimate.stats import MAX_RATIO, rms
from ema.estimate.stopwatch import Stopwatch
from ema.kinds.geared.dataset import GearedData, simulate_geared_dataset
from ema.kinds.geared.log_reading import HEALTH, GearedPrepared, prepare_geared
from ema.kinds.geared.loop import simulate_lanes
from ema.kinds.geared.output_error import HealthReading, read_health
from ema.model.actuator import GearedActuator
from ema.model.window import GearedWindow

REPORTED = {"fdj_nm": "FDJ", "eta_o": "eta_O", "eta_a": "eta_A"}
UNITS = {"fdj_nm": "N·m", "eta_o": doc.DIMENSIONLESS, "eta_a": doc.DIMENSIONLESS}


def held_out_physics(
    prepared: GearedPrepared, data: GearedData, reading: HealthReading, n: int
) -> tuple[np.ndarray, np.ndarray]:
    """(K, 3) physics on each held-out run, and (K,) its residual RMS [rad]."""
    values, residuals = [], []
    for logged in data.position_rad[n:]:
        held = read_health(prepared, logged=logged, start=reading.values)
        values.append([held.values[name] for name in HEALTH])
        residuals.append(rms(held.error_rad))
    return np.array(values), np.array(residuals)


def learned(data: GearedData, config: PipelineConfig) -> NetworkRegressor:
    n = config.n_simulations
    return trained(data.inputs[:n], data.normalize(data.truth[:n]), config)


def assessed(
    reading: HealthReading, data: GearedData, network: NetworkRegressor, check: tuple[np.ndarray, np.ndarray], n: int
) -> Assessed:
    """Physics and the network weighed on the held-out runs; the window's residual over theirs tests the misfit
    (they carry the window's own, so a window the model reads as it reads its simulations sits near 1)."""
    check_physics, check_rms = check
    unit = network.predict_unit(np.vstack([data.inputs[n:], data.window_inputs]))
    values = data.denormalize(unit)
    candidates = Candidates(
        physics=dict(reading.values),
        physics_std=dict(reading.stds),
        network={name: float(values[-1, i]) for i, name in enumerate(HEALTH)},
        network_unit=unit[-1],
        check_truth={name: data.truth[n:, i] for i, name in enumerate(HEALTH)},
        check_physics={name: check_physics[:, i] for i, name in enumerate(HEALTH)},
        check_network={name: values[:-1, i] for i, name in enumerate(HEALTH)},
        targets=HEALTH,
        physics_std_source="residual",
    )
    ratio = rms(reading.error_rad) / max(float(np.median(check_rms)), 1e-300)
    return assess(candidates, ratio, misfit_limit(check_rms))


PHYSICAL = {"fdj_nm": (1e-6, np.inf), "eta_o": (0.1, 0.999), "eta_a": (-0.99, 0.999)}  # the reading's bounds


def within_physics(answer: Assessed) -> Assessed:
    """The answer with a value the blend carried past what is physical (an efficiency of 1 or more, a friction of
    0) held at that end, and said (``eta_o_at_bound``): a bound, not a reading past it."""
    values, notes = dict(answer.values), list(answer.notes)
    for name, (low, high) in PHYSICAL.items():
        if not low <= values[name] <= high:
            held = min(max(values[name], low), high)
            notes.append(
                doc.Note(
                    code="eta_o_at_bound",
                    parameter=REPORTED[name],
                    text=f"{REPORTED[name]} read {values[name]:.4g}, past what is physical: held at {held:g} (a "
                    "bound, not a value; the run holds little of it)",
                )
            )
            values[name] = held
    return replace(answer, values=values, notes=notes)


def closed_loop_check(prepared: GearedPrepared, answer: Assessed) -> doc.Check:
    """The window simulated at the answer: its position's mean absolute error [rad] (and at the document's nominal
    health: what the document alone predicts of the run), RMS over the calibrated model's floor on healthy runs
    (``position_error_rad``, a mean absolute error, as RMS of a normal residual: × √(π/2)), and in % of the
    position."""
    lanes = np.stack([prepared.lane(answer.values), prepared.lane(prepared.nominal)])
    simulated = simulate_lanes(prepared.run, lanes).position_rad
    error, at_nominal = prepared.position_rad - simulated[0], prepared.position_rad - simulated[1]
    floor = (prepared.geared.position_error_rad or 0.0) * np.sqrt(np.pi / 2)
    ratio = rms(error) / max(floor, prepared.resolution_rad / np.sqrt(12.0), 1e-300)
    notes = list(answer.notes)
    if ratio > MAX_RATIO:
        notes.append(
            doc.Note(
                code="not_reproduced",
                text=f"simulated at these estimates, the position lies {np.mean(np.abs(error)):.3g} rad from the "
                f"log on average, {ratio:.1f}x what the calibrated model leaves a healthy run: the window holds "
                "something the model lacks (ema calibrate traces it)",
            )
        )
    pct = 100.0 * float(np.linalg.norm(error)) / max(float(np.linalg.norm(prepared.position_rad)), 1e-300)
    return doc.Check(
        reproduced=ratio <= MAX_RATIO,
        equation_error_ratio=answer.inflation,
        equation_error_limit=None,
        output_error_ratio={"position_rad": ratio},
        output_error_pct={"position_rad": pct},
        mean_abs_error={
            "position_rad": float(np.mean(np.abs(error))),
            "position_rad_at_nominal": float(np.mean(np.abs(at_nominal))),
        },
        uncertainty_inflation=answer.inflation,
        notes=notes,
    )


def _estimates(prepared: GearedPrepared, answer: Assessed) -> doc.Estimates:
    """FDJ, η_O and η_A against the nominal, each std widened by the document's repeatability, and weakly
    determined where ±2 std span over a tenth of its healthy range (η_A judged against η_O's)."""
    repeatability = prepared.geared.repeatability
    entries = {}
    for name in HEALTH:
        std = float(np.hypot(answer.stds[name], repeatability.get(name, 0.0)))
        weak = weakly_determined("FDJ" if name == "fdj_nm" else "eta_O", std, prepared.ranges)
        entries[REPORTED[name]] = doc.parameter(
            answer.values[name], std, prepared.nominal[name], weak, unit=UNITS[name], repeatability_std=std
        )
    return doc.Estimates(FSJ=None, **entries)


def _report(
    prepared: GearedPrepared,
    data: GearedData,
    network: NetworkRegressor,
    answer: Assessed,
    check: doc.Check,
    *,
    read_with: doc.ActuatorRead,
    config: PipelineConfig,
) -> doc.Estimate:
    window = prepared.window
    s = window.signals
    return doc.Estimate(
        actuator_id=window.actuator_id,
        window_id=window.window_id,
        actuator=read_with,
        estimates=_estimates(prepared, answer),
        fsj_note=doc.Note(
            code="fsj_no_break_away",
            text="a geared servo's static friction is not read per run: its loop never lets the shaft rest under a "
            "slowly rising torque (ema calibrate tries a static friction over the runs)",
        ),
        irreversible=answer.values["eta_a"] < 0,
        notes=[*prepared.notes, *check.notes],
        timings_s=doc.Timings(total=0.0),  # the caller's stopwatch sets them
        stages=dict.fromkeys(doc.STAGES, "run"),
        dataset=doc.DatasetInfo(
            n_simulations=config.n_simulations,
            n_timesteps=data.inputs.shape[1],
            inputs=["position_rad"],
            check_simulations=config.check_simulations,
            noise_estimated={"position_resolution_rad": prepared.resolution_rad},
            box={
                REPORTED[name]: (float(lo), float(hi)) for name, lo, hi in zip(HEALTH, data.low, data.high, strict=True)
            },
        ),
        learned=learned_info(network.members_[0], config),
        methods={REPORTED[name]: report for name, report in answer.methods.items()},
        check=check,
        window=WindowInfo.logged(
            window,
            window.content_sha256(),
            processed_rate_hz=window.sample_rate_hz,
            command_clipped_fraction=float(np.mean(np.abs(s["duty_ratio"]) >= prepared.geared.duty_limit)),
            sliding_fraction=float(np.mean(np.diff(s["position_rad"], prepend=s["position_rad"][0]) != 0)),
        ),
        config=config,
    )


def estimate_geared(
    window: GearedWindow,
    config: PipelineConfig,
    *,
    actuator: GearedActuator,
    read_with: doc.ActuatorRead,
    on_stage: Callable[[str], None] | None = None,
) -> doc.Estimate:
    """The ``ema-estimate/1`` result of a geared servo's window, every stage run and timed (module docstring)."""
    watch, n = Stopwatch(on_stage), config.n_simulations
    with watch("prepare", "reading the log's constants and the document's, repairing the supply"):
        prepared = prepare_geared(window, actuator)
    with watch("physics", "reading FDJ, η_O and η_A by simulating the window's set point in closed loop"):
        reading = read_health(prepared)
    with watch("simulate", f"simulating {config.total_simulations} runs of the window's set point in closed loop"):
        data = simulate_geared_dataset(prepared, reading, config)
        check = held_out_physics(prepared, data, reading, n)
    with watch("learn", f"learning {config.members} network(s) of {config.hidden_units} neurons"):
        network = learned(data, config)
    with watch("assess", "weighing the estimators on held-out simulations"):
        answer = within_physics(assessed(reading, data, network, check, n))
    with watch("check", "simulating the window at the answer"):
        verdict = closed_loop_check(prepared, answer)
    with watch("report", "writing the report"):
        document = _report(prepared, data, network, answer, verdict, read_with=read_with, config=config)
    return document.model_copy(update={"timings_s": watch.timings()})
