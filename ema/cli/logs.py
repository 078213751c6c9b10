"""Recorded logs -> windows: JSON windows (one, a list, or a long recording), CSV, NPZ, or a folder of them.

A recording longer than the window length is cut into consecutive windows of that length,
``window_id`` = ``<recording id>#<index>``; a tail shorter than a window is dropped and said so. A
recording is one power-on of the drive: its pieces share its ``flight_id`` (the recording's id where it
names none), so a piece moving one way is read with the sensors' zero another piece read.
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from ema.model.actuator import ActuatorDocument, actuator_from_dict
from ema.model.checks import InputError, load_json
from ema.model.envelope import DEFAULT_AIRSPEED_MPS
from ema.model.logmap import LogMap, read_mapped
from ema.model.window import SIGNALS, Window, window_from_dict

SUFFIXES = (".json", ".csv", ".npz")
ACTUATORS_FILE = "actuators.json"  # in an archive's folder: {actuator_id: its ema-actuator/1 document}


@dataclass(frozen=True)
class Defaults:
    """Metadata for formats that may lack it (CSV, NPZ): flags of ``ema replay``."""

    actuator_id: str = "unknown"
    sample_rate_hz: float = 10_000.0
    airspeed_mps: float = DEFAULT_AIRSPEED_MPS
    altitude_m: float = 0.0


def cut(window: Window, window_s: float) -> tuple[list[Window], int]:
    """Consecutive windows of ``window_s`` seconds; returns them and the number of samples dropped."""
    n = round(window_s * window.sample_rate_hz)
    if window.n_samples <= n:
        return [window], 0
    count = window.n_samples // n
    pieces = [
        replace(
            window,
            signals={name: values[i * n : (i + 1) * n] for name, values in window.signals.items()},
            window_id=f"{window.window_id}#{i}",
            flight_id=window.flight_id or window.window_id,
        )
        for i in range(count)
    ]
    return pieces, window.n_samples - count * n


def _from_json(path: Path) -> list[Window]:
    document = json.loads(path.read_text())
    documents = document if isinstance(document, list) else [document]
    return [window_from_dict(d) for d in documents]


def _from_csv(path: Path, defaults: Defaults) -> list[Window]:
    """Columns named as the window's signals (others ignored); ``# key: value`` lines on top give metadata
    (``actuator_id``, ``window_id``, ``sample_rate_hz``, ``airspeed_mps``, ``altitude_m``, ``recorded_at``,
    ``flight_hours``, ``flight_id``)."""
    meta: dict[str, str] = {}
    lines = path.read_text().splitlines()
    body = [line for line in lines if not line.startswith("#")]
    for line in lines:
        if line.startswith("#") and ":" in line:
            key, value = line[1:].split(":", 1)
            meta[key.strip()] = value.strip()
    rows = list(csv.DictReader(body))
    if not rows:
        raise InputError(str(path), "has no data rows")
    missing = [name for name in SIGNALS if name not in rows[0]]
    if missing:
        raise InputError(str(path), f"lacks the column(s) {', '.join(missing)}")
    try:
        signals = {name: np.array([float(row[name]) for row in rows]) for name in SIGNALS}
    except (TypeError, ValueError) as exc:
        raise InputError(str(path), f"has a non-numeric value ({exc})") from None
    return [_window(signals, meta, defaults, path)]


def _from_npz(path: Path, defaults: Defaults) -> list[Window]:
    with np.load(path, allow_pickle=False) as archive:
        missing = [name for name in SIGNALS if name not in archive]
        if missing:
            raise InputError(str(path), f"lacks the array(s) {', '.join(missing)}")
        signals = {name: np.asarray(archive[name], dtype=np.float64) for name in SIGNALS}
        meta = {key: str(archive[key]) for key in archive.files if key not in SIGNALS}
    return [_window(signals, meta, defaults, path)]


def _window(signals: dict[str, np.ndarray], meta: dict[str, Any], defaults: Defaults, path: Path) -> Window:
    """Arrays and metadata through the ema-window/1 contract, as a JSON window would go."""
    try:
        document: dict[str, Any] = {
            "schema": "ema-window/1",
            "actuator_id": str(meta.get("actuator_id", defaults.actuator_id)),
            "window_id": str(meta.get("window_id", path.stem)),
            "sample_rate_hz": float(meta.get("sample_rate_hz", defaults.sample_rate_hz)),
            "flight_condition": {
                "airspeed_mps": float(meta.get("airspeed_mps", defaults.airspeed_mps)),
                "altitude_m": float(meta.get("altitude_m", defaults.altitude_m)),
            },
            "signals": {name: values.tolist() for name, values in signals.items()},
            **{key: str(meta[key]) for key in ("recorded_at", "flight_id") if key in meta},
            **({"flight_hours": float(meta["flight_hours"])} if "flight_hours" in meta else {}),
        }
    except ValueError as exc:
        raise InputError(str(path), f"has metadata that is not a number ({exc})") from None
    return window_from_dict(document)


def read_file(path: Path, defaults: Defaults = Defaults(), log_map: LogMap | None = None) -> list[Window]:
    """Every window in one file (a CSV through ``log_map`` where one is given: ``ema.model.logmap``); errors
    name the file."""
    readers = {".json": lambda: _from_json(path), ".csv": lambda: _from_csv(path, defaults)}
    if log_map is not None:
        readers[".csv"] = lambda: [window_from_dict(read_mapped(path, log_map))]
    readers[".npz"] = lambda: _from_npz(path, defaults)
    if path.suffix.lower() not in readers:
        raise InputError(str(path), f"is not a {'/'.join(SUFFIXES)} file")
    try:
        return readers[path.suffix.lower()]()
    except InputError as exc:
        if exc.field == str(path):
            raise
        raise InputError(str(path), f"{exc.field}: {exc.message}") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, ValueError) as exc:
        raise InputError(str(path), f"cannot be read ({exc})") from None


@dataclass(frozen=True)
class Log:
    """What a log holds: its windows in order, the tails its cuts dropped, and the files of a folder that
    could not be read (each skipped with its reason: one bad file does not stop an archive job)."""

    windows: list[Window]
    dropped: dict[str, int]  # window_id -> samples after it that did not fill a window
    bad_files: dict[str, str]  # file -> why it was skipped


def read_log(path: Path, window_s: float | None, defaults: Defaults = Defaults(), log_map: LogMap | None = None) -> Log:
    """The windows of a file, or of a folder's files in name order, long recordings cut to ``window_s``. A
    bad file given alone is an InputError naming it; in a folder it is skipped and listed, and only a folder
    with no readable window is an error. ``window_s`` None: every file's windows as they are."""
    path = Path(path)
    if not path.exists():
        raise InputError(str(path), "does not exist")
    if path.is_dir():
        files = sorted(p for p in path.iterdir() if p.suffix.lower() in SUFFIXES and p.name != ACTUATORS_FILE)
    else:
        files = [path]
    if not files:
        raise InputError(str(path), f"holds no {'/'.join(SUFFIXES)} file")
    windows: list[Window] = []
    dropped: dict[str, int] = {}
    bad: dict[str, str] = {}
    for file in files:
        try:
            recordings = read_file(file, defaults, log_map)
        except InputError as exc:
            if not path.is_dir():
                raise
            bad[str(file)] = exc.message
            continue
        for recording in recordings:
            pieces, tail = cut(recording, window_s) if window_s is not None else ([recording], 0)
            windows.extend(pieces)
            if tail:
                dropped[pieces[-1].window_id] = tail
    if not windows:
        first = next(iter(bad.items()), None)
        raise InputError(str(path), "holds no readable window" + (f" ({first[0]}: {first[1]})" if first else ""))
    return Log(windows, dropped, bad)


def read_actuators(folder: Path) -> dict[str, ActuatorDocument]:
    """The documents of an archive's actuators, from its ``ACTUATORS_FILE`` (none where it has none); a bad
    one is an InputError naming the file and the actuator."""
    path = Path(folder) / ACTUATORS_FILE
    if not Path(folder).is_dir() or not path.exists():
        return {}
    documents = load_json(path)
    if not isinstance(documents, dict):
        raise InputError(str(path), "must map each actuator_id to its ema-actuator/1 document")
    read = {}
    for actuator_id, document in documents.items():
        try:
            read[actuator_id] = actuator_from_dict(document)
        except InputError as exc:
            raise InputError(f"{path}: {actuator_id}: {exc.field}", exc.message) from None
    return read


def read_one(path: Path, log_map: LogMap | None = None) -> Window:
    """The one window of a file (JSON, CSV or NPZ, a CSV through ``log_map``): what ``ema estimate`` reads; a
    file of several is refused naming it (``ema replay`` posts each)."""
    windows = read_file(Path(path), Defaults(), log_map)
    if len(windows) != 1:
        raise InputError(str(path), f"holds {len(windows)} windows: ema estimate reads one (ema replay posts each)")
    return windows[0]
