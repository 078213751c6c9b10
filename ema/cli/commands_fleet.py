"""Commands for the ground and the bench: an archive across Ray workers, and the latency benchmark."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import click

from ema.cli.options import (
    OUTPUT_FILE,
    OUTPUT_FOLDER,
    NothingAnsweredError,
    actuator,
    as_json,
    database_setting,
    emit,
    log_map,
    log_map_document,
    pipeline_config,
    sizes,
    span,
    window_s,
)
from ema.model.bounds import DURATION_RANGE_S, MAX_THREADS

ARCHIVE = click.Path(exists=True, path_type=Path)


@click.command()
@click.argument("archive", type=ARCHIVE)
@click.option("--out", required=True, type=OUTPUT_FILE, help="results CSV, a row per window (a rerun resumes from it)")
@click.option("--workers", type=click.IntRange(1, 4096), default=2, help="worker processes (windows at a time)")
@click.option("--threads", type=click.IntRange(1, MAX_THREADS), default=1, help="threads (CPUs) each worker reserves")
@click.option("--ray-address", default=None, help="'auto' or HOST:PORT of a cluster [default: a local Ray]")
@window_s
@click.option(
    "--database",
    default=None,
    callback=database_setting,
    help="also store every answer in this history: an SQLite file or a postgresql:// address (the service's)",
)
@click.option("--verbose", is_flag=True, help="also print how the wall time splits: start-up, windows, writing")
@actuator
@log_map
@sizes
@as_json
def fleet(
    archive: Path,
    *,
    out: Path,
    workers: int,
    threads: int,
    ray_address: str | None,
    window_s: float | None,
    database: str | None,
    actuator_file: Path | None,
    log_map_file: Path | None,
    verbose: bool,
    as_json: bool,
    **size_values: int,
) -> None:
    """Reprocess an archive (folder, NPZ, CSV, MATLAB or JSON logs) on worker processes; one CSV row per window.

    Workers are local processes (forked from one that loads the pipeline as the archive is read), this one for one
    worker, one window or where none trains a network (a ball screw's, a slow log's: milliseconds each), or a Ray
    cluster's with --ray-address (``pip install 'ema[fleet]'``). A window is read with its actuator's document:
    the folder's actuators.json maps actuator_ids to ema-actuator/1 documents; the others take --actuator (the
    thesis's where none is given). Exit status 2 when no window was answered; unreadable files are skipped."""
    from ema.cli.pool import LocalWorkers

    started = time.perf_counter()
    pool = LocalWorkers(workers, threads) if workers > 1 and ray_address is None else None  # loading meanwhile
    try:
        from ema.cli.commands_remote import report_log
        from ema.cli.fleet import check_engine, run_fleet

        check_engine(workers, ray_address)
        config = pipeline_config(size_values)
        read, documents = _archive(archive, window_s, actuator_file, log_map_file)
    except BaseException:
        if pool is not None:
            pool.close()
        raise
    report_log(read)
    print(f"ema fleet: {len(read.windows)} window(s) from {archive}, {workers} worker(s)", file=sys.stderr)
    run = run_fleet(
        read.windows,
        out,
        config=config,
        workers=workers,
        address=ray_address,
        threads=threads,
        database=database,
        documents=documents,
        pool=pool,
        started=started,
        conflicts=read.conflicts,
    )
    result = {**run, "bad_files": read.bad_files}
    emit(result, as_json, _print_fleet_verbose if verbose else _print_fleet)
    if result["answered"] + result["skipped"] == 0 and result["refused"]:
        raise NothingAnsweredError(f"none of the {result['refused']} window(s) was answered (see {out})")


def _archive(archive: Path, window_s: float | None, actuator_file: Path | None, log_map_file: Path | None) -> Any:
    """(the archive's windows as read, the documents they are read with: the folder's actuators.json, else
    ``--actuator``)."""
    from ema.cli.logs import read_actuators, read_log
    from ema.cli.workers import Documents
    from ema.model.actuator import read_actuator

    documents = Documents(read_actuators(archive), None if actuator_file is None else read_actuator(actuator_file))
    return read_log(archive, window_s, log_map=log_map_document(log_map_file)), documents


def _print_fleet_verbose(result: dict) -> None:
    _print_fleet(result)
    phases = result["phases_s"]
    click.echo(
        f"time: start-up {phases['start-up']:.1f} s (reading the archive, starting the workers, the first window), "
        f"windows {phases['windows']:.1f} s, of which writing rows {phases['writing']:.1f} s; total "
        f"{result['seconds']:.1f} s"
    )


def _print_fleet(result: dict) -> None:
    skipped = f", {len(result['bad_files'])} unreadable file(s) skipped" if result["bad_files"] else ""
    click.echo(
        f"{result['answered']} answered, {result['refused']} refused, {result['skipped']} already in "
        f"{result['csv']}{skipped}; {result['windows_per_s']:.2f} windows/s on {result['workers']} worker(s) "
        f"({result['engine']})"
    )


@click.command()
@click.option(
    "--out",
    type=OUTPUT_FOLDER,
    default=None,
    help="also write the figures as bench.json in this folder  [default: print them, write nothing]",
)
@click.option(
    "--repeats",
    type=click.IntRange(1, 1000),
    default=45,
    help="windows per duration (the verdict on a p95 needs 45 or more to say 'met')",
)
@click.option(
    "--durations", default="0.5,2", help=f"window durations [s], comma-separated, each {span(DURATION_RANGE_S)}"
)
@click.option(
    "--under-load",
    type=click.IntRange(0, 64),
    default=0,
    help="also time with this many CPU-bound processes running beside",
)
@click.option("--docs", is_flag=True, help="rewrite the section of docs/benchmarks.md")
@sizes
@as_json
def bench(
    *, out: Path | None, repeats: int, durations: str, under_load: int, docs: bool, as_json: bool, **size_values: int
) -> None:
    """Latency of one window -> estimates: p50/p95 per stage, real-time factor, accuracy (idle, and under load)."""
    from ema.cli.bench import run_bench
    from ema.model.checks import in_range

    seconds = [in_range("--durations", d, *DURATION_RANGE_S, "s") for d in durations.split(",")]  # at 10 kHz
    result = run_bench(
        pipeline_config(size_values), seconds, repeats=repeats, under_load=under_load, out=out, docs=docs
    )
    emit(result, as_json, lambda r: click.echo(r["table"]))


COMMANDS = (fleet, bench)
