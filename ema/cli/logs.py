"""Recorded logs -> windows: JSON windows (one, a list, or a long recording), CSV, NPZ, or a folder of them.

A recording longer than the window length is cut into consecutive windows of that length,
``window_id`` = ``<recording id>#<index>``; a tail shorter than a window is dropped and said so. A
recording is one power-on of the drive: its pieces share its ``flight_id`` (the recording's id where it
names none), so a piece moving one way is read with the sensors' zero another piece read.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from ema.model.actuator import ACTUATOR_SCHEMA, ActuatorDocument, actuator_from_dict
from ema.model.bounds import DEFAULT_SAMPLE_RATE_HZ, MIN_SAMPLES
from ema.model.checks import InputError, load_json
from ema.model.envelope import DEFAULT_AIRSPEED_MPS
from ema.model.kinds import ALL_SIGNALS, KINDS, KindFacts, nearest_kind
from ema.model.log_files import TABLE_SUFFIXES, EmaDocumentError, read_table
from ema.model.logmap import LOGMAP_SCHEMA, LogMap, read_mapped
from ema.model.window import WINDOW_SCHEMA, Window, window_from_dict

SUFFIXES = (".json", *TABLE_SUFFIXES)
ACTUATORS_FILE = "actuators.json"  # in an archive's folder: {actuator_id: its ema-actuator/1 document}
GIVEN_BY_FLAG = {ACTUATOR_SCHEMA: "--actuator", LOGMAP_SCHEMA: "--log-map"}  # documents that go beside a log


@dataclass(frozen=True)
class Defaults:
    """Metadata for formats that may lack it (CSV, NPZ): flags of ``ema replay``."""

    actuator_id: str = "unknown"
    sample_rate_hz: float = DEFAULT_SAMPLE_RATE_HZ
    airspeed_mps: float = DEFAULT_AIRSPEED_MPS
    altitude_m: float = 0.0


def cut(window: Window, window_s: float) -> tuple[list[Window], int]:
    """Consecutive windows of ``window_s`` seconds; returns them and the number of samples dropped (``read_log``
    cuts no recording ``too_short_to_cut``)."""
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


def too_short_to_cut(window: Window, window_s: float) -> str | None:
    """Why ``window`` is not cut into pieces of ``window_s`` seconds (each would hold fewer samples than a window
    may), or None."""
    n = round(window_s * window.sample_rate_hz)
    if n >= MIN_SAMPLES or window.n_samples <= n:
        return None
    return (
        f"kept whole: {window_s:g} s at {window.sample_rate_hz:g} Hz is {n} sample(s), under a window's {MIN_SAMPLES} "
        f"(--window-s {MIN_SAMPLES / window.sample_rate_hz:.3g} or more cuts it)"
    )


def _from_json(path: Path) -> list[Window]:
    """The windows of a JSON file; another of ema's documents (one that goes beside a log, kept in its folder) is
    refused saying what it is and the flag that takes it."""
    document = load_json(path)
    schema = document.get("schema") if isinstance(document, dict) else None
    if isinstance(schema, str) and schema.startswith("ema-") and schema != WINDOW_SCHEMA:
        flag = GIVEN_BY_FLAG.get(schema)
        raise InputError(
            str(path), f"is an {schema} document, not a window" + (f": give it with {flag}" if flag else "")
        )
    documents = document if isinstance(document, list) else [document]
    return [window_from_dict(d) for d in documents]


def _from_table(path: Path, defaults: Defaults) -> list[Window]:
    """A CSV or NPZ in ema's own columns, named as the signals of a window of its kind (the kind whose signals
    it holds: ``tabled_kind``; others ignored); a CSV's ``# key: value`` lines on top, an NPZ's text arrays, give
    metadata (``actuator_id``, ``window_id``, ``sample_rate_hz``, ``airspeed_mps``, ``altitude_m``,
    ``recorded_at``, ``flight_hours``, ``flight_id``)."""
    table = read_table(path)
    for name in ALL_SIGNALS:
        if name in table.unread:
            table.numeric(name, path, "a window's signal")  # names the cell that is no number
    kind = tabled_kind(path, set(table.columns))
    meta = {**{k: str(v) for k, v in table.scalars.items()}, **table.meta}
    signals = {name: table.columns[name] for name in kind.all_signals if name in table.columns}
    return [_window(signals, meta, defaults, path)]


def tabled_kind(path: Path, columns: set[str]) -> KindFacts:
    """The one kind whose every signal is a column; an InputError naming the file where none is (the nearest
    kind's missing columns said, and the log map a file in its own columns needs) or several are."""
    found = [kind for kind in KINDS.values() if set(kind.signals) <= columns]
    if len(found) == 1:
        return found[0]
    if found:
        names = " and ".join(kind.name for kind in found)
        raise InputError(str(path), f"holds the columns of a {names} window alike: keep one kind's")
    own = "a log in its own columns and units is read through --log-map"
    if not columns & set(ALL_SIGNALS):
        kinds = "; ".join(f"a {kind.name}'s {', '.join(kind.signals)}" for kind in KINDS.values())
        raise InputError(str(path), f"has no numeric column named as a window's signals ({kinds}): {own}")
    nearest = nearest_kind(columns)
    missing = ", ".join(name for name in nearest.signals if name not in columns)
    raise InputError(str(path), f"lacks the numeric column(s) {missing} of a {nearest.name} window ({own})")


def _window(signals: dict[str, np.ndarray], meta: dict[str, Any], defaults: Defaults, path: Path) -> Window:
    """Arrays and metadata through the ema-window/1 contract, as a JSON window would go."""
    try:
        document: dict[str, Any] = {
            "schema": WINDOW_SCHEMA,
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
    """Every window in one file: a JSON window, a CSV or NPZ in ema's columns, or any logged file (CSV, MATLAB,
    NPZ, a recorder's JSON) through ``log_map`` (``ema.model.logmap``); errors name the file."""
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise InputError(str(path), f"is not a {'/'.join(SUFFIXES)} file")
    if suffix == ".mat" and log_map is None:
        raise InputError(str(path), "is a MATLAB file: its variables become a window's signals through --log-map")
    try:
        if suffix == ".json" and log_map is None:
            return _from_json(path)
        if log_map is not None:  # a recorder's JSON too, parsed once: its map names its fields
            try:
                return [window_from_dict(read_mapped(path, log_map))]
            except EmaDocumentError:  # one of ema's documents beside the logs: read, or refused naming its flag
                return _from_json(path)
        return _from_table(path, defaults)
    except InputError as exc:
        if exc.field.startswith(str(path)):
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
    kept_whole: dict[str, str] = field(default_factory=dict)  # window_id -> why it was not cut (too_short_to_cut)
    # (actuator_id, window_id) -> the files that hold that one key with different content: none of them is read
    conflicts: dict[tuple[str, str], list[str]] = field(default_factory=dict)


def read_log(path: Path, window_s: float | None, defaults: Defaults = Defaults(), log_map: LogMap | None = None) -> Log:
    """The windows of a file, or of a folder's files in name order, long recordings cut to ``window_s`` (None:
    each to its kind's ``window_s``, a servo's log or a rig's run kept whole). A bad file given alone is an
    InputError naming it; in a folder it is skipped and listed, and only a folder with no readable window is an
    error."""
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
    kept_whole: dict[str, str] = {}
    sources: dict[tuple[str, str], list[str]] = {}  # key -> the files it was read from
    for file in files:
        try:
            recordings = read_file(file, defaults, log_map)
        except InputError as exc:
            if not path.is_dir():
                raise
            variable = exc.field.removeprefix(str(file)).removeprefix(": ")  # the variable at fault, where named
            bad[str(file)] = f"{variable}: {exc.message}" if variable else exc.message
            continue
        for recording in recordings:
            length = window_s if window_s is not None else KINDS[recording.kind].cut_s
            whole = None if length is None else too_short_to_cut(recording, length)
            if whole is not None:
                kept_whole[recording.window_id] = whole
            pieces, tail = cut(recording, length) if length is not None and whole is None else ([recording], 0)
            windows.extend(pieces)
            for piece in pieces:
                sources.setdefault((piece.actuator_id, piece.window_id), []).append(str(file))
            if tail:
                dropped[pieces[-1].window_id] = tail
    windows, conflicts = _one_file_a_key(windows, sources)
    if not windows and not conflicts:
        first = next(iter(bad.items()), None)
        raise InputError(str(path), "holds no readable window" + (f" ({first[0]}: {first[1]})" if first else ""))
    return Log(windows, dropped, bad, kept_whole, conflicts)


def _one_file_a_key(
    windows: list[Window], sources: dict[tuple[str, str], list[str]]
) -> tuple[list[Window], dict[tuple[str, str], list[str]]]:
    """(the windows with every key (actuator_id, window_id) once, the keys read from none): a window met again with
    the same content (a file copied) is read once; a key met in several files with different content is read from
    none, and its files listed, whatever order they were read in."""
    kept: dict[tuple[str, str], Window] = {}
    differing: set[tuple[str, str]] = set()
    for window in windows:
        key = (window.actuator_id, window.window_id)
        if key not in kept:
            kept[key] = window
        elif kept[key].content_sha256() != window.content_sha256():
            differing.add(key)
    conflicts = {key: sorted(set(sources[key])) for key in differing}
    return [window for key, window in kept.items() if key not in differing], conflicts


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
    """The one window of a file (JSON, CSV or NPZ, any logged file through ``log_map``): what ``ema estimate`` reads; a
    file of several is refused naming it (``ema replay`` posts each)."""
    windows = read_file(Path(path), Defaults(), log_map)
    if len(windows) != 1:
        raise InputError(str(path), f"holds {len(windows)} windows: ema estimate reads one (ema replay posts each)")
    return windows[0]
