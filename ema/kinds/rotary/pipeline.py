"""Window -> ``ema-estimate/1``: what ``ema estimate``, the service and the fleet call.

The thesis's §6.3 proposal, made to hold on data our simulator did not draw:

1. **prepare**: repair, average, align and zero the window's sensors, read its viscous coefficient
   (``ema.kinds.rotary.prepare.conditioning``);
2. **physics**: solve Eq. 5.1 by least squares (``ema.kinds.rotary.physics.friction``), a block-jackknife std beside;
3. **simulate**: a Case-1B dataset of the window's own command, logged load and first state, its
   health drawn in a box around the physics estimate (``ema.kinds.rotary.box``: no fixed range, so no
   cap on a worn actuator), with the window's own sensor noise;
4. **learn**: the shallow network on the residual torque of the sliding samples (``learned``);
5. **assess**: both estimators scored on held-out simulations and blended per parameter, checked against the
   window itself (``assessed``, ``ema.estimate.assess.weighing``);
6. **check**: the window simulated at the answer (``checked``, ``ema.kinds.rotary.reproduction``);
7. **report**: FSJ where the window shows a quasi-static break-away (``ema.kinds.rotary.physics.static_friction``),
   and the document.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ema.estimate.assess.weighing import Assessed, Candidates, assess, misfit_limit
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import ActuatorRead, Check, Estimate, Note
from ema.estimate.documents.window_facts import HistoryReadings
from ema.estimate.stats import MAX_RATIO, rms
from ema.estimate.stopwatch import Stopwatch
from ema.kinds.rotary.dataset import Data, simulate_dataset
from ema.kinds.rotary.network import NetworkEstimator
from ema.kinds.rotary.other_windows import known_from
from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.friction import SOLUTION_ARRAYS, FrictionSolution, solve_friction, solve_window
from ema.kinds.rotary.physics.scenario import inside
from ema.kinds.rotary.physics.static_friction import read_static_friction
from ema.kinds.rotary.prepare.conditioning import Prepared, prepare, widened
from ema.kinds.rotary.report import estimate_document
from ema.kinds.rotary.reproduction import output_error_ratios
from ema.model.actuator import THESIS, RotaryActuator
from ema.model.window import RotaryWindow, Window, as_window

# On a few dozen noisy simulations the network stops improving within a few epochs, and the physics solution
# carries most of the answer (ema.estimate.assess.weighing): the thesis's 12 failures and 1000 epochs made its time
# the pipeline's least predictable.


def learned(data: Data, config: PipelineConfig) -> NetworkEstimator:
    n = config.n_simulations
    health = data.sims.health
    return NetworkEstimator(config).fit(data.inputs[:n], health.fdj_nm[:n], health.eta_o[:n], data.box)


def candidates(
    window: RotaryWindow, physics: FrictionSolution, data: Data, network: NetworkEstimator, n: int
) -> tuple[Candidates, FrictionSolution]:
    """Physics and network on the window and on the held-out simulations (and the physics solution of those)."""
    held = {name: values[n:] for name, values in data.sims.signals.items()}
    check_physics = solve_friction(
        held, window.sample_rate_hz, data.drive_as_read, residual_nm=data.sims.residual_nm[n:]
    )
    unit = network.predict_unit(np.vstack([data.inputs[n:], data.window_inputs]))
    fdj, eta_o = data.box.denormalize(unit)
    health = data.sims.health
    # A held-out simulation that never slides long enough has no physics answer: left out, not poisoning the scores.
    ok = np.isfinite(check_physics.fdj_nm) & np.isfinite(check_physics.eta_o)
    check_physics = replace(check_physics, **{k: getattr(check_physics, k)[ok] for k in SOLUTION_ARRAYS})
    fdj_check, eta_check = fdj[:-1][ok], eta_o[:-1][ok]
    truth_fdj, truth_eta = health.fdj_nm[n:][ok], health.eta_o[n:][ok]
    return Candidates(
        physics={k: float(v) for k, v in physics.values().items()},
        physics_std={"FDJ": float(physics.fdj_std_nm[0]), "eta_O": float(physics.eta_o_std[0])},
        network={"FDJ": float(fdj[-1]), "eta_O": float(eta_o[-1])},
        network_unit=unit[-1],
        check_truth={"FDJ": truth_fdj, "eta_O": truth_eta},
        check_physics=check_physics.values(slice(None)),
        check_network={"FDJ": fdj_check, "eta_O": eta_check},
    ), check_physics


def checked(
    window: RotaryWindow,
    data: Data,
    answer: Assessed,
    physics: FrictionSolution,
    *,
    equation_ratio: float,
    n: int,
    nominal_fdj_nm: float,
) -> Check:
    """Simulate the window at the answer and compare (``ema.kinds.rotary.reproduction``). Where the answer is the
    point the noise was measured at (the physics estimate, when it carries the answer), that simulation is
    the one: a lane of the dataset's batch, the same numbers as a run of its own."""
    health = inside(answer.values["FDJ"], answer.values["eta_O"], nominal_fdj_nm)
    noise = rms((data.sims.residual_nm[n:] - data.sims.clean_residual_nm)[:, data.sliding])
    floor = float(np.hypot(noise, physics.resolution_nm[0]))  # a log without noise: the model's resolution
    known = data.sims.reference_signals if health.identical(data.sims.reference) else None
    ratios = output_error_ratios(
        window,
        data.scenario,
        health,
        noise=data.noise,
        residual_floor_nm=floor,
        sliding=data.sliding,
        drive=data.drive_as_read,
        simulated_at_health=known,
    )
    reproduced = ratios["residual_torque"] <= MAX_RATIO
    notes = list(answer.notes)
    if not reproduced:
        notes.append(
            Note(
                code="not_reproduced",
                text=(
                    f"simulated at these estimates, the window's residual torque differs by "
                    f"{ratios['residual_torque']:.1f}x "
                    "its noise floor: the model does not reproduce this window"
                ),
            )
        )
    return Check(
        reproduced=reproduced,
        equation_error_ratio=equation_ratio,
        output_error_ratio=ratios,
        uncertainty_inflation=answer.inflation,
        notes=notes,
    )


