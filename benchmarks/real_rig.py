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
import itertools
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ema.calibration.documents import Change, DriveLearned
from ema.cli.benchmark_docs import write_section
from ema.kinds import estimate
from ema.kinds.linear.calibration_report import calibrate_linear
from ema.model.actuator import LinearActuator, as_kind, read_actuator
from ema.model.logmap import read_logmap, read_mapped
from ema.model.window import window_from_dict
from ema.prognosis.documents import Stored
from ema.prognosis.prognose import prognose
from ema.prognosis.status import status_of

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
    "What the data cannot show, and what ema says of it. At −40 kgf the load's sign is one the healthy runs were "
    "never learned at: the nominal is extrapolated there, and ema says how large a change it cannot show (about "
    "±0.1 N·m); on these runs the opposing stroke's current sits at 1.12–1.13 A and the aiding one's at 0.66–0.69 A "
    "in every state, so no seeded fault departs there, and none is claimed. At the reversals, the position error at "
    "25 Hz is the controller's own lag (3.1–3.6 mm at a stroke's start, ±0.3 mm from run to run): the 0.65 mm "
    "smaller balls of backlash stage 2 leave a lost motion within it, and ema reads backlash through the friction it "
    "changes (a preload lost, or the balls' new contact). The motor's dynamics act within a sample and are not read; "
    "η_O is read where runs at two load sizes are read together (a single run at one load holds FDJ + k·|T_L| only). "
    "A local defect shows only as a rise of the current along the stroke larger than one run's scatter there. A "
    "published deep-learning classifier on the same data (RAVEN) labels the 13 states at 20 kgf with up to 87 % "
    "accuracy; it gives a class, where ema gives a physical change (FDJ up or down, by how much, against what healthy "
    "sets allow) and says where it cannot see one."
)
LEARN_RUNS = 4  # the first runs of each healthy load teach the drive (8 in all, the lab's count); the rest are held out


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


@dataclass(frozen=True)
class SetRead:
    """One (state, load)'s runs as ``ema estimate`` read them, and what ``ema calibrate`` said changed."""

    fdj: np.ndarray  # (runs, 3): value, std, repeatability std
    detected: int  # runs whose estimate noted a departure (fdj_departed)
    change: Change | None  # calibrate's FDJ verdict against the healthy document
    stroke: str


def read_set(runs: list, learned: LinearActuator) -> SetRead:
    results = [estimate(w, actuator=learned) for w in runs]
    fdj = np.array([(r.estimates.FDJ.value, r.estimates.FDJ.std, r.estimates.FDJ.repeatability_std) for r in results])
    detected = sum(any(n.code == "fdj_departed" for n in r.notes) for r in results)
    if len(runs) < 2:
        return SetRead(fdj, detected, None, "too few runs to compare")
    report, _, _ = calibrate_linear(runs, learned)
    return SetRead(fdj, detected, report.changes[0], report.selection_steps[0].reason)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path, default=RIG / "runs")
    parser.add_argument("--docs", action="store_true", help="rewrite its section of docs/results.md and its figure")
    args = parser.parse_args()
    found = sets(args.runs)
    first = slice(0, LEARN_RUNS)
    teach = [
        w for state, load in found if state == HEALTHY and load > 0 for w in windows(args.runs, state, load, first)
    ]
    report, learned, _ = calibrate_linear(teach, as_kind(read_actuator(RIG / "actuator.json"), LinearActuator))
    assert learned is not None and report.drive is not None
    read = {}
    for state, load in found:
        held = slice(LEARN_RUNS, None) if state == HEALTHY and load > 0 else slice(None)
        read[(state, load)] = read_set(windows(args.runs, state, load, held), learned)
    lives = histories(args.runs, found, learned)
    parts = [
        CITATION,
        "",
        learned_text(report.drive, learned),
        "",
        *table(read),
        "",
        *checks(read),
        "",
        *lives,
        "",
        LIMITS,
    ]
    body = "\n".join(parts)
    print(body)
    if args.docs:
        figure(
            {f"{s} {load} kgf": r.fdj[:, :2] for (s, load), r in read.items()},
            ROOT / "docs" / "figures" / "rig_fdj.png",
        )
        shown = "" if args.runs == RIG / "runs" else f" --runs {args.runs}"
        command = f"python -m benchmarks.real_rig{shown} --docs"
        write_section("A real actuator: the Cranfield ball-screw rig", command, body, ROOT / "docs" / "results.md")


