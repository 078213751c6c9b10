"""What the commands print for a human (``--json`` prints the documents themselves)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import click

from ema.model.checks import InputError


def read_truth(path: Path | None) -> dict[str, float] | None:
    """A truth file's numbers by name (``{"FDJ": 0.05, "eta_O": 0.85}``, a servo's ``{"mass": 95.0}``): what the
    calibration compares with what it reports (``ema.calibration.truth``); entries that are not numbers (``ema
    simulate``'s ``flight_hours`` of null) are not a truth. Errors name the file."""
    if path is None:
        return None
    try:
        truth = json.loads(Path(path).read_text())
    except (OSError, ValueError) as exc:
        raise InputError(str(path), f"is not a truth file ({exc!r})") from None
    if not isinstance(truth, dict):
        raise InputError(str(path), "is not a truth file: a JSON object of true values by name")
    numbers = {
        name: float(value)
        for name, value in truth.items()
        if isinstance(value, int | float) and not isinstance(value, bool)
    }
    if not numbers:
        raise InputError(str(path), "holds no true value: a JSON object of numbers by name")
    return numbers


def _std(std: float | None) -> str:
    return "—" if std is None else f"{std:.2g}"


def _row(name: str, entry: Any) -> str:
    nominal = "—" if entry.nominal is None else f"{entry.nominal:.4g}"
    drift = "—" if entry.drift_pct is None else f"{entry.drift_pct:.2f}%"
    weak = "  weakly determined" if entry.weakly_determined else ""
    return f"{name:<22}{entry.value:>12.5g}{_std(entry.std):>10}{nominal:>11}{drift:>10}  {entry.unit or ''}{weak}"


def print_estimate(result: Any) -> None:
    click.echo(f"{result.actuator_id}  window {result.window_id}")
    click.echo(f"{'parameter':<22}{'value':>12}{'± std':>10}{'nominal':>11}{'drift':>10}  unit")
    for name in ("FDJ", "eta_O", "eta_A", "FSJ"):
        entry = getattr(result.estimates, name)
        if entry is not None:
            click.echo(_row(name, entry))
    for name, entry in result.estimates.constants.items():
        click.echo(_row(name, entry))
    if result.estimates.FSJ is None:
        click.echo(f"FSJ: not estimated: {result.fsj_note.text}")
    click.echo(check_line(result.check))
    for note in result.notes:
        click.echo(f"note [{note.code}]: {note.text}")
    ran = [
        (stage, seconds)
        for stage, seconds in result.timings_s.stages().items()
        if not result.stages.get(stage, "run").startswith("skipped")
    ]
    times = "  ".join(f"{stage} {seconds:.2f} s" for stage, seconds in ran)
    click.echo(f"time: {times}  total {result.timings_s.total:.2f} s")


SIGNAL_WORDS = {"residual_torque": "residual torque", "current_a": "stretches' current",
                "drive_force_n": "drive force", "position_rad": "position"}  # fmt: skip


def check_line(check: Any) -> str:
    """The answer against the window in one line: the simulation at the estimates, and the equation-error test;
    never the one saying "reproduced" where the other says the model lacks something."""
    ratios = check.output_error_ratio
    signal = "residual_torque" if "residual_torque" in ratios else next(iter(ratios))
    output = ratios[signal]
    what = SIGNAL_WORDS.get(signal, signal)
    if check.mean_abs_error:
        what += " (" + ", ".join(f"{value:.3g} rad on average" for value in list(check.mean_abs_error.values())[:1])
        what += f", {next(iter(check.output_error_pct.values())):.3g} % from the log)"
    elif check.output_error_pct:
        what += (
            " (" + ", ".join(f"{name} {pct:.3g} %" for name, pct in check.output_error_pct.items()) + " from the log)"
        )
    limit = check.equation_error_limit
    misfit = limit is not None and check.equation_error_ratio > limit
    if not check.reproduced:
        return f"check: the model does NOT reproduce the window ({what} {output:.2f}x its noise floor)"
    if misfit:
        return (
            f"check: simulated at the estimates, the window's {what} is {output:.2f}x its noise floor, "
            f"but its Eq. 5.1 error is {check.equation_error_ratio:.2f}x noise (over {limit:.2f}x): something small "
            "the model lacks (note model_misfit)"
        )
    tested = "" if limit is None else f"; Eq. 5.1 error {check.equation_error_ratio:.2f}x noise, within {limit:.2f}x"
    return f"check: the model reproduces the window ({what} {output:.2f}x its noise floor{tested})"


def print_simulate(result: dict[str, Any]) -> None:
    summary = result["summary"]
    count = len(result["windows"])
    where = result["window"] if count == 1 else f"{count} windows to {result['window']}"
    click.echo(
        f"wrote {where}: {summary['n_samples']} samples, {summary['duration_s']:g} s at "
        f"{summary['sample_rate_hz']:g} Hz each, {result['command']} command"
    )
    truths = result["truth"] if isinstance(result["truth"], list) else [result["truth"]]
    for i, truth in enumerate(truths):
        hours = "" if truth.get("flight_hours") is None else f"  at {truth['flight_hours']:g} flight hours"
        label = "truth" if len(truths) == 1 else f"window {i}"
        click.echo(
            f"{label}: FDJ {truth['FDJ']:.4f} N·m  η_O {truth['eta_O']:.4f}  η_A {truth['eta_A']:.4f}  "
            f"FSJ {truth['FSJ']:.4f} N·m{hours}"
        )
    click.echo(
        f"effects: {result['effects'] or 'none'}   noise: {'none' if result['noise'] == 'none' else 'realistic'}"
    )
    click.echo(f"{'signal':<22}{'min':>12}{'max':>12}" + ("  (the last window)" if len(truths) > 1 else ""))
    for name, (low, high) in summary["ranges"].items():
        click.echo(f"{name:<22}{low:>12.4g}{high:>12.4g}")
    click.echo(f"moving {summary['moving_fraction']:.0%} of the window")


def print_calibration(report: dict[str, Any]) -> None:
    """The ``ema-calibration/1`` report as a person reads it: what every kind's holds, then its kind's own parts as
    the kind prints them (``ema.kinds.report_lines``: the rotary's unexplained residual, ambiguity and errors against
    a truth, a ball screw's drive and changes, a servo's constants as simulated, a geared servo's runs per load)."""
    from ema.kinds import report_lines

    floor = report["noise_floor"]
    if floor and floor["copies"]:
        click.echo(
            f"noise floor: the base model's residual is {floor['equation_error_ratio']:.2f}x what noise alone leaves "
            f"({floor['copies']} copies)"
        )
    if report["candidates"]:
        click.echo(f"{'candidate':<28}{'z':>9}{'held-out drop':>15}  parameters")
    for c in sorted(report["candidates"], key=lambda c: -c["score"])[:8]:
        parameters = ", ".join(f"{k}={v:.4g}" for k, v in list(c["parameters"].items())[:4])
        click.echo(f"{c['effect']:<28}{c['score']:>9.1f}{c['held_out_drop']:>14.1%}  {parameters}")
    for i, step in enumerate(report["selection_steps"]):
        said = (
            f"named {step['selected']}" if step["selected"] else "nothing named" if i == 0 else "nothing further named"
        )
        click.echo(f"{said}: {step['reason']}")
    click.echo(f"held out: {report['held_out']['note']}")
    _print_estimates(report)
    for line in report_lines(report):
        click.echo(line)
    for line in _truth_lines(report):
        click.echo(line)
    for when in ("before", "after", "document"):
        errors = report.get(f"model_error_pct_{when}")
        if errors:
            said = ", ".join(f"{ERROR_WORDS.get(name, name)} {pct:.2f} %" for name, pct in errors.items())
            click.echo(f"model error {when}: {said}  (100·‖y − ŷ‖/‖y‖)")
    if report.get("figure"):
        click.echo(f"figure: {report['figure']}")


def _truth_lines(report: dict[str, Any]) -> list[str]:
    """Each constant's error against a known truth, before -> after (relative where the truth is not 0)."""
    after = report.get("error_pct_after") or report.get("error_after") or {}
    relative = bool(report.get("error_pct_after"))
    before = (report.get("error_pct_before") if relative else report.get("error_before")) or {}
    said = "{:.2f} %".format if relative else "{:.3g}".format
    return [
        f"{name} error against the truth: {said(before[name]) if name in before else '—'} -> {said(after[name])}"
        for name in after
    ]


ERROR_WORDS = {"drive_force_n": "force, inverse model", "drive_force_n_closed_loop": "force, closed loop"}


def _print_estimates(report: dict[str, Any]) -> None:
    """FDJ and η_O before and after, in FDJ's unit as the learned constants give it."""
    learned = {entry["name"]: entry for entry in report.get("learned", [])}
    units = {"FDJ": " " + learned["FDJ"]["unit"] if "FDJ" in learned else " N·m", "eta_O": ""}
    for name in ("FDJ", "eta_O"):
        if name not in report["estimates_after"]:
            continue
        was = report["estimates_before"].get(name)
        line = f"{name}: {'—' if was is None else f'{was:.5g}{units[name]}'} -> {report['estimates_after'][name]:.5g}"
        click.echo(line + units[name])


TIME_UNITS = {
    "flight_hours": ("flight hour", "flight hours"),
    "days": ("day", "days"),
    "windows": ("window", "windows"),
}


def _slope(trend: Any, unit: str, value_unit: str = "") -> str:
    """The trend's slope with its unit: the parameter's (``value_unit``, with its leading space) per the
    prognosis's time unit."""
    if trend.slope_std is None:
        return "no slope yet"
    return f"slope {trend.slope_per_unit:+.3g} ± {trend.slope_std:.2g}{value_unit} per {unit}"


def value_units(stored: Any) -> dict[str, str]:
    """Each parameter's unit as its latest stored estimate gives it, with a leading space (none for an efficiency,
    or where no estimate says): N·m at the motor shaft, N on the load, a constant's own (kg, N·s/m)."""
    units: dict[str, str] = {}
    for entry in reversed(stored.estimates):
        read = {name: getattr(entry.estimates, name) for name in ("FDJ", "eta_O", "eta_A")} | entry.estimates.constants
        for name, estimate in read.items():
            if name not in units and estimate is not None and estimate.unit not in (None, "1"):
                units[name] = f" {estimate.unit}"
    return units


def _life(life: Any, unit: str, status: str) -> str:
    """A remaining life, counted from the last window, in the prognosis's time unit; ``status`` as the prognosis
    words it."""
    if life.rul is None:
        return status
    high = "open" if life.rul_high is None else f"{life.rul_high:.3g}"
    faster = "; speeding up" if life.speeding_up else ""
    return (
        f"{life.threshold:g} crossed in {life.rul:.3g} {unit} from the last window (90 %: {life.rul_low:.3g} to "
        f"{high}; earliest plausible {life.rul_earliest:.3g}){faster}"
    )


def print_prognosis(stored: Any, prognosis: Any, plot: Path | None) -> None:
    """An actuator's outlook per parameter, the laws it weighs, its backtest, its sensors' trends and notes."""
    from ema.kinds import prognosis_lines

    one, many = TIME_UNITS[prognosis.time_unit]
    units = value_units(stored)
    click.echo(f"{prognosis.actuator_id}: {len(stored.estimates)} window(s), time in {many}")
    for name, trend in prognosis.trends.items():
        level, level_std = trend.now()
        laws = ", ".join(f"{law} {w:.2f}" for law, w in sorted(trend.laws.items(), key=lambda x: -x[1]) if w >= 0.05)
        life = _life(prognosis.remaining_life[name], many, prognosis.life_status(name))
        unit = units.get(name, "")
        click.echo(f"{name:<6} now {level:.5g} ± {level_std:.2g}{unit}, {_slope(trend, one, unit)}; {life}")
        if laws:
            click.echo(f"       laws weighed by how they predicted later windows: {laws}")
        for point in prognosis.backtest.get(name, []):
            inside = "—" if point.later_inside is None else f"{100 * point.later_inside:.0f} %"
            said = "no crossing" if point.crossing is None else f"crossing at {point.crossing:.4g} {many}"
            click.echo(
                f"       backtest at {point.time:.4g} {many} ({point.windows} windows; times from the first window): "
                f"{said}; of the {point.later_windows} later windows {inside} inside its 90 % band"
            )
    for name, trend in {**prognosis.sensors, **prognosis.constants}.items():
        click.echo(f"{name} now {trend.level:.4g} ± {trend.level_std:.2g}, {_slope(trend, one)} ({trend.n} windows)")
    for line in prognosis_lines(prognosis.model_dump(mode="json")):  # its kind's own parts (a rotary's J_M)
        click.echo(line)
    for note in prognosis.notes:
        click.echo(f"note [{note.code}]: {note.text}")
    if plot is not None:
        click.echo(f"figure: {plot}")
