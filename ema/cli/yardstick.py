"""A reference for speed figures: a plain 16-lane Numba kernel of the same EMA, timed in the same run.

These machines drift ~2x from day to day, so an absolute latency says little; a ratio to work of the
same kind measured in the same run does. The yardstick is written apart from ``ema.kinds.rotary.simulator.kernels``, in
the form a careful engineer would write first, so that it moves with the machine, not with our
optimizations. It simulates ``SIMS`` windows of 0.5 s at h = 1 µs, 16 lanes per group, recording
10 kHz interval means of the position. The latency target is a share of its time with the groups run
one after another on one thread, the reading that matches the target's own figures
(docs/benchmarks.md); spread over every core with ``prange`` it runs ~2x faster on two cores, and
the benchmarks give the share of that too.

Per lane and 1 µs step (SI): ω_ref = sat(G_P·(θ_cmd − θ_u)), I_ref = sat(GAP·(ω_ref − ω)/k_T),
V = ±V_max, I += h·(V − R·I − k_T·ω)/L, T_M = sat(k_T·I), a constant hinge load T_ext at the shaft,
Coulomb friction with a stick band, ω += h·(T_M + T_ext − C·ω − T_F)/J, θ_m += h·ω.
"""

from __future__ import annotations

import time

import numpy as np
from numba import get_num_threads, njit, prange, set_num_threads

from ema.model.bounds import DEFAULT_SAMPLE_RATE_HZ

SIMS = 500
LANES = 16
DURATION_S = 0.5
YARDSTICK_STEP_S = 1e-6
RATE_HZ = DEFAULT_SAMPLE_RATE_HZ
# Table 3.1's drive (the yardstick needs numbers, not our document types)
G_P, GAP, R, L, K_T, T_MAX, V_MAX, I_MAX, N, J, C = (
    1e5,
    0.05,
    2.13,
    7.2e-4,
    0.0752,
    1.689,
    48.0,
    22.5,
    500.0,
    2.5e-5,
    5.172e-5,
)


@njit(cache=True)
def _group(command_rad: np.ndarray, fdj: np.ndarray, load_nm: np.ndarray, steps: int, per_sample: int) -> np.ndarray:
    """(LANES, samples) interval means of θ_u [rad] for one group: ``command_rad`` (samples,),
    ``fdj`` and ``load_nm`` (LANES,) per lane. Written as a careful engineer would without our
    kernel's tricks: constants hoisted, selects rather than branches, one pass per step."""
    samples = steps // per_sample
    out = np.zeros((LANES, samples))
    current = np.zeros(LANES)
    speed = np.zeros(LANES)
    angle = np.zeros(LANES)
    omega_max = V_MAX / K_T
    h_over_l, h_over_j, gap_over_kt, weight = YARDSTICK_STEP_S / L, YARDSTICK_STEP_S / J, GAP / K_T, 1.0 / per_sample
    for k in range(steps):
        target = command_rad[k // per_sample]
        sample = k // per_sample
        for lane in range(LANES):
            w = speed[lane]
            theta_u = angle[lane] / N
            w_ref = min(max(G_P * (target - theta_u), -omega_max), omega_max)
            i_ref = min(max(gap_over_kt * (w_ref - w), -I_MAX), I_MAX)
            volts = V_MAX if i_ref > current[lane] else -V_MAX
            current[lane] += h_over_l * (volts - R * current[lane] - K_T * w)
            drive = min(max(K_T * current[lane], -T_MAX), T_MAX) + load_nm[lane] / N - C * w
            stuck = w == 0.0 and abs(drive) <= fdj[lane]
            direction = 1.0 if (w > 0.0 or (w == 0.0 and drive > 0.0)) else -1.0
            friction = drive if stuck else direction * fdj[lane]
            new_speed = w + h_over_j * (drive - friction)
            new_speed = 0.0 if new_speed * w < 0.0 else new_speed
            speed[lane] = new_speed
            angle[lane] += YARDSTICK_STEP_S * new_speed
            out[lane, sample] += theta_u * weight
    return out


@njit(parallel=True, cache=True)
def _all(command_rad: np.ndarray, fdj: np.ndarray, load_nm: np.ndarray, steps: int, per_sample: int) -> float:
    """Every group, in parallel; returns a checksum so the work cannot be optimized away."""
    groups = fdj.shape[0] // LANES
    sums = np.zeros(groups)
    for g in prange(groups):
        lanes = slice(g * LANES, (g + 1) * LANES)
        sums[g] = _group(command_rad, fdj[lanes], load_nm[lanes], steps, per_sample).sum()
    return sums.sum()


def yardstick_seconds(repeats: int = 2, threads: int | None = None) -> float:
    """Best wall time of ``SIMS`` × 0.5 s on the yardstick kernel, compiled (or loaded) outside the timing,
    its groups over ``threads`` (None: every thread Numba has; 1: one group after another)."""
    rng = np.random.default_rng(0)
    per_sample = round(1.0 / (RATE_HZ * YARDSTICK_STEP_S))
    samples = round(DURATION_S * RATE_HZ)
    sims = -(-SIMS // LANES) * LANES
    command = np.radians(20.0) * np.sin(2 * np.pi * 2.0 * np.arange(samples) / RATE_HZ)
    fdj = rng.uniform(0.04, 0.06, sims)
    load = rng.uniform(-100.0, 100.0, sims)
    _all(command[:2], fdj[:LANES], load[:LANES], 2 * per_sample, per_sample)
    before = get_num_threads()
    set_num_threads(threads or before)
    try:
        best = np.inf
        for _ in range(repeats):
            start = time.perf_counter()
            _all(command, fdj, load, samples * per_sample, per_sample)
            best = min(best, time.perf_counter() - start)
    finally:
        set_num_threads(before)
    return float(best)


if __name__ == "__main__":  # python -m ema.cli.yardstick
    for count in (1, None):
        seconds = yardstick_seconds(threads=count)
        print(f"yardstick: {SIMS} x {DURATION_S} s on a 16-lane kernel, {count or 'every'} thread(s): {seconds:.3f} s")
