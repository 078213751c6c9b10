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
    "eta_O",
    "eta_O_std",
    "eta_A",
    "eta_A_std",
    "FSJ",
    "FSJ_std",
    "reproduced",
    "replay",
    "simulate_s",
    "train_s",
    "predict_s",
    "total_s",
    "error",
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
    timings = answer["timings_s"]
    row.update({f"{stage}_s": timings[stage] for stage in ("simulate", "train", "predict", "total")})
    row["reproduced"] = answer["fit_check"]["reproduced"]
    row["replay"] = answer.get("replay", False)
    return row


def done_windows(path: Path, answered_only: bool = False) -> set[tuple[str, str]]:
    """(actuator_id, window_id) of every row already in ``path``: answered, or refused as bad input (only
    the answered ones with ``answered_only``)."""
    if not path.exists():
        return set()
    with path.open(newline="") as handle:
        rows = csv.DictReader(handle)
        return {(r["actuator_id"], r["window_id"]) for r in rows if not (answered_only and r["error"])}


class ResultsWriter:
    """Appends rows to the CSV, each flushed to disk before the next window starts."""

    def __init__(self, path: Path) -> None:
        new = not path.exists() or path.stat().st_size == 0
        self._handle = path.open("a", newline="")
        self._writer = csv.DictWriter(self._handle, fieldnames=COLUMNS)
        if new:
            self._writer.writeheader()

    def write(self, row: dict[str, Any]) -> None:
        self._writer.writerow(row)
        self._handle.flush()
        os.fsync(self._handle.fileno())

    def close(self) -> None:
        self._handle.close()

    def __enter__(self) -> ResultsWriter:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()
