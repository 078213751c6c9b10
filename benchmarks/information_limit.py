"""How well could *any* reading of Eq. 5.1 do on a window? The limit its sensor noise sets: docs/results.md.

For windows where the estimates still err by more than 10 % of the range now and then (0.1 s
windows, 1–2 kHz logs), this asks whether a better estimator could avoid it. Each window is
drawn twice by ``tests.foreign`` (the seeds of ``benchmarks.foreign_accuracy``): as logged, and
without its sensor noise. Their difference gives each sensor's realized noise level. On the clean
twin, linearized at the true health, Eq. 5.1 on raw samples reads

    y_k = sgn(ω_k)·(k_T·I_k + H_k/n − J·(ω_{k+1} − ω_{k−1})/2h) = FDJ + k(η_O)·|H_k/n|    (sliding k)

and each sensor's noise enters y through a known linear map A_s (current: diagonal; speed: the
central difference; hinge and position: through the hinge reading of ``ema.kinds.rotary.simulator.hinge``, its measured
slope b included). With Σ = Σ_s σ_s² A_s A_sᵀ, generalized least squares has covariance
(Xᵀ Σ⁻¹ X)⁻¹ (X: ∂y/∂(FDJ, η_O)): the smallest any linear unbiased reading of these equations
reaches, because it weighs every sample by what the noise leaves of it. *Current sensor alone*
keeps only the current's noise (speed, hinge and position perfect): the torque no reading of the
motor current avoids. Neither uses the controller's equations: what those would add, and what
they would cost, is ``benchmarks.whole_loop``'s question.

For each group: the mean |error| an unbiased estimator at that std would make (√(2/π)·std),
the number of windows expected past 10 % of the range (Σ P(|N(0, std)| > 10 %)), and our Eq. 5.1
fit's RMS error over fresh noise draws on the clean twin, as a multiple of the efficient std.

    python -m benchmarks.information_limit [--per-group 60] [--draws 100] [--docs]
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from benchmarks.foreign_accuracy import RESULTS_MD
from benchmarks.foreign_groups import group_seed, groups
from benchmarks.tails import expected_over
from ema.cli.benchmark_docs import write_section
from ema.estimate import thread_budget
from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.friction import SolveSettings, regressors, solve_friction
from ema.kinds.rotary.prepare.conditioning import prepare
from ema.kinds.rotary.simulator.hinge import HINGE_SMOOTHING_S, local_line
from ema.kinds.rotary.simulator.residual import kernel_samples
from ema.model.actuator import THESIS
from ema.model.params import DriveConstants, eta_a_from_eta_o
from ema.model.window import RotaryWindow, Window, as_window, window_from_dict

GROUPS = ("short window (0.1 s, gust)", "low log rate (1-2 kHz)")  # the groups with errors past 10 % of range
SENSORS = ("current_a", "motor_speed_radps", "hinge_moment_nm", "position_deg")
ACTUATOR = DriveConstants()


def twins(group: str, i: int) -> tuple[Window, Window, dict[str, float]]:
    """Window ``i`` of ``group`` as logged and without its sensor noise (both as the pipeline prepares
    them), and its truth."""
    make, seed = groups()[group], group_seed(group, i)
    logged, clean = make(seed), make(seed, noise_level=0.0)
    as_logged = prepare(as_window(window_from_dict(logged.document), RotaryWindow), actuator=THESIS).window
    clean_window = as_window(window_from_dict(clean.document), RotaryWindow)
    return as_logged, prepare(clean_window, actuator=THESIS).window, logged.truth


def noise_levels(logged: Mapping[str, Any], clean: Mapping[str, np.ndarray]) -> dict[str, float]:
    """Each sensor's realized noise std (the foreign draw scales its levels ±30 % per window)."""
    return {name: float(np.std(np.asarray(logged[name]) - clean[name])) for name in SENSORS}


def _k_slopes(eta_o: float, step: float = 1e-5) -> tuple[float, float]:
    """d(1 − η_A)/dη_O and d(1/η_O − 1)/dη_O at ``eta_o`` (Eq. 3.4 ties η_A to η_O)."""
    aid = (eta_a_from_eta_o(eta_o - step, 500.0) - eta_a_from_eta_o(eta_o + step, 500.0)) / (2 * step)
    return float(aid), -1.0 / eta_o**2


