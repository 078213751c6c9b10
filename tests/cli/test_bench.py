"""ema bench's report: the latency as a share of a yardstick timed in the same run, and the yardstick itself."""

import numpy as np

from ema.cli.bench import TARGET_SHARE, reference_lines, stage_factors
from ema.cli.yardstick import LANES, _group


def _row(load: str, duration_s: float, total_s: float) -> dict:
    stages = {s: 0.0 for s in ("prepare", "physics", "simulate", "learn", "assess", "check", "report")}
    stages["simulate"] = total_s
    return {
        "load": load,
        "duration_s": duration_s,
        "p50_s": {**stages, "total": total_s},
        "p95_s": {**stages, "total": 2 * total_s},
    }


def test_latency_is_stated_as_a_share_of_the_yardstick_and_the_target_named_once():
    rows = [_row("idle", 0.5, 0.1), _row("idle", 2.0, 0.4), _row("2 busy processes", 0.5, 0.2)]
    refs = {"yardstick_s": 1.0, "yardstick_every_thread_s": 0.5, "kernel_s": 0.5, "kernel_ns_per_step": 2.0}
    lines = reference_lines(rows, refs)
    assert "2.00 ns per simulation-step" in lines[0]
    table = [line for line in lines if line.startswith("| idle") or line.startswith("| 2 busy")]
    verdict = "met" if TARGET_SHARE >= 0.2 else "not met"
    assert table[0] == f"| idle | 0.5 s | 0.100 | 0.200 | 0.400 | ≤ {TARGET_SHARE} | {verdict} |"
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
