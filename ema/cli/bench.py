"""``ema bench``: the end-to-end latency of one window -> estimates, idle and beside other work.

Warm first (kernels compiled or loaded, the pipeline's modules imported), then for each window duration run the
whole pipeline on fresh synthetic windows with a known truth and realistic noise (the §5.6
command, health drawn in Table 3.1's ranges), and record every stage's time, the real-time factor
(pipeline seconds per second of window) and the error reached. With ``--under-load N`` the same
windows are timed again while N CPU-bound processes run beside (an onboard computer is shared).
Figures from one run are compared as ratios: this machine's speed drifts ~2x from day to day. So the
same run times the simulation kernel alone (ns per simulation-step) and a yardstick, an independent
16-lane kernel of the same EMA (``ema.cli.yardstick``), and states each latency as a share of it.
"""

from __future__ import annotations

import gc
import itertools
import json
import math
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from ema.cli.benchmark_docs import BENCHMARKS_MD, write_section
from ema.cli.yardstick import DURATION_S, SIMS, yardstick_seconds
from ema.estimate import thread_budget
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import STAGES as PIPELINE_STAGES
from ema.estimate.report import share_of_range
from ema.kinds import estimate_thesis_window, thesis_kernel_seconds, thesis_window
from ema.model.actuator import THESIS
from ema.model.bounds import DEFAULT_SAMPLE_RATE_HZ
from ema.model.params import DEFAULT_RANGES, HealthParams

TIMED_STAGES = (*PIPELINE_STAGES, "total")
TARGET_SHARE = 0.128  # a 0.5 s window's idle p95 as a share of the yardstick: the latency target
CONFIDENCE = 0.9  # a verdict on the p95 is given when it holds at this confidence, else more windows are asked for
BUSY = "import itertools\nfor _ in itertools.count(): pass"


@contextmanager
def load(processes: int) -> Iterator[None]:
    """``processes`` CPU-bound Python processes running beside, for the duration of the block."""
    busy = [subprocess.Popen([sys.executable, "-c", BUSY]) for _ in range(processes)]
    try:
        yield
    finally:
        for process in busy:
            process.kill()
            process.wait()


def time_windows(config: PipelineConfig, duration_s: float, repeats: int, seed: int) -> dict[str, Any]:
    """p50/p95 per stage, the real-time factor and the mean error over ``repeats`` windows."""
    rng = np.random.default_rng(seed)
    timings: dict[str, list[float]] = {stage: [] for stage in TIMED_STAGES}
    errors: dict[str, list[float]] = {"FDJ": [], "eta_O": []}
    for repeat in range(repeats):
        truth = HealthParams.uniform(1, DEFAULT_RANGES, rng)
        window = thesis_window(truth, seed=seed + repeat, duration_s=duration_s)
        result = estimate_thesis_window(window, config)
        for stage in TIMED_STAGES:
            timings[stage].append(getattr(result.timings_s, stage))
        estimates, ranges = result.estimates, THESIS.ranges
        errors["FDJ"].append(share_of_range("FDJ", abs(estimates.FDJ.value - truth.fdj_nm[0]), ranges))
        if estimates.eta_O is not None:
            errors["eta_O"].append(share_of_range("eta_O", abs(estimates.eta_O.value - truth.eta_o[0]), ranges))
        print(f"  {duration_s:g} s window #{repeat + 1}: {result.timings_s.total:.2f} s", file=sys.stderr)
    return {
        "duration_s": duration_s,
        "p50_s": {s: float(np.median(v)) for s, v in timings.items()},
        "p95_s": {s: float(np.percentile(v, 95)) for s, v in timings.items()},
        "real_time_factor_p50": float(np.median(timings["total"])) / duration_s,
        "real_time_factor_p95": float(np.percentile(timings["total"], 95)) / duration_s,
        "error_pct_of_range": {k: 100 * float(np.mean(v)) for k, v in errors.items()},
        "total_s": timings["total"],  # every window's, for the verdict's bounds
    }


