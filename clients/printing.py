"""What the commands print for a human (``--json`` prints the documents themselves)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import click

from sim.checks import InputError


def read_truth(path: Path | None) -> dict[str, float] | None:
    """``{"FDJ": 0.05, "eta_O": 0.85, "FSJ": 0.1}`` (FSJ optional); errors name the file."""
    if path is None:
        return None
    try:
        truth = json.loads(Path(path).read_text())
        return {key: float(truth[key]) for key in ("FDJ", "eta_O")}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputError(str(path), f"is not a truth file with FDJ and eta_O ({exc!r})") from None


def _std(std: float | None) -> str:
    return "—" if std is None else f"{std:.2g}"


def print_estimate(result: Any) -> None:
    click.echo(f"{result.actuator_id}  window {result.window_id}")
    click.echo(f"{'parameter':<10}{'value':>12}{'± std':>12}{'nominal':>12}{'drift':>10}")
    for name in ("FDJ", "eta_O", "eta_A", "FSJ"):
        entry = getattr(result.estimates, name)
        if entry is None:
            continue
        weak = "  weakly determined" if entry.weakly_determined else ""
        click.echo(f"{name:<10}{entry.value:>12.5g}{_std(entry.std):>12}{entry.nominal:>12.4g}{entry.drift_pct:>9.2f}%"
                   f"{weak}")  # fmt: skip
    if result.estimates.FSJ is None:
        click.echo(f"FSJ: not estimated: {result.fsj_note.text}")
    check = result.fit_check
    click.echo(f"check: the model {'reproduces' if check.reproduced else 'does NOT reproduce'} the window "
               f"(residual torque {check.output_error_ratio['residual_torque']:.2f}x its noise floor)")  # fmt: skip
    for note in result.notes:
        click.echo(f"note [{note.code}]: {note.text}")
    click.echo("time: " + "  ".join(f"{stage} {seconds:.2f} s" for stage, seconds in result.timings_s))


def print_simulate(result: dict[str, Any]) -> None:
    summary = result["summary"]
    click.echo(f"wrote {result['window']}: {summary['n_samples']} samples, {summary['duration_s']:g} s at "
               f"{summary['sample_rate_hz']:g} Hz, {result['command']} command")  # fmt: skip
    truth = result["truth"]
    click.echo(f"truth: FDJ {truth['FDJ']:.4f} N·m  η_O {truth['eta_O']:.4f}  η_A {truth['eta_A']:.4f}  "
               f"FSJ {truth['FSJ']:.4f} N·m")  # fmt: skip
    click.echo(
        f"effects: {result['effects'] or 'none'}   noise: {'none' if result['noise'] == 'none' else 'realistic'}"
    )
    click.echo(f"{'signal':<22}{'min':>12}{'max':>12}")
    for name, (low, high) in summary["ranges"].items():
        click.echo(f"{name:<22}{low:>12.4g}{high:>12.4g}")
    click.echo(f"moving {summary['moving_fraction']:.0%} of the window")


def print_calibration(report: dict[str, Any]) -> None:
    click.echo(f"noise floor: the base model's residual is {report['noise_floor']['equation_error_ratio']:.2f}x "
               f"what noise alone leaves ({report['noise_floor']['copies']} copies)")  # fmt: skip
    click.echo(f"{'candidate':<28}{'z':>9}{'held-out drop':>15}  parameters")
    for c in sorted(report["candidates"], key=lambda c: -c["score"])[:8]:
        parameters = ", ".join(f"{k}={v:.4g}" for k, v in list(c["parameters"].items())[:4])
        click.echo(f"{c['effect']:<28}{c['score']:>9.1f}{c['held_out_drop']:>14.1%}  {parameters}")
    for step in report["selection_steps"]:
        click.echo(f"step: {step['selected'] or '—'}: {step['reason']}")
    if report["unexplained"]:
        click.echo(f"unexplained: {report['unexplained']['description']}")
    click.echo(f"held out: {report['held_out']['note']}")
    for name in ("FDJ", "eta_O"):
        line = f"{name}: {report['estimates_before'][name]:.5g} -> {report['estimates_after'][name]:.5g}"
        if report.get("error_pct_before"):
            line += f"   error {report['error_pct_before'][name]:.2f} % -> {report['error_pct_after'][name]:.2f} %"
        click.echo(line)
    if report["figure"] is not None:
        click.echo(f"figure: {report['figure']}")
