"""Window -> health estimates with uncertainty and timings: what ``ema estimate`` and the service call.

The thesis's §6.3 proposal: simulate a fresh Case-1B dataset for the window's own command, flight
condition and first state, with the window's own sensor noise; train; predict. A physics
least-squares fit of the same window runs beside it, and both are scored on held-out simulated
windows to blend them per parameter (``training.combine``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from sim.checks import InputError
from sim.effects import EffectSet
from sim.noise import SensorNoise, add_sensor_noise
from sim.params import DEFAULT_RANGES, HealthParams, eta_a_from_eta_o
from sim.window import Window
from training.baseline import FrictionLeastSquares
from training.combine import fit_blend
from training.dataset import DatasetConfig, Scenario, build_dataset, scenario_from_window, window_noise
from training.estimator import NetworkEstimator
from training.network import TrainConfig
from training.preprocess import INPUT_SETS, features

SCHEMA = "ema-estimate/1"
TARGETS = ("FDJ", "eta_O")
NOMINAL = {"FDJ": DEFAULT_RANGES.nominal_fdj_nm, "eta_O": DEFAULT_RANGES.nominal_eta_o}


@dataclass(frozen=True)
class PipelineConfig:
    n_simulations: int = 500
    n_timesteps: int = 1000
    hidden_units: int = 100
    members: int = 1  # networks in the ensemble
    input_set: str = "residual_torque"
    # Held-out simulated windows that score network and baseline. 16 instead of 32: 0.2 s faster,
    # errors within the spread of 5 bench windows (0.29 % / 0.07 % against 0.23 % / 0.09 %).
    check_windows: int = 16
    seed: int = 0
    train: TrainConfig = field(default_factory=TrainConfig)

    def __post_init__(self) -> None:
        if not 20 <= self.n_simulations <= 20_000:
            raise InputError("n_simulations", f"must be in [20, 20000], got {self.n_simulations}")
        if not 10 <= self.n_timesteps <= 10_000:
            raise InputError("n_timesteps", f"must be in [10, 10000], got {self.n_timesteps}")
        if not 1 <= self.hidden_units <= 2000:
            raise InputError("hidden_units", f"must be in [1, 2000], got {self.hidden_units}")
        if not 1 <= self.members <= 20:
            raise InputError("members", f"must be in [1, 20], got {self.members}")
        if not 8 <= self.check_windows <= 1000:
            raise InputError("check_windows", f"must be in [8, 1000], got {self.check_windows}")


def check_windows(
    scenario: Scenario, window: Window, noise: SensorNoise, n: int, seed: int
) -> tuple[HealthParams, list[Window]]:
    """Fresh health draws of the window's scenario, as noisy as the window: the scoring windows."""
    rng = np.random.default_rng(seed)
    health = HealthParams.uniform(n, DEFAULT_RANGES, rng)
    signals = add_sensor_noise(scenario.simulate(health).signals, noise, rng)
    windows = [
        Window({name: values[i] for name, values in signals.items()}, window.sample_rate_hz, window.flight_condition)
        for i in range(n)
    ]
    return health, windows


def baseline_fit(window: Window) -> FrictionLeastSquares | InputError:
    """The least-squares fit of a window, or the reason it cannot fit (too little sliding motion)."""
    try:
        return FrictionLeastSquares().fit(window)
    except InputError as exc:
        return exc


def baseline_values(fitted: FrictionLeastSquares | InputError) -> dict[str, float] | None:
    """FDJ and η_O of a baseline fit, or None where it abstained."""
    if isinstance(fitted, InputError):
        return None
    return {"FDJ": fitted.fdj_, "eta_O": fitted.eta_o_}


def network_values(network: NetworkEstimator, windows: list[Window], config: PipelineConfig) -> dict[str, np.ndarray]:
    """The network's FDJ and η_O for each window."""
    stacked = {name: np.stack([w.signals[name] for w in windows]) for name in windows[0].signals}
    inputs = features(stacked, windows[0].sample_rate_hz, config.n_timesteps, config.input_set)
    return network.predict(inputs)


def _entry(value: float, std: float | None, nominal: float) -> dict[str, Any]:
    return {"value": value, "std": std, "nominal": nominal, "drift_pct": 100.0 * (value - nominal) / nominal}


