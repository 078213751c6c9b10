"""Commands that run in this process: estimate, simulate, calibrate, schemas."""

from __future__ import annotations

import datetime as dt
import json
import sys
from pathlib import Path
from typing import Any

import click

from ema.cli.options import (
    EXISTING,
    FIGURE_FILE,
    OUTPUT_FILE,
    about_file,
    actuator,
    actuator_document,
    as_json,
    emit,
    flags_named,
    kind_given,
    log_map,
    log_map_document,
    pipeline_config,
    progress,
    say_if_compiling,
    sizes,
    span,
    threads,
)
from ema.model.bounds import (
    COMMAND_FAMILIES,
    DEFAULT_SAMPLE_RATE_HZ,
    DURATION_RANGE_S,
    MAX_FLIGHT_HOURS,
    NOISE_COPIES,
    NOISE_COPIES_RANGE,
    SAMPLE_RATE_RANGE_HZ,
)
from ema.model.envelope import AIRSPEED_RANGE_MPS, ALTITUDE_RANGE_M, DEFAULT_AIRSPEED_MPS

SIMULATE_FLAGS = {
    "flight_condition.airspeed_mps": "--airspeed",
    "flight_condition.altitude_m": "--altitude",
    "fsj_nm": "--fsj",
    "fdj_nm": "--fdj",
    "eta_o": "--eta-o",
    "sample_rate_hz": "--rate",
    "duration_s": "--duration",
    "command": "--command",
    "effects": "--effect",
    "ground_load.constant_nm": "--load",
    "ground_load.ramp_nmps": "--load-ramp",
}


def history_of(window: Any, paths: tuple[Path, ...], actuator: Any) -> Any:
    """What the ema-estimate/1 results in ``paths``, of other windows of ``window``'s actuator, lend it, as its kind
    reads them (``ema.kinds.readings_of_results``); InputError naming --history."""
    from pydantic import ValidationError

    from ema.estimate.documents import Estimate
    from ema.kinds import readings_of_results
    from ema.model.checks import InputError, from_validation, load_json

    results = []
    for path in paths:
        try:
            result = Estimate.model_validate(load_json(path))
        except InputError as exc:
            raise InputError("--history", f"{path} {exc.message}") from None
        except ValidationError as exc:
            first = from_validation(exc)
            said = f"{path} is not an ema-estimate/1 result ({first.field}: {first.message})"
            raise InputError("--history", said) from None
        if result.actuator_id != window.actuator_id:
            raise InputError(
                "--history", f"{path} is of actuator {result.actuator_id}, the window of {window.actuator_id}"
            )
        results.append(result)
    return readings_of_results(actuator, [result.window for result in results], window.flight_id)


@click.command()
@click.argument("window", type=EXISTING)
@click.option(
    "--history",
    "history",
    type=EXISTING,
    multiple=True,
    metavar="RESULT.json",
    help="the ema-estimate/1 result of another window of the actuator (repeatable): J_M where it read one, "
    "its sensors' zero where it is of the window's flight_id",
)
@actuator
@log_map
@sizes
@threads
@as_json
def estimate(
    window: Path,
    *,
    history: tuple[Path, ...],
    actuator_file: Path | None,
    log_map_file: Path | None,
    threads: int | None,
    as_json: bool,
    **size_values: int,
) -> None:
    """Read the health of one window, in-process: FDJ and the efficiencies its kind reports (FSJ where it shows), each
    with a std: an ema-window/1 JSON file, a CSV or NPZ in ema's columns (docs/model.md), or a log in its own columns
    and units (CSV, MATLAB, NPZ, a recorder's JSON) with --log-map."""
    from ema.cli.logs import read_one
    from ema.cli.printing import print_estimate
    from ema.estimate import thread_budget
    from ema.kinds import estimate as estimate_one

    config = pipeline_config(size_values)
    document = actuator_document(actuator_file)
    read = read_one(window, log_map_document(log_map_file))
    kind_given([read], actuator_file)
    say_if_compiling([read])
    known = history_of(read, history, document) if history else None
    thread_budget.configure(threads)
    with about_file(window):
        result = estimate_one(read, config, actuator=document, on_stage=progress, history=known)
    emit(result, as_json, print_estimate)


