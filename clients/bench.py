"""``ema bench``: the end-to-end latency of one window -> estimates, over a grid of sizes.

Warm first (kernels compiled or loaded, torch initialized), then for each size run the whole
pipeline on fresh synthetic windows with a known truth and record every stage's time and the
error reached. Figures: median and p95 per stage, the mean absolute relative error of FDJ and
η_O, and the ratio against the thesis (≈ 90 s for 500 simulations + training on 4 cores, §6.3).
Writes bench.json and bench.png into --out, and a section of docs/benchmarks.md.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from clients.report import write_section
from sim.params import DEFAULT_RANGES, HealthParams
from sim.synthetic import synthetic_window
from training.pipeline import PipelineConfig, estimate_window

THESIS_CADENCE_S = 90.0  # §6.3: 1000 timesteps, 500 sims, 100 neurons on the thesis's 4-core PC
THESIS_PROJECTED_S = 20.0  # §6.3: the update period it projected for an onboard system
DEFAULT_GRID = ((250, 500, 50), (500, 1000, 100), (1000, 1000, 100), (1000, 2000, 200))
STAGES = ("simulate", "train", "predict", "total")


def run_size(sims: int, timesteps: int, hidden: int, repeats: int, seed: int) -> dict[str, Any]:
    rng = np.random.default_rng(seed)
    timings: dict[str, list[float]] = {stage: [] for stage in STAGES}
    errors = []
    for repeat in range(repeats):
        truth = HealthParams.uniform(1, DEFAULT_RANGES, rng)
        window = synthetic_window(truth, seed=seed + repeat)
        result = estimate_window(window, PipelineConfig(n_simulations=sims, n_timesteps=timesteps, hidden_units=hidden))
        for stage in STAGES:
            timings[stage].append(result["timings_s"][stage])
        estimates = result["estimates"]
        errors.append(
            [
                abs(estimates["FDJ"]["value"] / truth.fdj_nm[0] - 1),
                abs(estimates["eta_O"]["value"] / truth.eta_o[0] - 1),
            ]
        )
        print(f"  {sims}x{timesteps}x{hidden} #{repeat + 1}: {result['timings_s']['total']:.2f} s", file=sys.stderr)
    mean_error = 100 * np.mean(errors, axis=0)
    return {
        "n_simulations": sims,
        "n_timesteps": timesteps,
        "hidden_units": hidden,
        "repeats": repeats,
        "median_s": {stage: float(np.median(values)) for stage, values in timings.items()},
        "p95_s": {stage: float(np.percentile(values, 95)) for stage, values in timings.items()},
        "error_pct": {"FDJ": float(mean_error[0]), "eta_O": float(mean_error[1])},
        "speedup_vs_thesis": THESIS_CADENCE_S / float(np.median(timings["total"])),
    }


def markdown(rows: list[dict[str, Any]]) -> str:
    lines = [
        "One synthetic 0.5 s in-flight window at 10 kHz with realistic sensor noise -> estimates, in-process",
        "(`training.pipeline.estimate_window`, what the service runs). Median (p95) seconds per stage;",
        "error = mean |relative error| of FDJ / η_O against the window's truth; thesis: ≈ 90 s for",
        f"500 simulations + training on 4 cores, update period projected at {THESIS_PROJECTED_S:g} s (§6.3).",
        "Target: ≤ 2 s end to end at the default size (500 x 1000 x 100).",
        "",
        "| sims x timesteps x hidden | simulate | train | predict | total | error FDJ / η_O | vs thesis 90 s |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        cells = [f"{r['median_s'][s]:.2f} ({r['p95_s'][s]:.2f})" for s in STAGES]
        size = f"{r['n_simulations']} x {r['n_timesteps']} x {r['hidden_units']}"
        error = f"{r['error_pct']['FDJ']:.2f} % / {r['error_pct']['eta_O']:.2f} %"
        lines.append(f"| {size} | {' | '.join(cells)} | {error} | {r['speedup_vs_thesis']:.0f}x faster |")
    return "\n".join(lines)


def plot(rows: list[dict[str, Any]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = [f"{r['n_simulations']}x{r['n_timesteps']}x{r['hidden_units']}" for r in rows]
    figure, axis = plt.subplots(figsize=(7, 4))
    bottom = np.zeros(len(rows))
    for stage in STAGES[:-1]:
        heights = np.array([r["median_s"][stage] for r in rows])
        axis.bar(labels, heights, bottom=bottom, label=stage)
        bottom += heights
    axis.axhline(2.0, color="black", ls="--", lw=1, label="2 s target")
    axis.set(ylabel="median seconds per window", title="ema: one window -> estimates")
    axis.legend()
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


def command_bench(args: Any) -> dict[str, Any]:
    from sim.checks import InputError

    grid = DEFAULT_GRID if not args.quick else ((100, 250, 30),)
    if args.repeats < 1:
        raise InputError("--repeats", f"must be at least 1, got {args.repeats}")
    print("warming up (JIT compile or cache load, torch start)…", file=sys.stderr)
    estimate_window(synthetic_window(HealthParams.single(), seed=0), PipelineConfig(n_simulations=40))
    rows = [run_size(*size, repeats=args.repeats, seed=100) for size in grid]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "bench.json").write_text(json.dumps(rows, indent=2))
    plot(rows, out / "bench.png")
    if not args.quick and args.docs.parent.is_dir():
        write_section("Pipeline latency", f"ema bench --repeats {args.repeats}", markdown(rows), args.docs)
    elif not args.quick:
        print(f"{args.docs.parent} does not exist: the table is not written there", file=sys.stderr)
    return {"rows": rows, "json": str(out / "bench.json"), "plot": str(out / "bench.png"), "table": markdown(rows)}