def linearized(clean: Window, truth: dict[str, float]) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """(X (m, 2): ∂y/∂(FDJ, η_O) on the sliding samples, the mask (n,), A_s (n, n) per sensor at unit std)."""
    rate, n = clean.sample_rate_hz, clean.n_samples
    signals = clean.signals
    mask = regressors(as_read(signals, rate), rate, ACTUATOR, SolveSettings())[3][0].copy()
    mask[[0, -1]] = False  # the central difference needs both neighbours
    direction = np.sign(signals["motor_speed_radps"])
    load = signals["hinge_moment_nm"] / ACTUATOR.gear_ratio
    aiding = load * direction > 0
    eta_o = truth["eta_O"]
    slope_aid, slope_opp = _k_slopes(eta_o)
    k = np.where(aiding, 1.0 - eta_a_from_eta_o(eta_o, 500.0), 1.0 / eta_o - 1.0)
    X = np.stack([np.ones(n), np.abs(load) * np.where(aiding, slope_aid, slope_opp)], axis=1)[mask]
    identity = np.eye(n)
    central = (np.roll(identity, -1, axis=0) - np.roll(identity, 1, axis=0)) * rate / 2
    hinge = (direction - k * np.sign(load))[:, None] / ACTUATOR.gear_ratio  # y's sensitivity to the hinge read
    read_h, read_d = _hinge_read_maps(signals, rate)
    operators = {
        "current_a": np.diag(direction * ACTUATOR.torque_constant_nm_per_a),
        "motor_speed_radps": -direction[:, None] * ACTUATOR.inertia_kgm2 * central,
        "hinge_moment_nm": hinge * read_h,
        "position_deg": hinge * read_d,
    }
    return X, mask, operators


def _hinge_read_maps(signals: dict[str, np.ndarray], rate: float) -> tuple[np.ndarray, np.ndarray]:
    """∂H_read/∂H_e and ∂H_read/∂δ (n, n) of ``ema.kinds.rotary.simulator.hinge`` at these signals, the slope b's own
    response to the noise included (to first order)."""
    n = len(signals["hinge_moment_nm"])
    line = local_line(np.eye(n), kernel_samples(rate, HINGE_SMOOTHING_S)).T  # [i, j] = ∂(line at i)/∂(sample j)
    high_pass = np.eye(n) - line
    fast, fast_hinge = high_pass @ signals["position_deg"], high_pass @ signals["hinge_moment_nm"]
    spread = float(np.sum(fast**2))
    b = float(fast_hinge @ fast) / spread  # H_read = line·H + b·(δ − line·δ), b = Σ fast_H·fast_δ / Σ fast_δ²
    db_dh = fast @ high_pass / spread
    db_dd = (fast_hinge @ high_pass - 2 * b * (fast @ high_pass)) / spread
    return line + np.outer(fast, db_dh), b * high_pass + np.outer(fast, db_dd)


def efficient_std(
    X: np.ndarray,
    mask: np.ndarray,
    operators: dict[str, np.ndarray],
    levels: dict[str, float],
    sensors: tuple[str, ...],
) -> np.ndarray:
    """(2,) std of FDJ and η_O, as shares of their ranges, of the GLS reading with these sensors' noise."""
    rows = [levels[s] * operators[s][mask] for s in sensors]
    covariance = sum(r @ r.T for r in rows)
    information = X.T @ np.linalg.solve(covariance, X)
    std = np.sqrt(np.diag(np.linalg.inv(information)))
    return std / np.array([np.ptp(THESIS.ranges.of("FDJ")), np.ptp(THESIS.ranges.of("eta_O"))])


