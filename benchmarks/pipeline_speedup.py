"""Today's pipeline against the one this round started from, side by side in one run: docs/benchmarks.md.

The earlier pipeline is checked out of git (commit ``LEGACY``) into a temporary worktree and run in
a subprocess on the very same window files, then today's in this process; both warm first. The
figures are per-window wall times of ``estimate_window`` (its own timing) and the mean error in %
of the thesis's range against the windows' truth.

    python -m benchmarks.pipeline_speedup [--windows 10] [--docs]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from ema.cli.benchmark_docs import typed_command, write_section
from ema.estimate import thread_budget
from ema.estimate.report import share_of_range
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import DEFAULT_RANGES, HealthParams
from ema.model.window import read_window, write_window

LEGACY = "b8987e4"  # the last commit of round 1
ROOT = Path(__file__).resolve().parent.parent
LEGACY_RUN = """
import json, sys, time
from ema.model.window import read_window
from ema.kinds.rotary.pipeline import estimate_window
paths = sys.argv[1:]
estimate_window(read_window(paths[0]))  # warm
out = []
for path in paths:
    result = estimate_window(read_window(path))
    out.append({"total": result["timings_s"]["total"], "FDJ": result["estimates"]["FDJ"]["value"],
                "eta_O": result["estimates"]["eta_O"]["value"]})
print(json.dumps(out))
"""


def windows(folder: Path, n: int) -> tuple[list[Path], list[dict[str, float]]]:
    rng = np.random.default_rng(42)
    paths, truths = [], []
    for i in range(n):
        health = HealthParams.uniform(1, DEFAULT_RANGES, rng)
        path = folder / f"w{i}.json"
        write_window(synthetic_window(health, seed=900 + i), path)
        paths.append(path)
        truths.append({"FDJ": float(health.fdj_nm[0]), "eta_O": float(health.eta_o[0])})
    return paths, truths


def legacy(paths: list[Path], checkout: Path) -> list[dict[str, float]]:
    subprocess.run(
        ["git", "-C", str(ROOT), "worktree", "add", "--force", str(checkout), LEGACY], check=True, capture_output=True
    )
    try:
        env = {"PYTHONPATH": str(checkout), "PATH": "/usr/bin:/bin"}
        done = subprocess.run(
            [sys.executable, "-c", LEGACY_RUN, *map(str, paths)],
            env=env,
            check=True,
            capture_output=True,
            text=True,
            cwd=checkout,
        )
        return json.loads(done.stdout.strip().splitlines()[-1])
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(checkout)], capture_output=True)


def today(paths: list[Path]) -> list[dict[str, float]]:
    thread_budget.configure()
    estimate_window(read_window(paths[0]), actuator=THESIS)  # warm
    out = []
    for path in paths:
        result = estimate_window(read_window(path), actuator=THESIS)
        eta_o = result.estimates.eta_O
        assert eta_o is not None, "a window in flight is loaded: eta_O is read"
        out.append({"total": result.timings_s.total, "FDJ": result.estimates.FDJ.value, "eta_O": eta_o.value})
    return out


def row(name: str, runs: list[dict[str, float]], truths: list[dict[str, float]]) -> str:
    totals = np.array([r["total"] for r in runs])
    errors = {
        k: 100
        * np.mean([share_of_range(k, abs(r[k] - t[k]), THESIS.ranges) for r, t in zip(runs, truths, strict=True)])
        for k in ("FDJ", "eta_O")
    }
    return (
        f"| {name} | {np.median(totals):.2f} | {np.percentile(totals, 95):.2f} | {np.median(totals) / 0.5:.2f} "
        f"| {errors['FDJ']:.2f} % / {errors['eta_O']:.2f} % |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", type=int, default=10)
    parser.add_argument("--docs", action="store_true")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        paths, truths = windows(Path(folder), args.windows)
        old = legacy(paths, Path(folder) / "legacy")
        new = today(paths)
    speedup = np.median([r["total"] for r in old]) / np.median([r["total"] for r in new])
    body = "\n".join(
        [
            f"The same {args.windows} synthetic 0.5 s windows (realistic noise, §5.6 commands, health uniform in",
            f"Table 3.1's ranges) through round 1's pipeline (commit {LEGACY}, 500 + 16 simulations, run from a",
            "git worktree in a subprocess) and today's, one after the other in one run, both warm.",
            "",
            "| pipeline | p50 [s] | p95 [s] | real-time factor p50 | error FDJ / η_O (% of range) |",
            "|---|---:|---:|---:|---:|",
            row(f"round 1 ({LEGACY})", old, truths),
            row("today", new, truths),
            "",
            f"Speed-up at the median: **{speedup:.1f}x**.",
        ]
    )
    print(body)
    if args.docs:
        write_section("Speed-up over round 1, side by side", typed_command(), body)


if __name__ == "__main__":
    main()
