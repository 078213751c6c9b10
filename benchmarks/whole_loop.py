"""Would reading the whole closed loop beat Eq. 5.1 on short and slow windows? Not on a real loop: docs/results.md.

Eq. 5.1 reads the torque balance alone: k_T, J, n and four sensors. The model says more:
how the position and speed loops turn the command into a current reference, and how the PWM
current loop follows it. A reading that simulates that whole loop (the window's start, command
and flight condition known) and fits all four sensors can also use *when* things happen: the
instant the speed reference leaves saturation depends on the angle integrated over the whole
slew, so a friction change of a fraction of a mN·m moves a 20 A current step by microseconds.

For each window of ``benchmarks.information_limit``'s groups, with ``tests.foreign``'s simulation
and the window's realized sensor noise, by central differences at the true health (±2.5 % of the
range), this computes:

- *whole loop*: the Cramér–Rao std of that reading, F = Σ_s J_sᵀ J_s / σ_s² over the four sensors.
  Timing events make the signals almost discontinuous in the parameters, so read it as a scale;
  and the same with the loop's bus voltage, lag and position gain fitted as unknowns too;
- its first-order bias b = F⁻¹ Σ_s J_sᵀ Δs / σ_s² when the model it trusts is *our* simulator of
  the same model (started where the window starts, fed its command and logged hinge moment: what
  ``ema.kinds.rotary.dataset`` simulates), and when the real loop departs from the document's by less than any
  log shows: the PWM bus 1 % high, the command reaching the loop 10 µs late, the position gain
  0.1 % high, the loop reading a speed as noisy as the logged one (``tests.foreign.physics.Effects``);
- how far our Eq. 5.1 fit (``ema.kinds.rotary.physics.friction``) moves on the same departures, noise-free;
- where the whole-loop information lies: its share in the richest 2 % of the samples.

    python -m benchmarks.whole_loop [--per-group 60] [--docs]
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace

import numpy as np

from benchmarks.foreign_accuracy import RESULTS_MD
from benchmarks.foreign_groups import group_seed, groups
from benchmarks.information_limit import GROUPS, SENSORS, noise_levels
from benchmarks.tails import expected_over
from ema.cli.benchmark_docs import typed_command, write_section
from ema.estimate import thread_budget
from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.friction import solve_friction
from ema.kinds.rotary.physics.scenario import scenario_from_window
from ema.kinds.rotary.prepare.conditioning import prepare
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.model.window import RotaryWindow, as_window, window_from_dict
from tests.foreign.physics import Effects
from tests.foreign.windows import Draw

WIDTH = np.array([np.ptp(THESIS.ranges.of("FDJ")), np.ptp(THESIS.ranges.of("eta_O"))])  # the ranges, for shares
STEP = 0.025  # central-difference step, share of each range
DEPARTURES = {
    "bus +1 %": Effects(supply_voltage_factor=1.01),
    "10 µs late": Effects(loop_delay_s=1e-5),
    "G_P +0.1 %": Effects(position_gain_factor=1.001),
    "noisy speed read": Effects(loop_noise_radps=0.5),  # the loop reads the logged sensor's 0.5 rad/s noise
}
CONSTANTS = ("bus +1 %", "10 µs late", "G_P +0.1 %")  # departures a whole-loop reading could fit as unknowns
FEW = 0.02  # where the information lies: its share in this share of the samples that hold most
SLEW_RADPS = 400.0  # near the speed reference's saturation (638 rad/s)


def _weighted(signals: dict[str, np.ndarray], levels: dict[str, float]) -> np.ndarray:
    """(4·n,) the four sensors' clean signals, each over its noise std."""
    return np.concatenate([signals[s] / levels[s] for s in SENSORS])


def sensitivities(window: Draw, levels: dict[str, float]) -> np.ndarray:
    """(4·n, 2) ∂(weighted signals)/∂(FDJ, η_O), per share of the range."""
    health, columns = window.setup.health, []
    for field, width in (("fdj_nm", WIDTH[0]), ("eta_o", WIDTH[1])):
        value = getattr(health, field)
        up, down = (window.clean_signals(health=replace(health, **{field: value + s * STEP * width})) for s in (1, -1))
        columns.append((_weighted(up, levels) - _weighted(down, levels)) / (2 * STEP))
    return np.stack(columns, axis=1)


