"""What is checked before a request's body is read: its host, its key, its origin, its type and encoding, its
declared size; and while it is read, its size, its pace and the memory all bodies in flight hold.

A pure ASGI middleware, so that a wrong key gets its 401 (and an oversized body its 413) at once,
from the headers alone, with nothing parsed on the event loop. The key is compared as bytes in
constant time (a non-ASCII header is simply wrong, not an error). Without a key, the service only
answers to a loopback Host: a page on another site cannot reach it through DNS rebinding.

The operator's pages (``/ui``) need the key too: a browser cannot add a header to a link, so there it
may come as HTTP Basic authentication's password (the browser asks for it once; it never appears in a
URL, and so in no log).

A write is accepted as uncompressed ``application/json`` only, and never from a page of another origin:
a browser sends a ``text/plain`` POST across sites without asking (no CORS preflight), so either check
alone would let any open web page write into an actuator's history.

Slow clients hold only themselves. A body must arrive within ``body_timeout_s``, and after
``body_grace_s`` at no less than ``min_body_rate_bps`` on average: a client trickling a byte a second is
cut off with a 408 within seconds. What bounds memory is the bytes of all bodies in flight
(``max_upload_bytes``), not their number, so a trickle holding a few bytes never shuts out a body that
is ready. A refusal sent before the body is read is followed by reading (draining) the rest of it,
within bounds: a client still sending then reads the status instead of a connection reset.
"""

from __future__ import annotations

import asyncio
import base64
import binascii
import hmac
import json
import math
import time
from dataclasses import dataclass
from typing import Any

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from ema.service.config import LOOPBACK_NAMES

WRITES = frozenset({"POST", "PUT", "PATCH", "DELETE"})
PAGES = "/ui"
DRAIN_S = 5.0  # the longest a refused body is read on, so that its client sees the status
Refusal = tuple[int, bytes, list[tuple[bytes, bytes]]]  # status, body, extra headers


class BodyTooLargeError(Exception):
    pass


class BodyTooSlowError(Exception):
    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


class UploadsFullError(Exception):
    def __init__(self, retry_after_s: int) -> None:
        super().__init__()
        self.retry_after_s = retry_after_s


@dataclass(frozen=True)
class BodyLimits:
    """The body limits of the service's ``Settings`` (where each is defined, with its default and bound)."""

    max_body_bytes: int
    body_timeout_s: float
    body_grace_s: float
    min_body_rate_bps: float
    max_upload_bytes: int

    @classmethod
    def of(cls, settings: Any) -> BodyLimits:
        """The limits ``settings`` (an ``ema.service.config.Settings``) sets."""
        return cls(**{name: getattr(settings, name) for name in cls.__dataclass_fields__})


def error_body(loc: list[str], message: str, kind: str) -> bytes:
    return json.dumps({"detail": [{"loc": loc, "msg": message, "type": kind}]}).encode()


async def answer(send: Send, status: int, body: bytes, extra: list[tuple[bytes, bytes]] | None = None) -> None:
    headers = [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode()), *(extra or [])]
    await send({"type": "http.response.start", "status": status, "headers": headers})
    await send({"type": "http.response.body", "body": body})


def _host_name(host: bytes) -> str:
    text = host.decode("latin-1")
    return text[1 : text.index("]")] if text.startswith("[") and "]" in text else text.rsplit(":", 1)[0]


def _origin_host(origin: bytes) -> str:
    """``http://host:port`` -> ``host:port`` (the form of a Host header); "" for an opaque origin ("null")."""
    text = origin.decode("latin-1").strip().lower()
    return text.split("://", 1)[1].rstrip("/") if "://" in text else ""


