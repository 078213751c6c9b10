"""Commands that talk to a running service: replay a log into it, read an actuator's history back."""

from __future__ import annotations

import os
import sys
import urllib.error
import urllib.parse
from pathlib import Path
from typing import Any

import click

from ema.cli.options import (
    FIGURE_FILE,
    OUTPUT_FILE,
    NothingAnsweredError,
    as_json,
    emit,
    flags_named,
    log_map,
    log_map_document,
    service,
    window_s,
)
from ema.model.bounds import DEFAULT_SAMPLE_RATE_HZ
from ema.model.envelope import DEFAULT_AIRSPEED_MPS

LOG = click.Path(exists=True, path_type=Path)


def api_key(path: Path | None) -> str | None:
    """The key from --api-key-file, else EMA_API_KEY (never a flag: ``ps`` would show it)."""
    if path is not None:
        return path.read_text().strip()
    return os.environ.get("EMA_API_KEY")


@click.command()
@click.argument("log", type=LOG)
@service
@click.option(
    "--out",
    type=OUTPUT_FILE,
    default=None,
    help="CSV the answers are appended to (a rerun resumes from it)  [default: one per log and service in "
    "$XDG_STATE_HOME/ema/replay, said where]",
)
@window_s
@click.option("--actuator-id", default="unknown", help="for CSV/NPZ logs that carry none")
@click.option(
    "--rate",
    type=float,
    default=DEFAULT_SAMPLE_RATE_HZ,
    help="sample rate [Hz] of a rotary log in ema's columns that carries none",
)
@click.option(
    "--airspeed",
    type=float,
    default=DEFAULT_AIRSPEED_MPS,
    help="[m/s] of a rotary log in ema's columns that carries none",
)
@click.option("--altitude", type=float, default=0.0, help="[m] of a rotary log in ema's columns that carries none")
@click.option(
    "--actuator",
    "actuator_file",
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    default=None,
    metavar="A.json",
    help="store this ema-actuator/1 document in the service for the log's actuators before posting (a folder's "
    "actuators.json first)  [default: the documents the service holds]",
)
@log_map
@as_json
def replay(
    log: Path,
    *,
    url: str,
    out: Path | None,
    window_s: float | None,
    api_key_file: Path | None,
    actuator_id: str,
    rate: float,
    airspeed: float,
    altitude: float,
    actuator_file: Path | None,
    log_map_file: Path | None,
    as_json: bool,
) -> None:
    """Post a recorded log (JSON window(s), CSV, NPZ or a folder) to the service, window by window.

    Exit status 2 when no window was answered; a folder's unreadable files are skipped and listed."""
    from ema.cli.logs import Defaults, read_log
    from ema.cli.replay import put_documents
    from ema.cli.replay import replay as post_all

    defaults = Defaults(actuator_id, rate, airspeed, altitude)
    with flags_named({"sample_rate_hz": "--rate", "airspeed_mps": "--airspeed", "altitude_m": "--altitude"}):
        mapping = log_map_document(log_map_file)
        read = read_log(log, window_s, defaults, mapping)
    report_log(read)
    documents, sources = replayed_documents(log, actuator_file, {window.actuator_id for window in read.windows})
    key = api_key(api_key_file)
    check_service(url, key)  # a service that is not there: said now, and no file written
    for actuator_id, version in put_documents(url, documents, key, sources).items():
        print(f"{actuator_id}: its document stored in the service (version {version})", file=sys.stderr)
    out = out or default_results(log, url)
    print(f"replaying {len(read.windows)} window(s) from {log} to {url}; answers in {out}", file=sys.stderr)
    rows = post_all(read.windows, url, out, key)
    refused = [row for row in rows if row.get("error")]
    result = {
        "csv": str(out),
        "posted": len(rows),
        "answered": len(rows) - len(refused),
        "refused": len(refused),
        "bad_files": read.bad_files,
        "rows": rows,
    }
    emit(result, as_json, _print_replay)
    if rows and not result["answered"]:
        raise NothingAnsweredError(f"none of the {len(rows)} window(s) posted was answered (see {out})")


def replayed_documents(
    log: Path, actuator_file: Path | None, actuator_ids: set[str]
) -> tuple[dict[str, Any], dict[str, str]]:
    """(actuator_id -> the ema-actuator/1 document to store before its windows are posted, actuator_id -> where
    it came from): as ``ema fleet`` reads them (``ema.cli.workers.Documents``), a folder's actuators.json's, else
    --actuator's, else none (the service reads the windows with the document it holds)."""
    from ema.cli.logs import ACTUATORS_FILE, read_actuators
    from ema.cli.workers import Documents
    from ema.model.actuator import read_actuator

    given = Documents(read_actuators(log), None if actuator_file is None else read_actuator(actuator_file))
    documents, sources = {}, {}
    for actuator_id in sorted(actuator_ids):
        if (document := given.of(actuator_id)) is not None:
            listed = actuator_id in given.by_actuator
            documents[actuator_id] = document
            sources[actuator_id] = f"{log / ACTUATORS_FILE}: {actuator_id}" if listed else "--actuator"
    return documents, sources


def default_results(log: Path, url: str) -> Path:
    """Where a replay's answers go when --out names no file: the user's state folder, one file per log and
    service (so a rerun resumes it), never the working directory."""
    import hashlib

    home = os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
    key = hashlib.sha256(f"{log.resolve()}|{url.rstrip('/')}".encode()).hexdigest()[:12]
    return Path(home) / "ema" / "replay" / f"{log.stem}-{key}.csv"