def assessed(
    window: RotaryWindow,
    physics: FrictionSolution,
    data: Data,
    network: NetworkEstimator,
    *,
    prepared: Prepared,
    n: int,
) -> tuple[Assessed, float, float]:
    """The assessed answer (its stds widened by what prepare left undecided), the window's equation error over
    its held-out simulations' median, and the misfit limit that ratio is held to."""
    found, check_physics = candidates(window, physics, data, network, n)
    errors = np.hypot(check_physics.residual_rms_nm, check_physics.resolution_nm)  # never under the resolution
    floor = np.median(errors) if len(errors) else np.nan
    equation_ratio = float(np.hypot(physics.residual_rms_nm[0], physics.resolution_nm[0]) / floor)
    equation_ratio = equation_ratio if np.isfinite(floor) else 1.0
    limit = misfit_limit(errors)
    answer = assess(found, equation_ratio, limit)
    return replace(answer, stds=widened(answer.stds, prepared)), equation_ratio, limit


def estimate_window(
    window: Window,
    config: PipelineConfig = PipelineConfig(),
    *,
    actuator: RotaryActuator,
    version: int | None = None,
    on_stage: Callable[[str], None] | None = None,
    spec_only: bool = False,
    history: HistoryReadings | None = None,
) -> Estimate:
    """The ``ema-estimate/1`` result for one window, its stages timed.

    ``actuator``: the document every stage reads its constants from (``ema.model.actuator.THESIS`` itself is the
    default a caller chose for a user who gave none, and the answer says so), ``version`` its stored
    version; ``on_stage`` hears each stage as it starts (and may raise to stop the job there);
    ``spec_only`` reads the window with the document's model alone, no departures taken off (calibration's
    base); ``history``: what other windows of the actuator lend this one (``ema.kinds.rotary.other_windows``). Raises
    InputError naming the field for a window that cannot be read, or of another kind.
    """
    window = as_window(window, RotaryWindow)
    watch = Stopwatch(on_stage)
    read_with = ActuatorRead(name=actuator.name, version=version, default=actuator is THESIS)
    with watch("prepare", "preparing the window"):
        digest = window.content_sha256()
        prepared = prepare(window, actuator, spec_only=spec_only, known=known_from(history))
        w, n = prepared.window, config.n_simulations
        seen = replace(w, signals=as_read(w.signals, w.sample_rate_hz))
    with watch("physics", "solving Eq. 5.1"):
        physics = solve_window(seen.signals, w.sample_rate_hz, prepared.drive_as_read)
    with watch("simulate", f"simulating {config.total_simulations} windows around the physics estimate"):
        effects = prepared.departures.viscosity.effects()
        data = simulate_dataset(
            w, seen, physics, config, document=actuator, drive=prepared.drive_as_read, effects=effects
        )
    with watch("learn", f"learning {config.members} network(s) of {config.hidden_units} neurons"):
        network = learned(data, config)
    with watch("assess", "weighing the estimators on held-out simulations"):
        answer, equation_ratio, limit = assessed(w, physics, data, network, prepared=prepared, n=n)
    with watch("check", "checking the answer against the window"):
        check = checked(
            seen, data, answer, physics, equation_ratio=equation_ratio, n=n, nominal_fdj_nm=actuator.health.fdj
        )
        check = check.model_copy(update={"equation_error_limit": limit})
    with watch("report", "reading FSJ at the answer, writing the report"):
        fsj = read_static_friction(
            seen.signals, w.sample_rate_hz, answer.values["FDJ"], answer.values["eta_O"], data.drive_as_read, data.noise
        )
        document = estimate_document(
            prepared=prepared,
            physics=physics,
            data=data,
            network=network,
            answer=answer,
            check=check,
            fsj=fsj,
            config=config,
            digest=digest,
            read_with=read_with,
        )
    return document.model_copy(update={"timings_s": watch.timings()})