def _as_window(window: Draw, signals: dict[str, np.ndarray]) -> RotaryWindow:
    """``window``'s document with these signals, through the public contract."""
    document = {**window.document, "signals": {name: values.tolist() for name, values in signals.items()}}
    return as_window(window_from_dict(document), RotaryWindow)


def our_simulator_bias(window: Draw, clean: dict[str, np.ndarray], levels: dict[str, float]) -> np.ndarray:
    """(2,) first-order bias of a whole-loop reading that simulates the window with *our* simulator
    (``ema.kinds.rotary.dataset``'s scenario of the noise-free window: its command, start and logged load)."""
    scenario = scenario_from_window(_as_window(window, clean), drive=THESIS.params, hinge=THESIS.hinge)
    truth, (d_fdj, d_eta) = window.truth, STEP * WIDTH
    fdj, eta_o = truth["FDJ"] + np.array([0, d_fdj, -d_fdj, 0, 0]), truth["eta_O"] + np.array([0, 0, 0, d_eta, -d_eta])
    signals = scenario.simulate(HealthParams(fsj_nm=np.full(5, truth["FSJ"]), fdj_nm=fdj, eta_o=eta_o)).signals
    at, fdj_up, fdj_down, eta_up, eta_down = (_weighted({s: signals[s][j] for s in SENSORS}, levels) for j in range(5))
    J = np.stack([fdj_up - fdj_down, eta_up - eta_down], axis=1) / (2 * STEP)
    return np.linalg.solve(J.T @ J, J.T @ (_weighted(clean, levels) - at))


def our_fit(window: Draw, signals: dict[str, np.ndarray]) -> np.ndarray:
    """(2,) FDJ and η_O of the Eq. 5.1 fit on these signals, as shares of the range."""
    prepared = prepare(_as_window(window, signals), actuator=THESIS).window
    rate = prepared.sample_rate_hz
    solution = solve_friction(
        as_read({k: v[None] for k, v in prepared.signals.items()}, rate), rate, drive=THESIS.params
    )
    return np.array([solution.fdj_nm[0], solution.eta_o[0]]) / WIDTH


def where_it_lies(J: np.ndarray, speed_radps: np.ndarray) -> np.ndarray:
    """(2,) the share of the information (trace of JᵀJ) in the ``FEW`` richest samples, and the share of those
    samples at slew speed."""
    per_sample = (J**2).sum(axis=1).reshape(len(SENSORS), -1).sum(axis=0)
    richest = np.argsort(per_sample)[::-1][: max(1, round(FEW * len(per_sample)))]
    return np.array([per_sample[richest].sum() / per_sample.sum(), np.mean(np.abs(speed_radps[richest]) > SLEW_RADPS)])


def one_window(group: str, i: int) -> dict[str, np.ndarray]:
    """The whole-loop std (2,), the same with the loop's constants estimated too (2,), its biases
    (departures, 2), its bias read with our simulator (2,) and our fit's shifts (departures, 2)."""
    window = groups()[group](group_seed(group, i))
    clean = window.clean_signals()
    levels = noise_levels(window.document["signals"], clean)
    J = sensitivities(window, levels)
    information = J.T @ J
    base, ours = _weighted(clean, levels), our_fit(window, clean)
    departed = {name: window.clean_signals(effects=effects) for name, effects in DEPARTURES.items()}
    changes = np.stack([_weighted(signals, levels) - base for signals in departed.values()], axis=1)
    constants = changes[:, [name in CONSTANTS for name in DEPARTURES]]  # ∂/∂ each constant, one-sided
    cross = J.T @ constants
    profiled = information - cross @ np.linalg.pinv(constants.T @ constants) @ cross.T
    return {
        "std": np.sqrt(np.diag(np.linalg.inv(information))),
        "std_constants_fitted": np.sqrt(np.diag(np.linalg.inv(profiled))),
        "bias": np.linalg.solve(information, J.T @ changes).T,
        "our_simulator": our_simulator_bias(window, clean, levels),
        "shift": np.array([our_fit(window, signals) - ours for signals in departed.values()]),
        "where": where_it_lies(J, clean["motor_speed_radps"]),
    }