@click.command()
@click.option(
    "--out",
    required=True,
    type=OUTPUT_FILE,  # its folder made as the flag is read; with --series, the folder itself is made on writing
    help="the window's JSON file to write; with --series, the folder to write them into",
)
@click.option("--fdj", type=float, default=None, help="dynamic friction FDJ [N·m]  [default: the actuator's nominal]")
@click.option("--eta-o", "eta_o", type=float, default=None, help="opposing efficiency η_O  [default: nominal]")
@click.option("--fsj", type=float, default=None, help="static friction FSJ [N·m]  [default: nominal]")
@click.option(
    "--airspeed", type=float, default=DEFAULT_AIRSPEED_MPS, help=f"true airspeed [m/s], {span(AIRSPEED_RANGE_MPS)}"
)
@click.option("--altitude", type=float, default=0.0, help=f"altitude [m], {span(ALTITUDE_RANGE_M)}")
@click.option("--ground", is_flag=True, help="on the ground: a load cell's load (--load, --load-ramp), no aircraft")
@click.option("--load", "load_nm", type=float, default=0.0, help="with --ground: the hinge moment at t = 0 [N·m]")
@click.option("--load-ramp", "load_ramp_nmps", type=float, default=0.0, help="with --ground: its rate [N·m/s]")
@click.option("--command", type=click.Choice(COMMAND_FAMILIES), default="thesis", help="the command's family")
@click.option("--seed", type=int, default=0, help="seed of the command and the noise")
@click.option("--duration", type=click.FloatRange(*DURATION_RANGE_S), default=0.5, help="window length [s]")
@click.option("--rate", type=float, default=DEFAULT_SAMPLE_RATE_HZ, help=f"log rate [Hz], {span(SAMPLE_RATE_RANGE_HZ)}")
@click.option("--clean", is_flag=True, help="no sensor noise")
@click.option(
    "--effect",
    "effect",
    multiple=True,
    metavar="NAME[:KEY=VALUE,...]",
    help="an effect the base model lacks, e.g. cogging:amplitude_nm=0.02 (repeatable)",
)
@click.option("--actuator-id", default="synthetic/elevator", help="actuator_id written to the window")
@click.option("--truth-out", type=OUTPUT_FILE, help="also write the truth as JSON")
@click.option(
    "--recorded-at",
    type=click.DateTime(formats=["%Y-%m-%dT%H:%M:%S%z", "%Y-%m-%dT%H:%M:%S", "%Y-%m-%d"]),
    default=None,
    help="when the window began, written as recorded_at (UTC where no offset is given)",
)
@click.option(
    "--flight-hours", type=click.FloatRange(0, MAX_FLIGHT_HOURS), default=None, help="the airframe's hours then"
)
@click.option(
    "--series",
    type=click.IntRange(1, 10_000),
    default=1,
    help="draw this many windows of a degrading actuator into the folder --out (health from --fdj/--eta-o "
    "to --fdj-end/--eta-o-end, --every hours apart): a history to try the trend on",
)
@click.option(
    "--every", "every_hours", type=click.FloatRange(0.01, 10_000), default=10.0, help="with --series: hours apart"
)
@click.option("--fdj-end", type=float, default=None, help="with --series: FDJ of the last window [N·m]")
@click.option("--eta-o-end", type=float, default=None, help="with --series: η_O of the last window")
@actuator
@as_json
def simulate(as_json: bool, **options: Any) -> None:
    """Write a synthetic ema-window/1 file from the model (sensor noise unless --clean), or --series of them."""
    from ema.cli.options import actuator_document
    from ema.cli.printing import print_simulate
    from ema.kinds import synthesize

    stamp = options["recorded_at"]
    if stamp is not None and stamp.tzinfo is None:
        options["recorded_at"] = stamp.replace(tzinfo=dt.UTC)
    with flags_named(SIMULATE_FLAGS):
        actuator = actuator_document(options.pop("actuator_file"))
        result = synthesize(actuator, options)
    emit(result, as_json, print_simulate)


