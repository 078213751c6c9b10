"""Reproduce the thesis's chapter-6 results with our simulator and network; write docs/results.md.

Every case trains on a fresh dataset from one §5.6 command (Case 2: one per simulation) and is
scored on the test split and on 100 reserved simulations it never saw (thesis §6). Parity plots
go to docs/figures/. Run: python -m benchmarks.reproduce_thesis [--quick]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass, replace
from pathlib import Path

import matplotlib

from ema.model.actuator import THESIS

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ema.cli.benchmark_docs import write_section
from ema.estimate import thread_budget
from ema.estimate.learn.network import LearnConfig, learn_network, predict
from ema.kinds.rotary.box import Box
from ema.kinds.rotary.physics.features import features
from ema.kinds.rotary.physics.friction import solve_window
from ema.kinds.rotary.physics.scenario import Scenario
from ema.kinds.rotary.simulator.commands import random_command_knots
from ema.kinds.rotary.simulator.loads import GroundLoad
from ema.kinds.rotary.simulator.sensor_noise import add_sensor_noise
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.aircraft import FlightCondition
from ema.model.noise import NO_NOISE, SensorNoise
from ema.model.params import DEFAULT_RANGES, IRREVERSIBLE_RANGES, HealthParams, HealthRanges

DOCS = Path(__file__).resolve().parent.parent / "docs"
RATE_HZ, SAMPLES = 10_000.0, 5000


@dataclass(frozen=True)
class Case:
    name: str
    timesteps: int
    sims: int
    neurons: int
    thesis: str  # the thesis's figures for the same row, as printed
    load: FlightCondition | GroundLoad = FlightCondition()
    ranges: HealthRanges = DEFAULT_RANGES
    noise: SensorNoise = NO_NOISE
    inputs: str = "residual_torque"
    per_sim_command: bool = False
    train: LearnConfig = LearnConfig()


def cases(quick: bool) -> list[Case]:
    table_6_4 = [
        Case("1B", 1000, 500, 100, "6 s, 199 ep, test 3.93e-5, err 1.71 % / 3.47 %"),
        Case("1B", 1000, 1000, 50, "5 s, 224 ep, test 3.80e-5, err 8.46 % / 1.61 %"),
        Case("1B", 1000, 1000, 100, "8 s, 229 ep, test 3.18e-5, err 3.36 % / 1.34 %"),
        Case("1B", 2000, 1000, 100, "21 s, 217 ep, test 2.87e-5, err 3.07 % / 1.40 %"),
        Case("1B", 2000, 1000, 200, "69 s, 354 ep, test 1.69e-5, err 2.26 % / 1.99 %"),
    ]
    others = [
        Case("1B noisy", 1000, 500, 100, "(not in the thesis: realistic sensor noise)", noise=SensorNoise()),
        Case(
            "1B noisy, raw inputs",
            1000,
            500,
            100,
            "(thesis architecture on noisy data)",
            noise=SensorNoise(),
            train=LearnConfig(components=None),
        ),
        Case(
            "1B noisy, conjugate gradient",
            1000,
            500,
            100,
            "(optimizer comparison: the thesis's trainscg is one)",
            noise=SensorNoise(),
            train=LearnConfig(optimizer="cg"),
        ),
        Case(
            "1A constant load",
            2000,
            1000,
            100,
            "test 2.39e-4 (FDJ only; η_O not learned)",
            load=GroundLoad(-100.0, 0.0),
        ),
        Case("1A ramp load", 2000, 1000, 100, "between 1A constant and 1B", load=GroundLoad(-50.0, -300.0)),
        Case("1C irreversible", 2000, 1000, 100, "30 s, 318 ep, test 3.44e-6", ranges=IRREVERSIBLE_RANGES),
        Case(
            "2 random commands",
            2000,
            1000,
            100,
            "failed: best test 2.30e-2 (η_O only, 5000 sims)",
            per_sim_command=True,
            inputs="input_map",
        ),
    ]
    if quick:
        return [replace(c, sims=min(c.sims, 300), timesteps=min(c.timesteps, 500)) for c in (table_6_4[0], others[0])]
    return table_6_4 + others


def normalized_relative_error(prediction: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """The thesis's 'Err.': mean |p − t| / t on normalized values, in % (large near 0, as it warns)."""
    return 100 * np.mean(np.abs(prediction - truth) / np.maximum(truth, 1e-3), axis=0)