def check_service(url: str, key: str | None) -> None:
    """ServiceError where nothing answers at ``url`` or the service fails; an InputError naming the flag where
    what answers is no ema service's root (a path such as /v1 added) or wants a key: said before any file is
    written, and before a 404 could be read as the actuator's."""
    from ema.cli.replay import ServiceError, key_refused, request
    from ema.model.checks import InputError

    try:
        request(f"{url}/healthz", key, timeout=10)
    except urllib.error.HTTPError as error:
        said = f"{url}/healthz answered HTTP {error.code}"
        if error.code == 401:
            raise key_refused(url, error.code, error.read().decode(errors="replace")) from None
        if error.code < 500:
            raise InputError("--url", f"{said}: no ema service's root address answers so") from None
        raise ServiceError(f"{said}: the service failed") from None


def report_log(read: Any) -> None:
    """What reading a log left out, on standard error: each skipped file and each dropped tail."""
    for file, reason in read.bad_files.items():
        print(f"skipped {file}: {reason}", file=sys.stderr)
    for window_id, dropped in read.dropped.items():
        print(f"{window_id}: the last {dropped} sample(s) after it do not fill a window", file=sys.stderr)
    for window_id, reason in read.kept_whole.items():
        print(f"{window_id}: {reason}", file=sys.stderr)
    for (actuator_id, window_id), files in read.conflicts.items():
        print(f"conflict: ({actuator_id}, {window_id}) is in {' and '.join(files)} with different content: none read",
              file=sys.stderr)  # fmt: skip


def _number(value: float | None, width: int, digits: str) -> str:
    return f"{'—':>{width}}" if value is None else f"{value:>{width}{digits}}"


def _print_replay(result: dict[str, Any]) -> None:
    click.echo(f"{'window':<36}{'FDJ':>12} {'unit':<5}{'η_O':>9}{'η_A':>9}{'total [s]':>11}")
    for row in result["rows"]:
        if row.get("error"):
            click.echo(f"{row['window_id']:<36}  refused: {row['error']}")
            continue
        click.echo(
            f"{row['window_id']:<36}{_number(row['FDJ'], 12, '.5g')} {row.get('FDJ_unit') or '':<5}"
            f"{_number(row['eta_O'], 9, '.4f')}{_number(row['eta_A'], 9, '.4f')}{_number(row['total_s'], 11, '.2f')}"
        )
    skipped = f", {len(result['bad_files'])} unreadable file(s) skipped" if result["bad_files"] else ""
    click.echo(
        f"{result['posted']} window(s) posted: {result['answered']} answered, {result['refused']} refused"
        f"{skipped}; all answers in {result['csv']}"
    )


@click.command()
@click.argument("actuator_id")
@service
@click.option("--plot", type=FIGURE_FILE, default=None, help="PNG of the prognosis (needs [plots])")
@click.option(
    "--parameter", default="FDJ", help="what --plot draws: any estimate the prognosis trends (its names are listed)"
)
@as_json
def history(
    actuator_id: str, url: str, api_key_file: Path | None, plot: Path | None, parameter: str, as_json: bool
) -> None:
    """An actuator's stored estimates, their trend and its remaining useful life."""
    from ema.cli.figures import prognosis_figure
    from ema.cli.printing import print_prognosis, value_units
    from ema.cli.replay import ServiceError, key_refused, refusal_text, request
    from ema.model.checks import InputError
    from ema.prognosis.documents import PROGNOSIS, EstimateHistory

    key = api_key(api_key_file)
    check_service(url, key)
    base = f"{url}/v1/actuators/{urllib.parse.quote(actuator_id, safe='/')}"
    try:
        stored = EstimateHistory.model_validate(request(f"{base}/estimates", key, timeout=60))
    except urllib.error.HTTPError as error:
        if error.code in (401, 403):
            raise key_refused(url, error.code, error.read().decode(errors="replace")) from None
        if error.code in (404, 422):
            raise InputError(
                "ACTUATOR_ID", f"{actuator_id!r}: {refusal_text(error.code, error.read().decode())}"
            ) from None
        raise ServiceError(f"HTTP {error.code} from {url}") from None
    prognosis = PROGNOSIS.validate_python(request(f"{base}/prognosis", key, timeout=60))
    read = {"FDJ", "eta_O", "eta_A", *prognosis.trends, *prognosis.constants}
    read |= {name for entry in stored.estimates for name in entry.estimates.constants}
    if plot is not None and parameter not in read:
        raise InputError("--parameter", f"{parameter!r} is not one of this actuator's: {', '.join(sorted(read))}")
    trended = parameter in prognosis.trends or parameter in prognosis.constants
    drawn = plot if plot is not None and trended else None
    if drawn is not None:
        prognosis_figure(prognosis, parameter, drawn, unit=value_units(stored).get(parameter, "").strip())
    elif plot is not None:
        print(f"no figure written to {plot}: {parameter} has no trend (the notes say why)", file=sys.stderr)
    document = {
        "history": stored.model_dump(mode="json", by_alias=True),
        "prognosis": prognosis.model_dump(mode="json"),
    }
    emit(document, as_json, lambda _: print_prognosis(stored, prognosis, drawn))


COMMANDS = (replay, history)
