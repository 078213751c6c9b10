"""A real actuator: the Cranfield ball-screw rig's measured runs, read with what 25 Hz allows (docs/results.md).

C. Ruiz-Carcel and A. Starr, "Data-based detection and diagnosis of faults in linear actuators", IEEE Trans.
Instrumentation and Measurement, 2018; data: Cranfield University, CORD, article 5097649. The runs are
``examples/ballscrew-rig/runs`` (``../shared/data/ballscrew-rig`` beside a checkout, or ``--runs``).

The drive is learned (``ema calibrate``'s linear path) on the first half of the healthy runs at each load;
every other run is then read with the completed document, as ``ema estimate --log-map`` reads it: per
state and load, the median FDJ, the runs' own stds, their scatter, how many runs' ±2 std hold their
set's median, and the steps between states in stds. A figure shows every run's FDJ ± 2 std.

    python -m benchmarks.real_rig [--runs DIR] [--docs]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ema.calibration.linear_report import calibrate_linear
from ema.cli.report import write_section
from ema.estimate.kinds import estimate
from ema.model.actuator import read_actuator
from ema.model.logmap import read_logmap, read_mapped
from ema.model.window import window_from_dict

ROOT = Path(__file__).resolve().parent.parent
RIG = ROOT / "examples" / "ballscrew-rig"
SETS = [("normal", 20), ("normal", 40), ("lackLubrication1", 20)]


def windows(folder: Path, state: str, load: int, which: slice) -> list:
    mapping = read_logmap(RIG / "log-map.json")
    paths = sorted(folder.glob(f"{state}_load{load}_run*.csv"))[which]
    return [window_from_dict(read_mapped(path, mapping)) for path in paths]


def figure(rows: dict[str, np.ndarray], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 3.6))
    x = 0
    for name, values in rows.items():
        xs = np.arange(x, x + len(values))
        ax.errorbar(xs, values[:, 0], yerr=2 * values[:, 1], fmt="o", ms=4, capsize=2, label=name)
        ax.hlines(np.median(values[:, 0]), xs[0] - 0.4, xs[-1] + 0.4, colors="grey", linestyles="dashed")
        x += len(values) + 1
    ax.set_ylabel("FDJ [N·m], ±2 std")
    ax.set_xticks([])
    ax.set_title("Cranfield ball-screw rig (Ruiz-Carcel & Starr 2018): runs the calibration did not see")
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path, default=RIG / "runs")
    parser.add_argument("--docs", action="store_true", help="rewrite its section of docs/results.md and its figure")
    args = parser.parse_args()
    document = read_actuator(RIG / "actuator.json")
    first = slice(0, 5)
    report, learned = calibrate_linear(
        windows(args.runs, "normal", 20, first) + windows(args.runs, "normal", 40, first), document
    )
    assert learned is not None and report.drive is not None
    rows: dict[str, np.ndarray] = {}
    for state, load in SETS:
        held = slice(5, None) if state == "normal" else slice(None)
        results = [estimate(w, actuator=learned) for w in windows(args.runs, state, load, held)]
        rows[f"{state} {load} kgf"] = np.array([(r.estimates.FDJ.value, r.estimates.FDJ.std) for r in results])
    body = _body(report.drive, rows)
    print(body)
    if args.docs:
        figure(rows, ROOT / "docs" / "figures" / "rig_fdj.png")
        write_section(
            "A real actuator: the Cranfield ball-screw rig",
            "python -m benchmarks.real_rig --docs",
            body,
            ROOT / "docs" / "results.md",
        )


def _body(drive, rows: dict[str, np.ndarray]) -> str:
    table = [
        "| state, load | runs | median FDJ [N·m] | median std | scatter (std of runs) | ±2 std holds the median |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for name, values in rows.items():
        median = float(np.median(values[:, 0]))
        held = int(np.sum(np.abs(values[:, 0] - median) <= 2 * values[:, 1]))
        table.append(
            f"| {name} | {len(values)} | {median:.3f} | {np.median(values[:, 1]):.3f} | "
            f"{values[:, 0].std(ddof=1):.3f} | {held}/{len(values)} |"
        )
    medians = {name: float(np.median(v[:, 0])) for name, v in rows.items()}
    std = float(np.median(np.concatenate([v[:, 1] for v in rows.values()])))
    names = list(rows)
    steps = (
        f"Between the loads, the healthy medians differ by {abs(medians[names[0]] - medians[names[1]]):.3f} "
        f"N·m ({abs(medians[names[0]] - medians[names[1]]) / std:.1f} stds); lack of lubrication (stage 1) "
        f"raises FDJ by {medians[names[2]] - medians[names[0]]:+.3f} N·m at 20 kgf "
        f"({(medians[names[2]] - medians[names[0]]) / std:.1f} stds of one run)."
    )
    learned = (
        f"Learned on 10 healthy runs (5 at 20 kgf, 5 at 40 kgf): current per N·m c = "
        f"{drive.current_per_nm_a:.3f} ± {drive.current_per_nm_std_a:.3f} A/(N·m), current at zero torque "
        f"{drive.current_at_zero_torque_a:.3f} ± {drive.current_at_zero_torque_std_a:.3f} A, nominal FDJ "
        f"{drive.fdj_nm:.3f} ± {drive.fdj_std_nm:.3f} N·m, η_O {drive.eta_o:.2f} ± {drive.eta_o_std:.2f}, "
        f"repeatability {drive.repeatability_nm:.3f} N·m. Not separable: {'; '.join(drive.not_separable)}."
    )
    return "\n".join([learned, "", *table, "", steps, "", "![every run's FDJ ± 2 std](figures/rig_fdj.png)"])


if __name__ == "__main__":
    main()