def references() -> dict[str, float]:
    """The yardstick's seconds and our kernel's ns per simulation-step on the same ``SIMS`` × 0.5 s, this run."""
    rate_hz, steps_per_sample = DEFAULT_SAMPLE_RATE_HZ, 100
    samples = round(DURATION_S * rate_hz)
    best, lanes = thesis_kernel_seconds(SIMS, samples, rate_hz)
    steps = SIMS * samples * steps_per_sample
    return {
        "yardstick_s": yardstick_seconds(threads=1),
        "yardstick_every_thread_s": yardstick_seconds(),
        "kernel_s": float(best),
        "kernel_ns_per_step": 1e9 * best / steps,
        "lanes": lanes,
    }


def p95_bounds(seconds: list[float], confidence: float = CONFIDENCE) -> tuple[float, float | None]:
    """Distribution-free one-sided bounds on the p95 of what ``seconds`` were drawn from: the order statistics
    X_(j) <= p95 and X_(k) >= p95, each at ``confidence`` (the count of draws below the p95 is Binomial(n, 0.95)).
    The upper bound is None where n draws cannot give one: below 45 at 90 %, even the slowest of them sits
    below the p95 too often."""
    ordered, n = sorted(seconds), len(seconds)
    below = [math.comb(n, i) * 0.95**i * 0.05 ** (n - i) for i in range(n + 1)]  # P(i draws below the p95)
    cumulative = list(itertools.accumulate(below))  # P(at most i below)
    upper = next((ordered[k - 1] for k in range(1, n + 1) if cumulative[k - 1] >= confidence), None)
    lower = next((ordered[j - 1] for j in range(n, 0, -1) if 1.0 - cumulative[j - 1] >= confidence), ordered[0])
    return lower, upper


def verdict(seconds: list[float], yardstick_s: float) -> str:
    """Met, not met, or cannot tell (with the repeats to ask for): the p95's bounds against the target share."""
    lower, upper = p95_bounds(seconds)
    n, known = len(seconds), f"{CONFIDENCE:.0%} sure"
    if upper is not None and upper / yardstick_s <= TARGET_SHARE:
        return f"met: p95 ≤ {upper / yardstick_s:.3f} ({known}, {n} windows)"
    if lower / yardstick_s > TARGET_SHARE:
        return f"not met: p95 ≥ {lower / yardstick_s:.3f} ({known}, {n} windows)"
    bound = "unbounded" if upper is None else f"{upper / yardstick_s:.3f}"
    return (
        f"cannot tell from {n} windows (p95 between {lower / yardstick_s:.3f} and {bound}, {known}): "
        f"run --repeats {max(2 * n, 45)}"
    )


def reference_lines(rows: list[dict[str, Any]], refs: dict[str, float]) -> list[str]:
    """The kernel's and the yardstick's figures, and each latency as a share of the yardstick: on one thread
    (the target's measure) and on every thread (twice as fast on two cores, so a share twice as strict)."""
    lines = [
        f"Same run: our kernel simulates {SIMS} x {DURATION_S:g} s in {refs['kernel_s']:.3f} s "
        f"({refs['kernel_ns_per_step']:.2f} ns per simulation-step, {refs['lanes']} lanes a group, every thread "
        "of the budget); "
        f"the yardstick (`ema/cli/yardstick.py`, an independent 16-lane kernel) in {refs['yardstick_s']:.3f} s on one "
        f"thread, {refs['yardstick_every_thread_s']:.3f} s on every thread.",
        "",
        "| load | window | total p50 / yardstick | total p95 / yardstick | p95 / yardstick on every thread "
        "| target (0.5 s, idle p95) | verdict |",
        "|---|---:|---:|---:|---:|---:|---|",
    ]
    for r in rows:
        p50, p95 = r["p50_s"]["total"], r["p95_s"]["total"]
        share = p95 / refs["yardstick_s"]
        judged = r["duration_s"] == DURATION_S and r["load"] == "idle"
        target = f"≤ {TARGET_SHARE}" if judged else ""
        said = verdict(r["total_s"], refs["yardstick_s"]) if judged else ""
        lines.append(
            f"| {r['load']} | {r['duration_s']:g} s | {p50 / refs['yardstick_s']:.3f} "
            f"| {share:.3f} | {p95 / refs['yardstick_every_thread_s']:.3f} | {target} | {said} |"
        )
    return lines


