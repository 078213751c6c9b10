"""``ema replay``: post a recorded log to the service window by window, in order, and keep the answers.

Answers are appended to a CSV as they arrive (a crash loses nothing), and a replay into an existing
CSV skips the windows it already holds, so an interrupted replay resumes where it stopped. A 503
is waited out (Retry-After) and the same window retried: nothing is skipped or sent twice.
"""

from __future__ import annotations

import csv
import json
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Callable
from pathlib import Path
from typing import Any

from sim.window import Window, window_to_dict

COLUMNS = (
    "actuator_id", "window_id", "FDJ", "FDJ_std", "eta_O", "eta_O_std", "eta_A", "eta_A_std", "FSJ", "total_s", "error",
)  # fmt: skip
MAX_WAIT_S = 120.0


class ServiceError(Exception):
    """The service could not be reached or failed; not the window's fault."""


def post_window(url: str, window: Window, api_key: str | None, sleep: Callable[[float], None] = time.sleep) -> dict:
    """POST one window; wait out 503s. Returns the estimate, or {"error": ...} for a 422 about this window."""
    body = json.dumps(window_to_dict(window)).encode()
    headers = {"content-type": "application/json", **({"x-api-key": api_key} if api_key else {})}
    waited = 0.0
    while True:
        request = urllib.request.Request(f"{url.rstrip('/')}/v1/estimate", data=body, headers=headers, method="POST")
        try:
            with urllib.request.urlopen(request, timeout=600) as response:
                return json.loads(response.read())
        except urllib.error.HTTPError as error:
            if error.code == 503 and waited < MAX_WAIT_S:
                pause = float(error.headers.get("Retry-After", "1"))
                print(f"  service busy, retrying {window.window_id} in {pause:g} s", file=sys.stderr)
                sleep(pause)
                waited += pause
                continue
            detail = error.read().decode(errors="replace")
            if error.code == 422:
                return {"error": detail}
            raise ServiceError(f"HTTP {error.code} for {window.window_id}: {detail[:300]}") from None
        except urllib.error.URLError as error:
            raise ServiceError(f"cannot reach {url}: {error.reason}") from None


def row_of(window: Window, answer: dict[str, Any]) -> dict[str, Any]:
    row: dict[str, Any] = {"actuator_id": window.actuator_id, "window_id": window.window_id}
    if "error" in answer:
        return {**row, "error": answer["error"]}
    estimates = answer["estimates"]
    for name in ("FDJ", "eta_O", "eta_A"):
        row[name], row[f"{name}_std"] = estimates[name]["value"], estimates[name]["std"]
    row["FSJ"] = None if estimates["FSJ"] is None else estimates["FSJ"]["value"]
    row["total_s"] = answer["timings_s"]["total"]
    return row


def done_windows(out: Path) -> set[tuple[str, str]]:
    """(actuator_id, window_id) of the answered rows already in ``out``."""
    if not out.exists():
        return set()
    with out.open(newline="") as handle:
        return {(r["actuator_id"], r["window_id"]) for r in csv.DictReader(handle) if not r.get("error")}


def replay(windows: list[Window], url: str, out: Path, api_key: str | None = None) -> list[dict[str, Any]]:
    """Post every window not yet in ``out``, appending each answer as it comes; returns the new rows."""
    done = done_windows(out)
    todo = [w for w in windows if (w.actuator_id, w.window_id) not in done]
    if done:
        print(f"resuming: {len(windows) - len(todo)} window(s) already in {out}", file=sys.stderr)
    rows = []
    new_file = not out.exists()
    with out.open("a", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS)
        if new_file:
            writer.writeheader()
        for index, window in enumerate(todo, 1):
            started = time.perf_counter()
            row = row_of(window, post_window(url, window, api_key))
            writer.writerow(row)
            handle.flush()
            rows.append(row)
            status = row["error"][:80] if row.get("error") else f"FDJ {row['FDJ']:.5f}  η_O {row['eta_O']:.4f}"
            elapsed = time.perf_counter() - started
            print(f"[{index}/{len(todo)}] {window.window_id}: {status} ({elapsed:.1f} s)", file=sys.stderr)
    return rows


def command_replay(args: Any) -> dict[str, Any]:
    """``ema replay``: read the log (bad files exit 2 naming them), post, collect."""
    from clients.logs import Defaults, windows_of

    defaults = Defaults(args.actuator_id, args.rate, args.airspeed, args.altitude)
    windows = []
    for window, dropped in windows_of(args.log, args.window_s, defaults):
        windows.append(window)
        if dropped:
            print(
                f"{window.window_id}: the last {dropped} sample(s) of its recording do not fill a window",
                file=sys.stderr,
            )
    print(f"replaying {len(windows)} window(s) from {args.log} to {args.url}", file=sys.stderr)
    rows = replay(windows, args.url, args.out, args.api_key)
    return {"csv": str(args.out), "posted": len(rows), "rows": rows}


def print_replay(result: dict[str, Any]) -> None:
    print(f"{'window':<36}{'FDJ [N·m]':>12}{'η_O':>9}{'η_A':>9}{'total [s]':>11}")
    for row in result["rows"]:
        if row.get("error"):
            print(f"{row['window_id']:<36}  rejected: {row['error'][:60]}")
            continue
        print(
            f"{row['window_id']:<36}{row['FDJ']:>12.5f}{row['eta_O']:>9.4f}{row['eta_A']:>9.4f}{row['total_s']:>11.2f}"
        )
    print(f"{result['posted']} window(s) posted; all estimates in {result['csv']}")
