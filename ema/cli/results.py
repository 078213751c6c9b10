"""The results CSV of ``ema replay`` and ``ema fleet``: one row per window, appended as answers arrive.

A row is written and flushed as soon as its window is answered (or refused), so a crash loses
nothing, and a rerun skips the windows already in the file (``ema replay`` posts its refused ones
again, in a row of their own): nothing answered is posted or computed twice. The service's history
is idempotent too, so the window that was in flight when a client died is answered from the history
on the rerun, not stored twice.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Any

COLUMNS = (
    "actuator_id",
    "window_id",
    "FDJ",
    "FDJ_std",
    "FDJ_unit",
    "eta_O",
    "eta_O_std",
    "eta_A",
    "eta_A_std",
    "FSJ",
    "FSJ_std",
    "reproduced",
    "replay",
    "simulate_s",
    "learn_s",
    "assess_s",
    "total_s",
    "error",
    "document",
)


def row_of(actuator_id: str, window_id: str, answer: dict[str, Any]) -> dict[str, Any]:
    """A CSV row from an ema-estimate/1 document (as JSON), or from {"error": ...}."""
    row: dict[str, Any] = {"actuator_id": actuator_id, "window_id": window_id}
    if "error" in answer:
        error = answer["error"]
        return {**row, "error": f"{error['field']}: {error['message']}" if isinstance(error, dict) else error}
    for name in ("FDJ", "eta_O", "eta_A", "FSJ"):
        entry = answer["estimates"][name]
        row[name], row[f"{name}_std"] = (None, None) if entry is None else (entry["value"], entry["std"])
    row["FDJ_unit"] = answer["estimates"]["FDJ"].get("unit")
    timings = answer["timings_s"]
    aliases = {"learn": "train", "assess": "predict"}  # an answer of a service of the first stage names
    row.update(
        {
            f"{stage}_s": timings.get(stage, timings.get(aliases.get(stage, "")))
            for stage in ("simulate", "learn", "assess", "total")
        }
    )
    row["reproduced"] = (answer.get("check") or answer["fit_check"])["reproduced"]  # a first-stage service: fit_check
    row["replay"] = answer.get("replay", False)
    return row


def refused_under(path: Path) -> dict[tuple[str, str], str]:
    """(actuator_id, window_id) -> the document digest (``document_digest``) each window whose last row in ``path``
    is a refusal was refused under ("" where the row predates the column): a window refused under a document that
    has changed since is read again."""
    if not path.exists():
        return {}
    last: dict[tuple[str, str], dict[str, str]] = {}
    with path.open(newline="") as handle:
        for row in csv.DictReader(handle):
            last[(row["actuator_id"], row["window_id"])] = row
    return {key: row.get("document") or "" for key, row in last.items() if row["error"]}


def document_digest(document: Any) -> str:
    """A short digest of the document a window is read with (``default`` for the thesis's): what a refusal was
    made under."""
    if document is None:
        return "default"
    import hashlib

    text = document.model_dump_json(by_alias=True, exclude_none=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def done_windows(path: Path, answered_only: bool = False) -> set[tuple[str, str]]:
    """(actuator_id, window_id) of every row already in ``path``: answered, or refused as bad input (only
    the answered ones with ``answered_only``)."""
    if not path.exists():
        return set()
    with path.open(newline="") as handle:
        rows = csv.DictReader(handle)
        return {(r["actuator_id"], r["window_id"]) for r in rows if not (answered_only and r["error"])}


class ResultsWriter:
    """Appends rows to the CSV, each flushed to disk before the next window starts; the file is created at the
    first row (a run that answers nothing writes nothing), and an existing file keeps its own columns."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._handle: Any = None
        self._writer: csv.DictWriter | None = None

    def _open(self) -> csv.DictWriter:
        new = not self.path.exists() or self.path.stat().st_size == 0
        columns = list(COLUMNS)
        if not new:
            with self.path.open(newline="") as handle:
                columns = next(csv.reader(handle), columns)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._handle = self.path.open("a", newline="")
        writer = csv.DictWriter(self._handle, fieldnames=columns, extrasaction="ignore", restval="")
        if new:
            writer.writeheader()
        return writer

    def write(self, row: dict[str, Any]) -> None:
        if self._writer is None:
            self._writer = self._open()
        self._writer.writerow(row)
        self._handle.flush()
        os.fsync(self._handle.fileno())

    def close(self) -> None:
        if self._handle is not None:
            self._handle.close()

    def __enter__(self) -> ResultsWriter:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()