class Body:
    """One request's body as it arrives: its size, pace and share of the bytes in flight checked at each chunk,
    and whatever the app left unread drained once it has answered."""

    def __init__(self, guard: Guard, receive: Receive, done: bool) -> None:
        self.guard, self.receive, self.limits = guard, receive, guard.limits
        self.started = time.monotonic()
        self.received = 0
        self.held = 0  # bytes counted against max_upload_bytes: the declared length, else what arrived
        self.done = done

    def reserve(self, declared: int) -> bool:
        """Count a declared length against the bytes in flight; False where it finds no room."""
        if self.guard.in_flight + declared > self.limits.max_upload_bytes:
            return False
        self.guard.in_flight += declared
        self.held = declared
        return True

    def release(self) -> None:
        self.guard.in_flight -= self.held
        self.held = 0

    def _wait_s(self) -> float:
        """How long the next chunk may take: the total timeout, and the time at which the pace so far would fall
        under the minimum rate (never before the grace period ends)."""
        elapsed = time.monotonic() - self.started
        total = self.limits.body_timeout_s - elapsed
        paced = max(self.limits.body_grace_s, self.received / self.limits.min_body_rate_bps) - elapsed
        return max(min(total, paced), 0.0)

    async def __call__(self) -> Message:
        if self.done:
            return await self.receive()
        try:
            message = await asyncio.wait_for(self.receive(), self._wait_s())
        except TimeoutError:
            raise BodyTooSlowError(self._slow_reason()) from None
        chunk = len(message.get("body", b""))
        self.received += chunk
        self.done = not message.get("more_body", False) or message["type"] != "http.request"
        if self.received > self.limits.max_body_bytes:
            raise BodyTooLargeError
        if self.received > self.held:
            grown = self.received - self.held
            if self.guard.in_flight + grown > self.limits.max_upload_bytes:
                raise UploadsFullError(self.guard.retry_after_s())
            self.guard.in_flight += grown
            self.held += grown
        return message

    def _slow_reason(self) -> str:
        elapsed = time.monotonic() - self.started
        if elapsed >= self.limits.body_timeout_s - 1e-3:
            return f"did not arrive within {self.limits.body_timeout_s:g} s (EMA_BODY_TIMEOUT_S)"
        return (
            f"arrived at {self.received / max(elapsed, 1e-9):.0f} B/s, under the {self.limits.min_body_rate_bps:g} B/s "
            f"a body must keep after its first {self.limits.body_grace_s:g} s (EMA_MIN_BODY_RATE_BPS)"
        )

    async def drain(self) -> None:
        """Read what the client is still sending, within ``DRAIN_S`` and twice the body limit, and drop it: only
        then is an early answer sent, which the client reads once it has sent its body."""
        deadline, budget = time.monotonic() + DRAIN_S, 2 * self.limits.max_body_bytes
        while not self.done and budget > 0:
            try:
                message = await asyncio.wait_for(self.receive(), max(deadline - time.monotonic(), 0.0))
            except TimeoutError:
                return
            if message["type"] != "http.request":
                return
            budget -= len(message.get("body", b""))
            self.done = not message.get("more_body", False)