def blended_estimates(
    network: dict[str, float],
    baseline: dict[str, float] | None,
    check_truth: dict[str, np.ndarray],
    check_network: dict[str, np.ndarray],
    check_baseline: list[dict[str, float] | None],
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Per parameter: the blend of both estimators scored on the check windows (network alone if
    the baseline cannot fit the window or most check windows). Returns (estimates, methods)."""
    usable = [i for i, b in enumerate(check_baseline) if b is not None]
    estimates: dict[str, Any] = {}
    methods: dict[str, Any] = {}
    for name in TARGETS:
        if baseline is None or len(usable) < len(check_baseline) // 2:
            rms = float(np.sqrt(np.mean((check_network[name] - check_truth[name]) ** 2)))
            value, std = network[name], rms
            methods[name] = {"weight_network": 1.0, "rms_error_network": rms, "rms_error_baseline": None}
        else:
            base = np.array([check_baseline[i][name] for i in usable])  # type: ignore[index]
            blend = fit_blend(check_truth[name][usable], check_network[name][usable], base)
            value, std = blend.apply(network[name], baseline[name]), blend.rms_error
            methods[name] = {
                "weight_network": blend.weight_network,
                "rms_error_network": blend.rms_error_network,
                "rms_error_baseline": blend.rms_error_baseline,
            }
        methods[name].update(network=network[name], baseline=None if baseline is None else baseline[name])
        estimates[name] = _entry(value, std, NOMINAL[name])
    eta_o, eta_o_std = estimates["eta_O"]["value"], estimates["eta_O"]["std"]
    slope = float((eta_a_from_eta_o(eta_o + 1e-6) - eta_a_from_eta_o(eta_o - 1e-6)) / 2e-6)
    nominal_eta_a = float(eta_a_from_eta_o(NOMINAL["eta_O"]))
    estimates["eta_A"] = _entry(float(eta_a_from_eta_o(eta_o)), abs(slope) * eta_o_std, nominal_eta_a)
    return estimates, methods


def static_friction(fitted: FrictionLeastSquares | InputError) -> tuple[float | None, str]:
    """FSJ from the window's break-aways, or None with the reason it cannot be estimated."""
    if isinstance(fitted, InputError):
        return None, str(fitted)
    return fitted.fsj_, fitted.fsj_reason_


def estimate_window(
    window: Window,
    config: PipelineConfig = PipelineConfig(),
    on_stage: Callable[[str], None] | None = None,
    effects: EffectSet = EffectSet(),
) -> dict[str, Any]:
    """The ``ema-estimate/1`` result for one window; ``on_stage`` hears each stage as it starts.

    ``effects`` extends the model the dataset is simulated with (the calibration loop's output).
    """
    stage = on_stage or (lambda _: None)
    started = time.perf_counter()
    stage(f"simulating {config.n_simulations} + {config.check_windows} windows")
    scenario = scenario_from_window(window, effects)
    noise = window_noise(window, scenario)
    dataset_config = DatasetConfig(config.n_simulations, config.n_timesteps, config.input_set, seed=config.seed)
    dataset = build_dataset(scenario, dataset_config, noise)
    check_health, checks = check_windows(scenario, window, noise, config.check_windows, config.seed + 10_000)
    simulated = time.perf_counter()

    stage(f"training {config.members} network(s) of {config.hidden_units} neurons")
    train = replace(config.train, hidden=config.hidden_units, seed=config.seed)
    network = NetworkEstimator(train, config.members).fit(dataset)
    trained = time.perf_counter()

    stage("estimating")
    estimates, methods = blended_estimates(
        network={k: float(v[0]) for k, v in network_values(network, [window], config).items()},
        baseline=baseline_values(window_fit := baseline_fit(window)),
        check_truth={"FDJ": check_health.fdj_nm, "eta_O": check_health.eta_o},
        check_network=network_values(network, checks, config),
        check_baseline=[baseline_values(baseline_fit(w)) for w in checks],
    )
    fsj, fsj_note = static_friction(window_fit)  # the same fit: dynamic levels first, then break-aways
    estimates["FSJ"] = None if fsj is None else _entry(fsj, None, DEFAULT_RANGES.nominal_fsj_nm)
    if fsj is not None:
        estimates["FSD"] = {"value": fsj / estimates["FDJ"]["value"]}
    predicted = time.perf_counter()

    first = network.fits_[0]
    return {
        "schema": SCHEMA,
        "actuator_id": window.actuator_id,
        "window_id": window.window_id,
        "estimates": estimates,
        "fsj_note": fsj_note,
        "timings_s": {
            "simulate": simulated - started,
            "train": trained - simulated,
            "predict": predicted - trained,
            "total": predicted - started,
        },
        "dataset": {
            "n_simulations": config.n_simulations,
            "n_timesteps": config.n_timesteps,
            "inputs": list(INPUT_SETS[config.input_set]),
            "check_windows": config.check_windows,
            "noise_estimated": noise.as_dict(),
        },
        "training": {
            "epochs": first.epochs,
            "stop_reason": first.stop_reason,
            "val_mse": first.val_mse,
            "test_mse": first.test_mse,
            "members": config.members,
            "hidden_units": config.hidden_units,
        },
        "methods": methods,
    }