def _bound(stds: np.ndarray) -> str:
    return f"{100 * math.sqrt(2 / math.pi) * stds.mean():.2f} % / {expected_over(stds):.1f}"


def _spread(values: np.ndarray) -> str:
    """Median (worst) of shares of the range, in %."""
    median, worst = (f"{x:.0f}" if x >= 10 else f"{x:.2g}" for x in (100 * np.median(values), 100 * values.max()))
    return f"{median} ({worst})"


def table(rows: dict[str, list[dict[str, np.ndarray]]]) -> str:
    lines = [
        "| windows | parameter | whole loop: mean error / expected past 10 % | the same, its constants fitted too | "
        "its bias, read with our simulator | "
        + " | ".join(f"its bias, {name}" for name in DEPARTURES)
        + " | our fit moves, any of these |",
        "|---|---|" + "---:|" * (len(DEPARTURES) + 4),
    ]
    for group, found in rows.items():
        for p, name in enumerate(("FDJ", "η_O")):
            bias = np.abs(np.array([r["bias"][:, p] for r in found]))  # (windows, departures)
            cells = [_bound(np.array([r[k][p] for r in found])) for k in ("std", "std_constants_fitted")]
            cells.append(_spread(np.abs(np.array([r["our_simulator"][p] for r in found]))))
            cells += [_spread(b) for b in bias.T]
            cells.append(_spread(np.array([np.abs(r["shift"][:, p]).max() for r in found])))
            lines.append(f"| {group} ({len(found)}) | {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def report(rows: dict[str, list[dict[str, np.ndarray]]]) -> str:
    where = np.median([r["where"] for found in rows.values() for r in found], axis=0)
    return "\n".join(
        [
            "The windows of the section above, read through the whole closed loop of the model instead of",
            "Eq. 5.1 (module docstring): what that would buy and what it would cost. Errors and biases in",
            "% of the range; biases as median (worst) over the windows.",
            "",
            table(rows),
            "",
            "Trusted to the microsecond, the document's loop holds far more than Eq. 5.1 (first column), and",
            f"in a few instants: at the median window, {100 * where[0]:.0f} % of it lies in the richest "
            f"{100 * FEW:.0f} % of",
            f"the samples, {100 * where[1]:.0f} % of those at slew speed (> {SLEW_RADPS:.0f} rad/s, the speed "
            f"reference",
            "near its saturation). Fitting the loop's constants as unknowns keeps most of it (second",
            "column). But that information belongs to one implementation. Our own simulator of the model, started",
            "where the window starts and fed its command and hinge moment, differs from the independent one",
            "by far more (third column; among the causes, the side of the backlash at the start, the command",
            "between log samples and the ripple of an Euler against an exact current step, all legitimate",
            "readings of the model). A departure of the loop smaller than any log shows (a bus 1 % high,",
            "a 10 µs lag, a gain 0.1 % off, a loop that reads the logged speed sensor's noise) moves the",
            "reading by more than its std. Eq. 5.1 uses none of the loop's constants, and our fit moves by",
            "the last column's amounts under the same departures (at 1 kHz the 3-sample reconstruction",
            "feels the slightly changed motion). So the product reads Eq. 5.1 and says when a window is",
            "weak; `benchmarks.foreign_accuracy`'s drives unlike the document's are read as well as the others.",
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-group", type=int, default=60, help="windows per group")
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure()
    rows = {group: [one_window(group, i) for i in range(args.per_group)] for group in GROUPS}
    body = report(rows)
    print(body)
    if args.docs:
        write_section("Reading the whole loop instead", typed_command(), body, RESULTS_MD)


if __name__ == "__main__":
    main()
