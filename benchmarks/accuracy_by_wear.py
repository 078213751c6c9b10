"""The accuracy table's windows over the whole wear range (``benchmarks.foreign_accuracy``): error and ±2 std
coverage by FDJ over its nominal 0.05 N·m, and the estimate against the truth as a figure."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

WEAR_BINS = ((0.8, 1.2), (1.3, 1.7), (1.7, 2.1), (2.1, 2.5))  # FDJ / nominal


def wear_table(rows: dict[str, list[dict[str, Any]]]) -> str:
    """Error and coverage against wear: windows grouped by FDJ over its nominal 0.05 N·m."""
    lines = [
        "| FDJ / nominal | windows | FDJ mean / worst | η_O mean / worst | ±2 std coverage FDJ / η_O |",
        "|---|---:|---:|---:|---:|",
    ]
    every = [r for rs in rows.values() for r in rs if "FDJ" in r]
    for low, high in WEAR_BINS:
        found = [r for r in every if low <= r["FDJ"]["truth"] / 0.05 < high]
        if not found:
            continue
        cells = []
        for name in ("FDJ", "eta_O"):
            relative = 100 * np.abs([r[name]["relative"] for r in found])
            cells.append(f"{relative.mean():.2f} % / {relative.max():.2f} %")
        coverage = " / ".join(f"{100 * np.mean([abs(r[n]['z']) <= 2 for r in found]):.0f} %" for n in ("FDJ", "eta_O"))
        lines.append(f"| {low:g}–{high:g}x | {len(found)} | {cells[0]} | {cells[1]} | {coverage} |")
    return "\n".join(lines)


def wear_figure(rows: dict[str, list[dict[str, Any]]], path: Path) -> None:
    """Estimate against truth, ±2 std, over the whole wear range: what the thesis never had."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, 2, figsize=(10, 4.5))
    for axis, name, label in zip(axes, ("FDJ", "eta_O"), ("FDJ [N·m]", "η_O"), strict=True):
        for group, colour in (("worn", "tab:red"), ("healthy", "tab:blue")):
            found = [
                r[name] for g, rs in rows.items() for r in rs if name in r and g.startswith("worn") == (group == "worn")
            ]
            truth = np.array([f["truth"] for f in found])
            axis.errorbar(
                truth,
                [f["value"] for f in found],
                yerr=2 * np.array([f["std"] for f in found]),
                fmt="o",
                ms=3,
                lw=0.8,
                color=colour,
                label=f"{group} ({len(found)})",
            )
        low, high = axis.get_xlim()
        axis.plot([low, high], [low, high], color="grey", lw=1)
        axis.set(xlabel=f"true {label}", ylabel=f"estimated {label} (± 2 std)")
        axis.legend()
    figure.suptitle("ema on foreign windows, healthy and worn (Case 1C's irreversible range included)")
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)
