"""``ema replay``: post a recorded log to the service window by window, in order, and keep the answers.

Answers are appended to a CSV as they arrive (``ema.cli.results``); a rerun skips the windows the CSV
holds answered and posts the refused ones again (a refusal may be the service's, such as a budget an
operator has since raised). A 503 is waited out (Retry-After) and the same window retried. A refusal
(422, or 409 for another window under a stored window_id) is kept as its fields and messages. The
API key comes from a file or EMA_API_KEY, never from the command line (where ``ps`` shows it).
"""

from __future__ import annotations

import http.client
import json
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Callable
from pathlib import Path
from typing import Any
from urllib.parse import quote

from ema.cli.results import ResultsWriter, done_windows, row_of
from ema.model.actuator import ActuatorDocument
from ema.model.window import Window, window_to_dict

MAX_WAIT_S = 600.0


class ServiceError(Exception):
    """The service could not be reached or failed; not the window's fault."""


def request(
    url: str, api_key: str | None, data: bytes | None = None, timeout: float = 900, method: str | None = None
) -> dict[str, Any]:
    """One HTTP request to the service (GET, POST with ``data``, or ``method``); the JSON answer, or HTTPError /
    ServiceError."""
    headers = {"content-type": "application/json", **({"x-api-key": api_key} if api_key else {})}
    asked = urllib.request.Request(url, data=data, headers=headers, method=method)
    try:
        with urllib.request.urlopen(asked, timeout=timeout) as r:
            return json.loads(r.read())
    except urllib.error.HTTPError:
        raise
    except urllib.error.URLError as error:
        raise ServiceError(f"cannot reach the service at {url}: {error.reason}") from None
    except (ConnectionError, http.client.HTTPException, TimeoutError) as error:
        reason = str(error) or type(error).__name__
        raise ServiceError(
            f"the service at {url} stopped answering mid-request ({reason}): is it still running?"
        ) from None


def post_window(url: str, window: Window, api_key: str | None, sleep: Callable[[float], None] = time.sleep) -> dict:
    """POST one window; wait out 503s. Returns the estimate, or {"error": ...} for a 422 about this window."""
    body = json.dumps(window_to_dict(window)).encode()
    waited = 0.0
    while True:
        try:
            return request(f"{url.rstrip('/')}/v1/estimate", api_key, body)
        except urllib.error.HTTPError as error:
            detail = error.read().decode(errors="replace")
            if error.code == 503 and error.headers.get("Retry-After") is not None and waited < MAX_WAIT_S:
                pause = float(error.headers["Retry-After"])
                print(f"  service busy, retrying {window.window_id} in {pause:g} s", file=sys.stderr)
                sleep(pause)
                waited += pause
                continue
            if error.code in (401, 403):
                raise key_refused(url, error.code, detail) from None
            if error.code in (409, 422):
                return {"error": refusal_text(error.code, detail)}
            raise ServiceError(f"HTTP {error.code} for {window.window_id}: {detail[:300]}") from None


def put_documents(
    url: str, documents: dict[str, ActuatorDocument], api_key: str | None, sources: dict[str, str]
) -> dict[str, int]:
    """Each actuator's document stored in the service before its windows are posted (``PUT /v1/actuators/{id}``:
    the same document again stores nothing new, so a rerun adds no version); the versions it holds them under. A
    document refused is an InputError naming where it came from (``sources``: a flag or a file), a key refused
    one naming --api-key-file: said before any window is posted."""
    from ema.model.checks import InputError

    versions = {}
    for actuator_id, document in documents.items():
        body = document.model_dump_json(by_alias=True).encode()
        try:
            stored = request(f"{url}/v1/actuators/{quote(actuator_id, safe='/')}", api_key, body, 60, "PUT")
        except urllib.error.HTTPError as error:
            detail = error.read().decode(errors="replace")
            if error.code in (401, 403):
                raise key_refused(url, error.code, detail) from None
            said = refusal_text(error.code, detail)
            if error.code == 422:
                raise InputError(sources[actuator_id], f"the service refused it for {actuator_id}: {said}") from None
            raise ServiceError(f"HTTP {error.code} storing the document of {actuator_id}: {said[:300]}") from None
        versions[actuator_id] = int(stored["version"])
    return versions


def key_refused(url: str, status: int, body: str) -> Exception:
    """The InputError naming --api-key-file for a 401 or 403: the key is missing or not this service's."""
    from ema.model.checks import InputError

    said = refusal_text(status, body) if body.lstrip().startswith("{") else f"HTTP {status}"
    return InputError("--api-key-file", f"{url} refused the key ({said}): give its key in a file, or EMA_API_KEY")


def refusal_text(status: int, body: str) -> str:
    """A 422 or 409 answer as a person reads it: each ``field: message`` (the body as is if it is not ours)."""
    try:
        items = json.loads(body)["detail"]
        parts = [f"{'.'.join(str(p) for p in item['loc'] if p != 'body')}: {item['msg']}" for item in items]
    except (ValueError, KeyError, TypeError):
        return f"HTTP {status}: {body}"
    return ("conflict: " if status == 409 else "") + "; ".join(parts)


def answered(row: dict) -> str:
    """A stored answer in a few words: FDJ, and η_O where the window read it."""
    eta = "η_O not read" if row.get("eta_O") is None else f"η_O {row['eta_O']:.4f}"
    return f"FDJ {row['FDJ']:.5g}  {eta}"


def replay(windows: list[Window], url: str, out: Path, api_key: str | None = None) -> list[dict[str, Any]]:
    """Post every window not yet in ``out``, appending each answer as it comes; returns the new rows."""
    done = done_windows(out, answered_only=True)
    todo = [w for w in windows if (w.actuator_id, w.window_id) not in done]
    if done:
        print(f"resuming: {len(windows) - len(todo)} window(s) already in {out}", file=sys.stderr)
    rows = []
    started = time.perf_counter()
    with ResultsWriter(out) as writer:
        for index, window in enumerate(todo, 1):
            row = row_of(window.actuator_id, window.window_id, post_window(url, window, api_key))
            writer.write(row)
            rows.append(row)
            status = f"refused: {row['error']}" if row.get("error") else answered(row)
            elapsed = time.perf_counter() - started
            eta = elapsed / index * (len(todo) - index)
            print(
                f"[{index}/{len(todo)}] {window.window_id}: {status}  ({index / elapsed:.2f} windows/s, "
                f"{eta:.0f} s left)",
                file=sys.stderr,
            )
    return rows
