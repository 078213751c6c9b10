"""Simulator speed: ns per simulation-step and wall time for 500 simulations x 0.5 s.

Beside it, in the same run: the plain NumPy model vectorized across the same 500 simulations
(timed on a short horizon and scaled: it is linear in the horizon), the one-lane scalar path of the
same kernel, and the thesis's Simulink figure (100-150 ms per 0.5 s simulation).

    python -m benchmarks.sim_speed [--sims 500] [--repeats 3] [--docs]
"""

from __future__ import annotations

import argparse
import functools
import time

import numpy as np

from ema.cli.benchmark_docs import typed_command, write_section
from ema.estimate import thread_budget
from ema.kinds.rotary.simulator.batch import default_lanes, kernel_constants, simulate_batch
from ema.kinds.rotary.simulator.commands import random_command_knots
from ema.kinds.rotary.simulator.effects import EffectSet
from ema.kinds.rotary.simulator.loads import load_model
from ema.kinds.rotary.simulator.reference import simulate_numpy
from ema.model.actuator import THESIS
from ema.model.aircraft import FlightCondition
from ema.model.params import DEFAULT_RANGES, DriveConstants, HealthParams

RATE_HZ = 10_000.0
STEPS_PER_SAMPLE = 100
THESIS_MS_PER_SIM = (100.0, 150.0)  # Simulink Accelerator, one 0.5 s simulation (thesis ch. 3)


def best_of(repeats: int, run) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return min(times)


LANE_SWEEP = (1, 8, 16, 24, 32, 48, 72)


def lane_sweep(health: HealthParams, knots: np.ndarray, samples: int, repeats: int) -> list[str]:
    """Lines of a table: ns per simulation-step with one group of each of ``LANE_SWEEP`` lanes, one thread."""
    lines = [
        "",
        f"Cost per simulation-step by lanes per group (one group on one thread, {samples} samples): below",
        "`ema.kinds.rotary.simulator.batch.MIN_VECTOR_LANES` the lane loop runs its scalar path.",
        "",
        "| lanes per group | ns / sim-step |",
        "|---:|---:|",
    ]
    for lanes in LANE_SWEEP:
        one = HealthParams(*(getattr(health, name)[:lanes] for name in ("fsj_nm", "fdj_nm", "eta_o")))
        simulate_batch(knots[:11], one, lanes=lanes, drive=THESIS.params)
        run = functools.partial(simulate_batch, knots[: samples + 1], one, lanes=lanes, drive=THESIS.params)
        seconds = best_of(repeats, run)
        lines.append(f"| {lanes} | {seconds / (lanes * samples * STEPS_PER_SAMPLE) * 1e9:.3g} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sims", type=int, default=500)
    parser.add_argument("--samples", type=int, default=5000, help="log samples per simulation (5000 = 0.5 s)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--numpy-samples", type=int, default=5, help="horizon of the NumPy timing")
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/benchmarks.md")
    args = parser.parse_args()
    threads = thread_budget.configure()

    rng = np.random.default_rng(0)
    health = HealthParams.uniform(args.sims, DEFAULT_RANGES, rng)
    knots = random_command_knots(args.samples, RATE_HZ, rng)[0]
    simulate_batch(knots[:11], health, drive=THESIS.params)  # JIT (or cache load) outside the timing
    simulate_batch(knots[:11], health, lanes=1, drive=THESIS.params)
    steps = args.sims * args.samples * STEPS_PER_SAMPLE

    fast_s = best_of(args.repeats, lambda: simulate_batch(knots, health, drive=THESIS.params))
    short = args.samples // 10
    scalar_s = (
        best_of(1, lambda: simulate_batch(knots[: short + 1], health, lanes=1, drive=THESIS.params))
        * args.samples
        / short
    )

    c = kernel_constants(DriveConstants(), EffectSet())
    load = load_model(FlightCondition(), STEPS_PER_SAMPLE * 1e-6)
    eta_a = health.eta_a(500.0)
    per_sim = np.stack([health.fdj_nm, health.fsj_nm, 1 - eta_a, 1 / health.eta_o - 1])
    initial = np.zeros((3, args.sims))
    knots_rad = np.radians(knots[: args.numpy_samples + 1])[None]
    steps_each = np.full(args.numpy_samples, STEPS_PER_SAMPLE)
    numpy_s = best_of(1, lambda: simulate_numpy(c, load, per_sim, knots_rad, initial, steps_each))
    numpy_s *= args.samples / args.numpy_samples

    thesis_s = tuple(ms / 1000 * args.sims for ms in THESIS_MS_PER_SIM)
    rows = [
        (f"lock-step kernel, {default_lanes(args.sims)} lanes, {threads} threads", fast_s, "measured"),
        (f"same kernel, 1 lane (scalar path), {threads} threads", scalar_s, f"measured on {short} samples, scaled"),
        ("NumPy, vectorized across simulations", numpy_s, f"measured on {args.numpy_samples} samples, scaled"),
        ("thesis, Simulink Accelerator", thesis_s[0], f"{THESIS_MS_PER_SIM[0]:g}-{THESIS_MS_PER_SIM[1]:g} ms per sim"),
    ]
    lines = [
        f"{args.sims} simulations x {args.samples / RATE_HZ:g} s at h = 1 µs ({steps:.3g} simulation-steps).",
        "Target: ≤ 3 ns per simulation-step amortized, i.e. ≤ 0.75 s for 500 x 0.5 s.",
        "",
        "| implementation | wall time [s] | ns / sim-step | speed-up of the kernel | note |",
        "|---|---:|---:|---:|---|",
    ]
    for name, seconds, note in rows:
        lines.append(f"| {name} | {seconds:.3g} | {seconds / steps * 1e9:.3g} | {seconds / fast_s:.3g}x | {note} |")
    lines += lane_sweep(health, knots, short, args.repeats)
    body = "\n".join(lines)
    print(body)
    if args.docs:
        write_section("Simulator speed", typed_command(), body)


if __name__ == "__main__":
    main()