class Guard:
    def __init__(
        self, app: ASGIApp, key: bytes | None, prefix: str, limits: BodyLimits, allowed_origins: tuple[str, ...] = ()
    ) -> None:
        self.app = app
        self.key = key
        self.prefix = prefix
        self.limits = limits
        self.allowed_origins = {_origin_host(o.encode()) for o in allowed_origins}
        self.in_flight = 0  # bytes of bodies being received (the event loop's own counter: no lock)

    def retry_after_s(self) -> int:
        """When room for a body is likely: the bodies in flight drain at the minimum rate at worst."""
        return max(1, min(60, math.ceil(self.limits.body_grace_s)))

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = dict(scope.get("headers", []))
        declared_text = headers.get(b"content-length", b"")
        declared = int(declared_text) if declared_text.isdigit() else 0
        body = Body(self, receive, done=declared == 0 and b"transfer-encoding" not in headers)
        try:
            await self._guarded(scope, headers, body, send, declared)
        finally:
            body.release()

    async def _guarded(self, scope: Scope, headers: dict[bytes, bytes], body: Body, send: Send, declared: int) -> None:
        refusal = self._refusal(scope["path"], scope["method"], headers)
        if refusal is None and declared <= self.limits.max_body_bytes and not body.reserve(declared):
            retry = self.retry_after_s()
            refusal = (503, self._full(retry), [(b"retry-after", str(retry).encode())])
        if refusal is not None:
            page = scope["path"] == PAGES or scope["path"].startswith(PAGES + "/")
            challenge = [(b"www-authenticate", b'Basic realm="ema"')] if refusal[0] == 401 and page else []
            await body.drain()
            await answer(send, refusal[0], refusal[1], [*challenge, *refusal[2]])
            return

        async def drained_first(message: Message) -> None:
            """An answer given before the body was read waits for the body's end (the server stops reading once
            an answer is complete, and a client still sending would see its connection reset)."""
            if message["type"] == "http.response.start":
                await body.drain()
            await send(message)

        try:
            await self.app(scope, body, drained_first)
        except BodyTooLargeError:
            await body.drain()
            await answer(send, 413, self._too_large())
        except BodyTooSlowError as exc:
            await answer(send, 408, error_body(["body"], exc.reason, "timeout"))  # a slow client is not waited for
        except UploadsFullError as exc:
            await body.drain()
            await answer(send, 503, self._full(exc.retry_after_s), [(b"retry-after", str(exc.retry_after_s).encode())])

    def _full(self, retry_after_s: int) -> bytes:
        held = f"bodies in flight hold {self.in_flight} bytes (EMA_MAX_UPLOAD_BYTES {self.limits.max_upload_bytes})"
        return json.dumps({"detail": f"busy: {held}; retry after {retry_after_s} s"}).encode()

    def _too_large(self) -> bytes:
        return error_body(["body"], f"exceeds this service's limit of {self.limits.max_body_bytes} bytes", "too_large")

    def _refusal(self, path: str, method: str, headers: dict[bytes, bytes]) -> Refusal | None:
        protected = any(path == root or path.startswith(root + "/") for root in (self.prefix, PAGES))
        host = headers.get(b"host", b"localhost")
        if self.key is None and _host_name(host) not in LOOPBACK_NAMES:
            return (
                400,
                error_body(["header", "host"], "this service answers loopback hosts only (no key set)", "host"),
                [],
            )
        if protected and self.key is not None and not self._keyed(headers):
            message = "missing or wrong X-API-Key (or the pages' password)"
            return 401, error_body(["header", "x-api-key"], message, "unauthorized"), []
        if protected and method in WRITES:
            refused = self._write_refusal(method, headers, host)
            if refused is not None:
                return (*refused, [])
        declared = headers.get(b"content-length")
        if declared is not None and declared.isdigit() and int(declared) > self.limits.max_body_bytes:
            return 413, self._too_large(), []
        return None

    def _keyed(self, headers: dict[bytes, bytes]) -> bool:
        """The key as X-API-Key, or as the password of HTTP Basic authentication (what a browser sends)."""
        assert self.key is not None
        given = headers.get(b"x-api-key", b"")
        scheme, _, encoded = headers.get(b"authorization", b"").partition(b" ")
        if scheme.lower() == b"basic":
            try:
                given = base64.b64decode(encoded, validate=True).partition(b":")[2]
            except (binascii.Error, ValueError):
                return False
        return hmac.compare_digest(given, self.key)

    def _write_refusal(self, method: str, headers: dict[bytes, bytes], host: bytes) -> tuple[int, bytes] | None:
        """403 for a write from a page of another origin; 415 for a body that is not plain JSON (a DELETE may
        have none)."""
        origin = headers.get(b"origin")
        if origin is not None:
            source = _origin_host(origin)
            if source != host.decode("latin-1").lower() and source not in self.allowed_origins:
                message = f"a write from the page of {origin.decode('latin-1')!r} (EMA_ALLOWED_ORIGINS lists others)"
                return 403, error_body(["header", "origin"], message, "forbidden")
        encoding = headers.get(b"content-encoding", b"identity").strip().lower()
        if encoding not in (b"", b"identity"):
            shown = encoding.decode("latin-1")
            return 415, error_body(
                ["header", "content-encoding"], f"is {shown!r}; send the body uncompressed", "unsupported_media_type"
            )
        kind = headers.get(b"content-type", b"").split(b";")[0].strip().lower()
        bodiless = method == "DELETE" and headers.get(b"content-length", b"0") == b"0" and kind == b""
        if kind != b"application/json" and not bodiless:
            shown = kind.decode("latin-1") or "none"
            return 415, error_body(
                ["header", "content-type"], f"is {shown!r}; a body must be application/json", "unsupported_media_type"
            )
        return None
