"""ema bench's report: the latency as a share of a yardstick timed in the same run, and the yardstick itself."""

import numpy as np
import pytest

from ema.cli.bench import CONFIDENCE, TARGET_SHARE, p95_bounds, reference_lines, stage_factors, verdict
from ema.cli.yardstick import LANES, _group


def _row(load: str, duration_s: float, total_s: float, n: int = 60) -> dict:
    stages = {s: 0.0 for s in ("prepare", "physics", "simulate", "learn", "assess", "check", "report")}
    stages["simulate"] = total_s
    return {
        "load": load,
        "duration_s": duration_s,
        "p50_s": {**stages, "total": total_s},
        "p95_s": {**stages, "total": 2 * total_s},
        "total_s": list(np.linspace(total_s, 2 * total_s, n)),
    }


def test_latency_is_stated_as_a_share_of_the_yardstick_and_the_target_named_once():
    rows = [_row("idle", 0.5, 0.1), _row("idle", 2.0, 0.4), _row("2 busy processes", 0.5, 0.2)]
    refs = {"yardstick_s": 1.0, "yardstick_every_thread_s": 0.5, "kernel_s": 0.5, "kernel_ns_per_step": 2.0, "lanes": 8}
    lines = reference_lines(rows, refs)
    assert "2.00 ns per simulation-step" in lines[0]
    table = [line for line in lines if line.startswith("| idle") or line.startswith("| 2 busy")]
    said = "not met: p95 ≥ 0.19" if TARGET_SHARE < 0.19 else "met"
    assert table[0].startswith(f"| idle | 0.5 s | 0.100 | 0.200 | 0.400 | ≤ {TARGET_SHARE} | {said}")
    assert table[1].endswith("|  |  |") and table[2].endswith("|  |  |")  # the target is the idle 0.5 s window's only


def test_stage_factors_divide_each_stage_by_the_window_duration():
    lines = stage_factors([_row("idle", 2.0, 0.4)])
    assert "| learn | assess |" in lines[0] and "predict" not in lines[0] and "train" not in lines[0]
    assert "| 0.200 (0.200) |" in lines[2]  # simulate: 0.4 s of a 2 s window


def test_yardstick_drives_the_elevator_to_its_command_and_holds_it():
    steps_per_sample, samples = 100, 1000  # 0.1 s at 10 kHz
    command = np.full(samples, np.radians(2.0))
    out = _group(command, np.full(LANES, 0.05), np.zeros(LANES), steps_per_sample * samples, steps_per_sample)
    assert out.shape == (LANES, samples)
    assert np.allclose(out[:, -1], np.radians(2.0), atol=np.radians(0.05))  # arrived and held
    assert np.all(np.diff(out[:, :50], axis=1) >= 0)  # moving towards it, never back


@pytest.mark.parametrize("n", [45, 80, 200])
def test_the_p95_bounds_hold_the_true_p95_as_often_as_they_say(n):
    """Draws of a lognormal latency (not the product's): each one-sided bound holds its p95 at least CONFIDENCE
    of the time, less a sampling margin over 2000 runs."""
    rng = np.random.default_rng(n)
    true_p95 = float(np.exp(np.log(0.12) + 0.2 * 1.6448536))
    bounds = [p95_bounds(list(rng.lognormal(np.log(0.12), 0.2, n))) for _ in range(2000)]
    assert np.mean([lower <= true_p95 for lower, _ in bounds]) >= CONFIDENCE - 0.02
    assert np.mean([upper is not None and upper >= true_p95 for _, upper in bounds]) >= CONFIDENCE - 0.02


def test_a_short_run_asks_for_more_windows_instead_of_a_verdict_it_cannot_give():
    fast = [0.05] * 9 + [0.06]  # every one far below the target: still, 10 draws cannot bound a p95 from above
    assert p95_bounds(fast)[1] is None
    assert verdict(fast, yardstick_s=1.0).startswith("cannot tell from 10 windows") and "--repeats 45" in verdict(
        fast, yardstick_s=1.0
    )
    assert verdict([0.05] * 45, yardstick_s=1.0).startswith("met")
    assert verdict([0.5] * 10, yardstick_s=1.0).startswith("not met")  # slow enough to say so from a few