def thesis_dataset(case: Case, scenario: Scenario, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The thesis's dataset: health uniform over fixed ranges, features of the whole window, targets in [0, 1]."""
    rng = np.random.default_rng(seed)
    health = HealthParams.uniform(n, case.ranges, rng)
    signals = add_sensor_noise(scenario.simulate(health).signals, case.noise, rng)
    inputs = features(signals, RATE_HZ, case.timesteps, THESIS.params, case.inputs)
    box = Box(fdj_nm=case.ranges.fdj_nm, eta_o=case.ranges.eta_o)
    return inputs, box.normalize(health.fdj_nm, health.eta_o)


def run_case(case: Case, index: int) -> dict:
    rng = np.random.default_rng(1000 + index)
    n_knots = case.sims + 100 if case.per_sim_command else 1
    knots = random_command_knots(SAMPLES, RATE_HZ, rng, n_commands=n_knots)
    scenario = Scenario(THESIS.params, knots if case.per_sim_command else knots[0], case.load)
    started = time.perf_counter()
    inputs, targets = thesis_dataset(case, scenario, case.sims + 100, seed=index)
    simulate_s = time.perf_counter() - started
    train_x, train_y = inputs[: case.sims], targets[: case.sims]  # the last 100: reserved
    result = learn_network(train_x, train_y, replace(case.train, hidden=case.neurons))
    reserved = predict(result.model, inputs[case.sims :])
    truth = targets[case.sims :]
    return {
        "case": case,
        "parity": (reserved, truth),
        "simulate_s": simulate_s,
        "fit": result,
        "reserved_mse": float(np.mean((reserved - truth) ** 2)),
        "err_norm": normalized_relative_error(reserved, truth),
    }


def plot_parity(case: Case, index: int, prediction: np.ndarray, truth: np.ndarray) -> None:
    figure, axes = plt.subplots(1, 2, figsize=(8, 4))
    for axis, column, name in zip(axes, range(2), ("FDJ", "η_O"), strict=True):
        axis.plot([0, 1], [0, 1], color="grey", lw=1)
        axis.scatter(truth[:, column], prediction[:, column], s=10)
        axis.set(xlabel=f"true {name} (normalized)", ylabel="predicted", title=name, xlim=(0, 1), ylim=(0, 1))
    figure.suptitle(f"Case {case.name}: {case.timesteps} ts, {case.sims} sims, {case.neurons} neurons")
    figure.tight_layout()
    (DOCS / "figures").mkdir(parents=True, exist_ok=True)
    figure.savefig(DOCS / "figures" / f"parity_{index:02d}.png", dpi=90)
    plt.close(figure)


def baseline_comparison(n_windows: int) -> list[str]:
    """Network pipeline vs the least-squares baseline on the same noisy windows (physical errors)."""
    from ema.kinds.rotary.pipeline import estimate_window

    rows = []
    rng = np.random.default_rng(7)
    errors: dict[str, list] = {"network": [], "baseline": [], "blend": []}
    for seed in range(n_windows):
        health = HealthParams.uniform(1, DEFAULT_RANGES, rng)
        window = synthetic_window(health, seed=500 + seed)
        result = estimate_window(window, actuator=THESIS)
        truth = np.array([health.fdj_nm[0], health.eta_o[0]])
        methods = result.methods
        errors["network"].append(np.array([methods["FDJ"].network, methods["eta_O"].network]) / truth - 1)
        base = solve_window(window.signals, window.sample_rate_hz, drive=THESIS.params)
        errors["baseline"].append(np.array([base.fdj_nm[0], base.eta_o[0]]) / truth - 1)
        fdj, eta_o = result.estimates.FDJ, result.estimates.eta_O
        assert eta_o is not None, "a window in flight is loaded: eta_O is read"
        errors["blend"].append(np.array([fdj.value, eta_o.value]) / truth - 1)
    for name, values in errors.items():
        mean_abs = 100 * np.mean(np.abs(values), axis=0)
        rows.append(f"| {name} | {mean_abs[0]:.3f} % | {mean_abs[1]:.3f} % |")
    return rows


def write_results(results: list[dict], comparison: list[str], command: str) -> None:
    lines = [
        "Each row: a fresh dataset from one §5.6 command at the default flight condition (153 m/s, sea level)",
        "unless the case says otherwise, 75/15/10 split, early stopping after 12 validation failures.",
        "MSE on normalized targets; *reserved* = 100 simulations never used in training (thesis §6).",
        "*Err.* is the thesis's measure: mean relative error of the normalized FDJ / η_O (it inflates",
        "near 0, as the thesis's footnote warns). Our networks use the 16-component input projection",
        "unless the row says *raw inputs* (see `ema/estimate/learn/network.py`).",
        "",
        "| case | timesteps | sims | neurons | inputs | sim [s] | train [s] | epochs | stop | train MSE | test MSE"
        " | reserved MSE | Err. FDJ / η_O | thesis |",
        "|---|---:|---:|---:|---|---:|---:|---:|---|---:|---:|---:|---|---|",
    ]
    for i, r in enumerate(results):
        c, f = r["case"], r["fit"]
        lines.append(
            f"| [{c.name}](figures/parity_{i:02d}.png) | {c.timesteps} | {c.sims} | {c.neurons} | {c.inputs} "
            f"| {r['simulate_s']:.1f} | {f.seconds:.2f} | {f.epochs} | {f.stop_reason} | {f.train_mse:.2e} "
            f"| {f.test_mse:.2e} | {r['reserved_mse']:.2e} | {r['err_norm'][0]:.2f} % / {r['err_norm'][1]:.2f} % "
            f"| {c.thesis} |"
        )
    lines += [
        "",
        "### Reading the table",
        "",
        "- **Case 1B** (clean, as in the thesis): every Table 6.4 row reaches a test MSE 10-100x lower than",
        "  the thesis's, in seconds of training on 2 cores instead of tens. What buys it: L-BFGS with a",
        "  working line search, and the 16-component input projection (compare the *raw inputs* row).",
        "- **Sensor noise** is what limits accuracy in practice (thesis §6.4 expected 5-10 % on real data):",
        "  with realistic noise the test MSE is ~7e-5, i.e. an RMS error of ~0.8 % of each range",
        "  (~1.7e-4 N·m on FDJ, ~0.0025 on η_O). See the conjugate-gradient row for the thesis's kind of optimizer.",
        "- **Case 1A, constant load**: with n = 500, Eq. 3.4 makes 1 − η_A ≈ 1/η_O − 1, so a constant |T_ext|",
        "  adds the same k·|T_ext| whether it aids or opposes: sliding friction shows FDJ + k·|T_ext| and",
        "  not the two apart. The thesis's network kept FDJ and lost η_O; ours keeps η_O (from the",
        "  transients) and loses FDJ; both fail for the same reason. A ramp load separates them again.",
        "- **Case 1C**: the irreversible range trains as well as 1B (thesis: better than 1B; ours: on par).",
        "- **Case 2** fails for us as for the thesis: with a new command per simulation, the residual",
        "  torque trace is dominated by the command, not by FDJ or η_O; no shallow network on 1 000",
        "  simulations can invert that. Retraining per window (Case 1B on the logged command,",
        "  `ema/kinds/rotary/pipeline.py`) is the answer the thesis proposed in §6.3, and what the product does.",
        "",
        "### Network or physics? Both, on the same noisy windows",
        "",
        "Mean absolute relative error (physical units) over synthetic 0.5 s in-flight windows with",
        "realistic sensor noise: the window's network, the least-squares baseline of Eq. 5.1",
        "(`ema/kinds/rotary/physics/friction.py`, no simulation), and the answer the product reports (the baseline,",
        "less its bias on held-out simulations, blended with the network where it earns it: "
        "`ema/estimate/assess/weighing.py`).",
        "",
        "| estimator | FDJ | η_O |",
        "|---|---:|---:|",
        *comparison,
        "",
        "FSJ: in flight the position loop keeps the shaft hunting in the backlash and it rarely rests;",
        "after a pilot's step the drive jumps past the static level within one log interval. FSJ is",
        "read only at quasi-static break-aways (`ema/kinds/rotary/physics/static_friction.py`); otherwise the product",
        "reports `FSJ: null` with the reason. On the ground with a slowly rising load the shaft rests",
        "and breaks away: FSJ is read within 2 % there, within its ±2 std under sensor noise; a shaft held",
        "and then stepped away shows only a lower bound (tests/kinds/rotary/physics/test_static_friction.py).",
    ]
    write_section("Thesis chapter 6, reproduced", command, "\n".join(lines), DOCS / "results.md")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="two small cases, for a smoke run")
    parser.add_argument("--windows", type=int, default=20, help="windows in the network/baseline comparison")
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure()
    rng = np.random.default_rng(0)  # warm the imports and the kernels: no start-up cost in the first row's times
    learn_network(rng.normal(size=(60, 50)), rng.uniform(size=(60, 2)), LearnConfig(hidden=8, max_epochs=5))
    Scenario(THESIS.params, random_command_knots(50, RATE_HZ, rng)[0]).simulate(HealthParams.single())
    results = []
    for index, case in enumerate(cases(args.quick)):
        results.append(run_case(case, index))
        f = results[-1]["fit"]
        print(
            f"{case.name:>22} {case.timesteps}/{case.sims}/{case.neurons}: train {f.seconds:.2f} s, "
            f"test {f.test_mse:.2e}, reserved {results[-1]['reserved_mse']:.2e}",
            flush=True,
        )
    comparison = baseline_comparison(3 if args.quick else args.windows)
    print("\n".join(comparison))
    if args.docs:
        for index, result in enumerate(results):
            plot_parity(result["case"], index, *result["parity"])
        write_results(results, comparison, "python -m benchmarks.reproduce_thesis --docs" + (" --quick" * args.quick))


if __name__ == "__main__":
    main()