def learned_text(drive: DriveLearned, learned: LinearActuator) -> str:
    screw = learned.screw
    assert screw is not None and drive.fdj_nm is not None and drive.fdj_std_nm is not None
    return (
        f"Learned on the first {LEARN_RUNS} healthy runs at each positive load ({2 * LEARN_RUNS} runs): current per "
        f"N·m c = {drive.current_per_nm_a:.3f} ± {drive.current_per_nm_std_a:.3f} A/(N·m), current at zero torque "
        f"{drive.current_at_zero_torque_a:.3f} ± {drive.current_at_zero_torque_std_a:.3f} A, nominal FDJ "
        f"{drive.fdj_nm:.3f} ± {drive.fdj_std_nm:.3f} N·m, η_O {drive.eta_o:.2f} ± {drive.eta_o_std:.2f}; a healthy "
        f"run scatters by {screw.run_to_run_nm:.4f} N·m within a set, a healthy set's mean by "
        f"{screw.healthy_set_nm:.4f} N·m about the nominal. Not separable: {'; '.join(drive.not_separable)}."
    )


def table(read: dict[tuple[str, int], SetRead]) -> list[str]:
    rows = [
        "| state | load [kgf] | runs | median FDJ [N·m] | repeatability std | std | scatter | ±2 std holds the median "
        "| `ema calibrate` says (FDJ against the healthy nominal) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for (state, load), r in read.items():
        median = float(np.median(r.fdj[:, 0]))
        held = int(np.sum(np.abs(r.fdj[:, 0] - median) <= 2 * r.fdj[:, 1]))
        said = "—" if r.change is None else ("**departed**: " if r.change.departed else "") + r.change.said
        rows.append(
            f"| {state} | {load} | {len(r.fdj)} | {median:.3f} | {np.median(r.fdj[:, 2]):.4f} | "
            f"{np.median(r.fdj[:, 1]):.4f} | {r.fdj[:, 0].std(ddof=1):.4f} | {held}/{len(r.fdj)} | {said} |"
        )
    return rows


MEDIAN_EFFICIENCY = 1.2533  # a median of n normal draws has sqrt(π/2)·σ/√n for its std


def checks(read: dict[tuple[str, int], SetRead]) -> list[str]:
    """The lab's checks, on these runs."""
    median = {k: float(np.median(r.fdj[:, 0])) for k, r in read.items()}
    repeat = {k: float(np.median(r.fdj[:, 2])) for k, r in read.items()}
    of_median = {k: MEDIAN_EFFICIENCY * repeat[k] / np.sqrt(len(r.fdj)) for k, r in read.items()}
    std = {k: float(np.median(r.fdj[:, 1])) for k, r in read.items()}
    healthy = [k for k in read if k[0] == HEALTHY]
    equal = all(abs(median[a] - median[b]) <= 2 * np.hypot(std[a], std[b]) for a in healthy for b in healthy)
    held = [np.abs(r.fdj[:, 0] - np.median(r.fdj[:, 0])) <= 2 * r.fdj[:, 1] for r in read.values()]
    lines = [
        f"- every run answered: {sum(len(r.fdj) for r in read.values())} runs;",
        f"- the healthy FDJ equal across loads within 2 std: {'yes' if equal else 'NO'} "
        f"({', '.join(f'{k[1]} kgf {median[k]:.3f}' for k in healthy)});",
        "- single lack-of-lubrication runs whose estimate notes the departure (fdj_departed): "
        + ", ".join(
            f"{sum(r.detected for k, r in read.items() if k[1] == load and k[0].startswith('lackLubrication'))}/"
            f"{sum(len(r.fdj) for k, r in read.items() if k[1] == load and k[0].startswith('lackLubrication'))} "
            f"at {load} kgf"
            for load in sorted({k[1] for k in read})
        )
        + ";",
        f"- ±2 std holds its set's median: {100 * np.mean(np.concatenate(held)):.0f} % of the runs;",
    ]
    for load in sorted({k[1] for k in read if k[1] > 0}):
        order = [k for k in ((HEALTHY, load), ("lackLubrication1", load), ("lackLubrication2", load)) if k in read]
        steps = [
            f"{b[0]} {median[b] - median[a]:+.3f} N·m (2 std of the medians' difference "
            f"{2 * np.hypot(of_median[a], of_median[b]):.3f}; of two single runs "
            f"{2 * np.hypot(repeat[a], repeat[b]):.3f})"
            for a, b in itertools.pairwise(order)
        ]
        lines.append(f"- at {load} kgf, on the repeatability std: {'; '.join(steps)};")
    scatter = float(np.median([np.std(read[k].fdj[:, 0], ddof=1) for k in healthy if k[1] > 0]))
    typical = float(np.median(list(repeat.values())))
    lines.append(
        f"- the median repeatability std {typical:.4f} N·m, {typical / scatter:.1f}x the healthy sets' run-to-run sd "
        f"at the learned loads ({scatter:.4f});"
    )
    departed = [f"{s} {load}" for (s, load), r in read.items() if r.change is not None and r.change.departed]
    lines.append(f"- `departed`: {', '.join(departed) or 'none'}.")
    return ["On these runs (the lab's checks):", "", *lines]


def histories(folder: Path, found: list[tuple[str, int]], learned: LinearActuator) -> list[str]:
    """Each load's spalling stages as one actuator's life: its held-out healthy runs, then every run of spalling 1
    to 8 in that order, stored as the service stores them and trended in that order (the runs carry no time);
    beside it, the healthy runs alone. What the prognosis says of FDJ, and the status it earns."""
    rows = []
    for load in sorted({load for _, load in found}):
        stages = sorted((s for s, at in found if at == load and s.startswith("spalling")), key=lambda s: int(s[8:]))
        healthy = windows(folder, HEALTHY, load, slice(LEARN_RUNS, None) if load > 0 else slice(None))
        spalled = [w for stage in stages for w in windows(folder, stage, load, slice(None))]
        for name, runs in (("healthy", healthy), (f"healthy, then spalling 1–{len(stages)}", healthy + spalled)):
            stored = [
                Stored(
                    **estimate(w, actuator=learned).model_dump(by_alias=True), id=i, stored_at="2018-01-01T00:00:00Z"
                )
                for i, w in enumerate(runs)
            ]
            prognosis = prognose(f"rig {load}", stored, learned)
            trend, life = prognosis.trends["FDJ"], prognosis.remaining_life["FDJ"]
            status, _, reason = status_of(stored[-1], prognosis, learned, len(stored))
            away = "moving_away" if any(n.code == "moving_away" for n in prognosis.notes) else "—"
            rows.append(
                f"| {load} | {name} | {len(runs)} | {trend.slope_per_unit:+.2g} ± {trend.slope_std or 0:.2g} | "
                f"{life.status} (level {life.direction} {life.threshold:.3f}) | {away} | {status}: {reason} |"
            )
    return [
        "The spalling stages as an actuator's life (per load: the held-out healthy runs, then each stage's runs in "
        "order, trended in that order; FDJ slope per run):",
        "",
        "| load [kgf] | history | runs | FDJ slope [N·m per run] | remaining life | note | status |",
        "|---:|---|---:|---:|---|---|---|",
        *rows,
    ]


if __name__ == "__main__":
    main()