@click.command()
@click.argument("windows", type=EXISTING, nargs=-1, required=True)
@click.option(
    "--truth",
    type=EXISTING,
    help='JSON of what synthetic windows were drawn at, by name ({"FDJ": 0.05, "eta_O": 0.85}, a servo\'s '
    '{"mass": 95}): the report states its error against each constant it reports',
)
@click.option("--figure", type=FIGURE_FILE, help="also write a PNG of the residual before and after (needs [plots])")
@click.option(
    "--copies",
    type=click.IntRange(*NOISE_COPIES_RANGE),
    default=NOISE_COPIES,
    help="noise-only copies behind the noise floor",
)
@click.option(
    "--out-actuator",
    type=OUTPUT_FILE,
    default=None,
    metavar="A2.json",
    help="write the actuator's document completed with what the windows taught (a ball screw's c, I0 and nominal; "
    "a servo's load constants and effects)",
)
@actuator
@log_map
@sizes
@threads
@as_json
def calibrate(
    windows: tuple[Path, ...],
    *,
    truth: Path | None,
    figure: Path | None,
    copies: int,
    out_actuator: Path | None,
    actuator_file: Path | None,
    log_map_file: Path | None,
    threads: int | None,
    as_json: bool,
    **size_values: int,
) -> None:
    """Trace what the model misses in windows of one actuator to an effect, add it, re-estimate; learn what the
    document lacks (a ball screw's drive, a servo's load, a geared servo's loop and health: --out-actuator), or say
    what faulted runs changed."""
    from ema import kinds
    from ema.cli.figures import residual_figure
    from ema.cli.logs import read_one
    from ema.cli.printing import print_calibration, read_truth
    from ema.estimate import thread_budget
    from ema.model.checks import InputError

    config = pipeline_config(size_values)
    thread_budget.configure(threads)
    document = actuator_document(actuator_file)
    mapping = log_map_document(log_map_file)
    loaded = [read_one(path, mapping) for path in windows]
    kind_given(loaded, actuator_file)
    request = kinds.CalibrationRequest(config, document, read_truth(truth), copies=copies, on_stage=progress)
    with flags_named({"truth": "--truth"}):
        calibrated = kinds.calibrate(loaded, request)
    uncompared = [name for name in request.truth or {} if name not in (calibrated.report.error_after or {})]
    if uncompared:  # a truth file of ema simulate holds FSJ and eta_A: said, never silently passed over
        print(f"ema: --truth: not compared, the report carries no {', '.join(uncompared)}", file=sys.stderr)
    written: dict[str, str | None] = {"figure": None, "actuator_written": None}
    if out_actuator is not None:
        if calibrated.completed is None:
            raise InputError(
                "--out-actuator", "these windows taught the document nothing to complete: they were read with it"
            )
        out_actuator.write_text(calibrated.completed.model_dump_json(by_alias=True, indent=2, exclude_none=True) + "\n")
        written["actuator_written"] = str(out_actuator)
        print(f"ema: wrote the completed document to {out_actuator}", file=sys.stderr)
    undrawn = None  # the report is printed whatever happens to the figure: nothing computed is lost
    if figure is not None and calibrated.plot is None:
        undrawn = InputError("--figure", f"a {document.kind} actuator's calibration has no figure")
    elif figure is not None:
        try:
            written["figure"] = str(residual_figure(calibrated.plot, figure))
        except (OSError, ValueError) as error:
            undrawn = InputError("--figure", f"{figure}: not drawn ({error}); the report stands")
    emit({**calibrated.report.model_dump(mode="json", by_alias=True), **written}, as_json, print_calibration)
    if undrawn is not None:
        raise undrawn


REPOSITORY_SCHEMAS = Path(__file__).resolve().parents[2] / "docs" / "schemas"  # an editable install's


@click.command()
@click.option(
    "--out",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="folder to write the JSON Schemas to (with --check: to compare; default: the repository's docs/schemas, "
    "where this ema was installed from)",
)
@click.option("--check", is_flag=True, help="exit 1 if the files there differ from the code (writes nothing)")
def schemas(out: Path | None, check: bool) -> None:
    """Export the JSON Schema of every public document (or check the exported ones)."""
    from ema.cli.schema_export import export
    from ema.model.checks import InputError

    if out is None and not check:
        raise InputError("--out", "name the folder to write the schemas to (the repository's: --out docs/schemas)")
    if out is None:
        out = REPOSITORY_SCHEMAS
        if not out.is_dir():
            raise InputError("--out", "this ema was not installed from a repository: name the folder to check")
    try:
        stale = export(out, check=check)
    except OSError as error:
        raise InputError("--out", f"{out}: cannot be written ({error.strerror})") from None
    if check and stale:
        raise click.ClickException(f"stale or missing in {out}: {', '.join(stale)} (run: ema schemas --out {out})")
    click.echo(json.dumps({"folder": str(out), "checked" if check else "written": "all"}))


COMMANDS = (estimate, simulate, calibrate, schemas)