def stage_factors(rows: list[dict[str, Any]]) -> list[str]:
    """Each stage's real-time factor (its seconds per second of window), p50 (p95)."""
    lines = [
        "| load | window | " + " | ".join(TIMED_STAGES) + " |",
        "|---|---:|" + "---:|" * len(TIMED_STAGES),
    ]
    for r in rows:
        d = r["duration_s"]
        cells = " | ".join(f"{r['p50_s'][s] / d:.3f} ({r['p95_s'][s] / d:.3f})" for s in TIMED_STAGES)
        lines.append(f"| {r['load']} | {d:g} s | {cells} |")
    return lines


def markdown(rows: list[dict[str, Any]], config: PipelineConfig, refs: dict[str, float] | None = None) -> str:
    lines = [
        "One synthetic window (§5.6 command, realistic sensor noise, health uniform in Table 3.1's ranges) ->",
        f"estimates, in-process (`ema.kinds.estimate_thesis_window`, what the service runs), "
        f"{config.n_simulations} + {config.check_simulations} simulations, {config.hidden_units} neurons.",
        "p50 (p95) seconds per stage; real-time factor = pipeline seconds per second of window (≤ 1: real time);",
        "error = mean |error| in % of the thesis's range (0.02 N·m for FDJ, 0.30 for η_O).",
        "Windows run back to back, so beside busy processes this loop keeps a core of its own; a service",
        "waiting between requests does not (*Real time on a warm service* measures one).",
        "",
        "| load | window | " + " | ".join(TIMED_STAGES) + " | real-time factor p50 (p95) | error FDJ / η_O |",
        "|---|---:|" + "---:|" * (len(TIMED_STAGES) + 2),
    ]
    for r in rows:
        cells = " | ".join(f"{r['p50_s'][s]:.2f} ({r['p95_s'][s]:.2f})" for s in TIMED_STAGES)
        error = f"{r['error_pct_of_range']['FDJ']:.2f} % / {r['error_pct_of_range']['eta_O']:.2f} %"
        rtf = f"{r['real_time_factor_p50']:.2f} ({r['real_time_factor_p95']:.2f})"
        lines.append(f"| {r['load']} | {r['duration_s']:g} s | {cells} | {rtf} | {error} |")
    lines += ["", "Real-time factor per stage, p50 (p95):", "", *stage_factors(rows)]
    if refs:
        lines += ["", *reference_lines(rows, refs)]
    return "\n".join(lines)


def run_bench(
    config: PipelineConfig, durations: list[float], *, repeats: int, under_load: int, out: Path | None, docs: bool
) -> dict[str, Any]:
    thread_budget.configure()
    print("warming up (JIT compile or cache load, imports)…", file=sys.stderr)
    estimate_thesis_window(thesis_window(HealthParams.single(), seed=0, duration_s=0.1), config)
    gc.freeze()  # as the warm service does: what was loaded is never walked by a full collection again
    rows = [{**time_windows(config, d, repeats, seed=100), "load": "idle"} for d in durations]
    if under_load:
        with load(under_load):
            rows += [
                {
                    **time_windows(config, d, repeats, seed=100),
                    "load": f"{under_load} busy process{'es' if under_load != 1 else ''}",
                }
                for d in durations
            ]
    print("timing the kernel and the yardstick…", file=sys.stderr)
    refs = references()
    written = None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        written = out / "bench.json"
        written.write_text(json.dumps({"rows": rows, "references": refs}, indent=2))
        print(f"ema bench: figures written to {written}", file=sys.stderr)
    table = markdown(rows, config, refs)
    if docs:
        command = f"ema bench --repeats {repeats} --durations {','.join(f'{d:g}' for d in durations)}"
        write_section(
            "Pipeline latency",
            command + (f" --under-load {under_load}" if under_load else "") + " --docs",
            table,
            BENCHMARKS_MD,
        )
    return {"rows": rows, "references": refs, "json": None if written is None else str(written), "table": table}