def our_rms(clean: Window, truth: dict[str, float], levels: dict[str, float], draws: int, seed: int) -> np.ndarray:
    """(2,) RMS error (share of range) of ``ema.kinds.rotary.physics.friction`` on ``draws`` Gaussian noise draws at
    ``levels``."""
    rng = np.random.default_rng(seed)
    signals = {name: np.repeat(values[None], draws, axis=0) for name, values in clean.signals.items()}
    for name in SENSORS:
        signals[name] = signals[name] + levels[name] * rng.standard_normal(signals[name].shape)
    solution = solve_friction(as_read(signals, clean.sample_rate_hz), clean.sample_rate_hz, drive=THESIS.params)
    errors = np.stack([solution.fdj_nm - truth["FDJ"], solution.eta_o - truth["eta_O"]])
    return np.sqrt(np.nanmean(errors**2, axis=1)) / np.array([np.ptp(THESIS.ranges.of(k)) for k in ("FDJ", "eta_O")])


def one_window(group: str, i: int, draws: int) -> dict[str, np.ndarray]:
    logged, clean, truth = twins(group, i)
    levels = noise_levels(logged.signals, clean.signals)
    X, mask, operators = linearized(clean, truth)
    return {
        "efficient": efficient_std(X, mask, operators, levels, SENSORS),
        "current": efficient_std(X, mask, operators, levels, ("current_a",)),
        "ours": our_rms(clean, truth, levels, draws, group_seed(group, i)),
    }


def table(rows: dict[str, list[dict[str, np.ndarray]]]) -> str:
    lines = [
        "| windows | parameter | efficient: mean error / expected past 10 % | current sensor alone: same "
        "| our Eq. 5.1 fit: RMS / efficient std, median (worst) |",
        "|---|---|---:|---:|---:|",
    ]
    for group, found in rows.items():
        for p, name in enumerate(("FDJ", "η_O")):
            cells = []
            for kind in ("efficient", "current"):
                stds = np.array([r[kind][p] for r in found])
                cells.append(f"{100 * math.sqrt(2 / math.pi) * stds.mean():.1f} % / {expected_over(stds):.1f}")
            ratio = np.array([r["ours"][p] / r["efficient"][p] for r in found])
            lines.append(
                f"| {group} ({len(found)}) | {name} | {cells[0]} | {cells[1]} "
                f"| {np.median(ratio):.2f} ({ratio.max():.2f}) |"
            )
    return "\n".join(lines)


def report(rows: dict[str, list[dict[str, np.ndarray]]], draws: int) -> str:
    return "\n".join(
        [
            "The limit the sensor noise sets on windows of `benchmarks.foreign_accuracy`'s seeds (module",
            "docstring: GLS on Eq. 5.1's raw samples, each sensor's realized noise, linearized at the true",
            "health). Mean error in % of the range; *ours*: `ema/kinds/rotary/physics/friction.py` over "
            f"{draws} fresh noise draws on each clean twin.",
            "",
            table(rows),
            "",
            "Read beside the accuracy table above. *Efficient* is the least std of any unbiased estimator",
            "linear in Eq. 5.1's samples (Gauss–Markov); ours, a nonlinear least squares, comes within a few %",
            "of it at the median (the worst, at 1 kHz: the 3-sample reconstruction kernel's bias, which the",
            "product measures on its simulations and subtracts). *Current sensor alone* is",
            "the Cramér–Rao bound with speed, hinge and position noise-free: the model is then linear in",
            "(FDJ, k) with white noise, and least squares is efficient. Where these expect windows past 10 %",
            "of the range, no reading of Eq. 5.1 avoids them. A reading of the whole closed loop would hold",
            "more, but only for a loop known to the microsecond (next section). The remedy is more window",
            "(a longer or faster log) or the actuator's history (`ema history` weighs each window by its std:",
            "on 16 foreign histories of 30 windows, a fifth of them 0.1 s and a fifth 1–2 kHz, with 18 answers",
            "past 10 % of range, every trend's level at the last window stood within 1 % of the range of the",
            "truth: docs/prognosis.md).",
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-group", type=int, default=60, help="windows per group")
    parser.add_argument("--draws", type=int, default=100, help="noise draws per window for our fit's RMS")
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure()
    rows = {group: [one_window(group, i, args.draws) for i in range(args.per_group)] for group in GROUPS}
    body = report(rows, args.draws)
    print(body)
    if args.docs:
        write_section(
            "The information limit of short and slow windows",
            "python -m benchmarks.information_limit --docs",
            body,
            RESULTS_MD,
        )


if __name__ == "__main__":
    main()
