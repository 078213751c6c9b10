"""A real actuator: the Cranfield ball-screw rig's measured runs, read with what 25 Hz allows (docs/results.md).

C. Ruiz-Carcel and A. Starr, "Data-based detection and diagnosis of faults in linear actuators", IEEE Trans.
Instrumentation and Measurement, 2018; data: Cranfield University, CORD, article 5097649. The runs are
``examples/ballscrew-rig/runs`` (``../shared/data/ballscrew-rig`` beside a checkout, or ``--runs``).

Every (state, load) in the folder is read (file names as the data set's: ``<state>_load<kgf>_run<n>.csv``).
The drive is learned (``ema calibrate``'s linear path) on the first five healthy runs at each positive load;
every other run is then read with the completed document, as ``ema estimate --log-map`` reads it: per
state and load, the median FDJ, the runs' own stds, their scatter, how many runs' ±2 std hold their
set's median, and the steps between states in stds. A figure shows every run's FDJ ± 2 std.

    python -m benchmarks.real_rig [--runs DIR] [--docs]
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np

from ema.calibration.linear_report import calibrate_linear
from ema.cli.report import write_section
from ema.kinds import estimate
from ema.model.actuator import read_actuator
from ema.model.logmap import read_logmap, read_mapped
from ema.model.window import window_from_dict

ROOT = Path(__file__).resolve().parent.parent
RIG = ROOT / "examples" / "ballscrew-rig"
RUN = re.compile(r"^(?P<state>[A-Za-z0-9]+)_load(?P<load>-?[0-9]+)_run[0-9]+\.csv$")  # the data set's file names
HEALTHY = "normal"
CITATION = (
    "Measured runs of an electromechanical actuator rig with seeded faults (C. Ruiz-Carcel and A. Starr, "
    '"Data-based detection and diagnosis of faults in linear actuators", IEEE Transactions on Instrumentation '
    "and Measurement, 2018; data set: Cranfield University, CORD, article 5097649): a ball screw of 5 mm lead "
    "turned by a NEMA 34 stepper, loaded through a load cell, logged at 25 Hz. Each run is read with "
    "`examples/ballscrew-rig/` after `ema calibrate` learned the drive; the runs that taught it are not in the "
    "table."
)
LIMITS = (
    "What 25 Hz cannot show: the motor's dynamics (its inertia, its speed loop), which act within a sample; the "
    "runs are read only where the speed holds (stretches of constant speed). η_O is read only where runs at two "
    "load sizes are read together: in one run at one load, FDJ and η_O are one number, and the table's FDJ is "
    "read at the learned nominal η_O. A local defect (a spall) shows only as a rise of the current along the "
    "stroke larger than one run's scatter."
)
LEARN_RUNS = 5  # the first runs of each healthy load teach the drive; the rest are held out


def sets(folder: Path) -> list[tuple[str, int]]:
    """Every (state, load) the folder holds runs of, healthy first, then by load and name."""
    found = {(m["state"], int(m["load"])) for p in folder.glob("*.csv") if (m := RUN.match(p.name))}
    return sorted(found, key=lambda s: (s[0] != HEALTHY, s[1], s[0]))


def windows(folder: Path, state: str, load: int, which: slice) -> list:
    mapping = read_logmap(RIG / "log-map.json")
    paths = sorted(p for p in folder.glob(f"{state}_load{load}_run*.csv") if RUN.match(p.name))[which]
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
    found = sets(args.runs)
    first = slice(0, LEARN_RUNS)
    teach = [
        w for state, load in found if state == HEALTHY and load > 0 for w in windows(args.runs, state, load, first)
    ]
    report, learned, _ = calibrate_linear(teach, document)
    assert learned is not None and report.drive is not None
    rows: dict[str, np.ndarray] = {}
    said: dict[str, str] = {}
    for state, load in found:
        held = slice(LEARN_RUNS, None) if state == HEALTHY and load > 0 else slice(None)
        runs = windows(args.runs, state, load, held)
        results = [estimate(w, actuator=learned) for w in runs]
        rows[f"{state} {load} kgf"] = np.array([(r.estimates.FDJ.value, r.estimates.FDJ.std) for r in results])
        said[f"{state} {load} kgf"] = _compared(runs, learned)
    body = "\n".join([CITATION, "", _body(report.drive, rows), "", *_calibrations(said), "", LIMITS])
    print(body)
    if args.docs:
        figure(rows, ROOT / "docs" / "figures" / "rig_fdj.png")
        write_section(
            "A real actuator: the Cranfield ball-screw rig",
            "python -m benchmarks.real_rig --docs",
            body,
            ROOT / "docs" / "results.md",
        )


def _compared(runs: list, learned) -> str:
    """What ``ema calibrate`` says of ``runs`` against the learned healthy baseline: FDJ's change, then the stroke."""
    if len(runs) < 2:
        return "too few runs to compare"
    report, _, _ = calibrate_linear(runs, learned)
    return f"{report.changes[0].said}; {report.selection_steps[0].reason}"


def _calibrations(said: dict[str, str]) -> list[str]:
    return [
        "`ema calibrate` on each set's held-out runs, against the learned document (the healthy baseline):",
        "",
        "| state, load | what it says |",
        "|---|---|",
        *(f"| {name} | {text} |" for name, text in said.items()),
    ]


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
    steps = []
    for name, median in medians.items():
        state, load = name.split()[0], name.split()[1]
        base = f"{HEALTHY} {load} kgf"
        if state != HEALTHY and base in medians:
            change = median - medians[base]
            steps.append(f"{state} at {load} kgf: FDJ {change:+.3f} N·m ({change / std:+.1f} stds of one run).")
    healthy = [medians[n] for n in medians if n.startswith(HEALTHY + " ")]
    spread = max(healthy) - min(healthy)
    steps.insert(0, f"Healthy, across its loads: the medians span {spread:.3f} N·m ({spread / std:.1f} stds).")
    learned = (
        f"Learned on the first {LEARN_RUNS} healthy runs at each positive load: current per N·m c = "
        f"{drive.current_per_nm_a:.3f} ± {drive.current_per_nm_std_a:.3f} A/(N·m), current at zero torque "
        f"{drive.current_at_zero_torque_a:.3f} ± {drive.current_at_zero_torque_std_a:.3f} A, nominal FDJ "
        f"{drive.fdj_nm:.3f} ± {drive.fdj_std_nm:.3f} N·m, η_O {drive.eta_o:.2f} ± {drive.eta_o_std:.2f}, "
        f"repeatability {drive.repeatability_nm:.3f} N·m. Not separable: {'; '.join(drive.not_separable)}."
    )
    return "\n".join([learned, "", *table, "", *steps, "", "![every run's FDJ ± 2 std](figures/rig_fdj.png)"])


if __name__ == "__main__":
    main()
