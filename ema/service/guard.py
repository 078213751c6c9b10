"""What is checked before a request's body is read: its host, its key, its origin, its type, its declared
size; and while it is read, its size and its pace.

A pure ASGI middleware, so that a wrong key gets its 401 (and an oversized body its 413) at once,
from the headers alone, with nothing parsed on the event loop. The key is compared as bytes in
constant time (a non-ASCII header is simply wrong, not an error). Without a key, the service only
answers to a loopback Host: a page on another site cannot reach it through DNS rebinding.

The operator's pages (``/ui``) need the key too: a browser cannot add a header to a link, so there it
may come as HTTP Basic authentication's password (the browser asks for it once; it never appears in a
URL, and so in no log).

A write is accepted as ``application/json`` only, and never from a page of another origin: a browser
sends a ``text/plain`` POST across sites without asking (no CORS preflight), so either check alone
would let any open web page write into an actuator's history. A body must arrive within
``body_timeout_s``: a client trickling a byte a second holds a connection, never the service.
"""

from __future__ import annotations

import asyncio
import base64
import binascii
import hmac
import json
import time

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from ema.service.config import LOOPBACK_NAMES

WRITES = frozenset({"POST", "PUT", "PATCH", "DELETE"})
PAGES = "/ui"


class BodyTooLargeError(Exception):
    pass


class BodyTooSlowError(Exception):
    pass


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


class Guard:
    def __init__(
        self,
        app: ASGIApp,
        key: bytes | None,
        prefix: str,
        max_body_bytes: int,
        body_timeout_s: float = 60.0,
        allowed_origins: tuple[str, ...] = (),
    ) -> None:
        self.app = app
        self.key = key
        self.prefix = prefix
        self.max_body_bytes = max_body_bytes
        self.body_timeout_s = body_timeout_s
        self.allowed_origins = {_origin_host(o.encode()) for o in allowed_origins}

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = dict(scope.get("headers", []))
        refusal = self._refusal(scope["path"], scope["method"], headers)
        if refusal is not None:
            page = scope["path"] == PAGES or scope["path"].startswith(PAGES + "/")
            challenge = [(b"www-authenticate", b'Basic realm="ema"')] if refusal[0] == 401 and page else None
            await answer(send, *refusal, challenge)
            return
        received, deadline = 0, time.monotonic() + self.body_timeout_s

        async def limited() -> Message:
            nonlocal received
            try:
                message = await asyncio.wait_for(receive(), max(deadline - time.monotonic(), 0.0))
            except TimeoutError:
                raise BodyTooSlowError from None
            received += len(message.get("body", b""))
            if received > self.max_body_bytes:
                raise BodyTooLargeError
            return message

        try:
            await self.app(scope, limited, send)
        except BodyTooLargeError:
            await answer(send, 413, self._too_large())
        except BodyTooSlowError:
            message = f"did not arrive within {self.body_timeout_s:g} s (EMA_BODY_TIMEOUT_S)"
            await answer(send, 408, error_body(["body"], message, "timeout"))

    def _too_large(self) -> bytes:
        return error_body(["body"], f"exceeds this service's limit of {self.max_body_bytes} bytes", "too_large")

    def _refusal(self, path: str, method: str, headers: dict[bytes, bytes]) -> tuple[int, bytes] | None:
        protected = any(path == root or path.startswith(root + "/") for root in (self.prefix, PAGES))
        host = headers.get(b"host", b"localhost")
        if self.key is None and _host_name(host) not in LOOPBACK_NAMES:
            return 400, error_body(["header", "host"], "this service answers loopback hosts only (no key set)", "host")
        if protected and self.key is not None and not self._keyed(headers):
            return 401, error_body(
                ["header", "x-api-key"], "missing or wrong X-API-Key (or the pages' password)", "unauthorized"
            )
        if protected and method in WRITES:
            refused = self._write_refusal(headers, host)
            if refused is not None:
                return refused
        declared = headers.get(b"content-length")
        if declared is not None and declared.isdigit() and int(declared) > self.max_body_bytes:
            return 413, self._too_large()
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

    def _write_refusal(self, headers: dict[bytes, bytes], host: bytes) -> tuple[int, bytes] | None:
        """403 for a write from a page of another origin, 415 for a body that does not say it is JSON."""
        origin = headers.get(b"origin")
        if origin is not None:
            source = _origin_host(origin)
            if source != host.decode("latin-1").lower() and source not in self.allowed_origins:
                message = f"a write from the page of {origin.decode('latin-1')!r} (EMA_ALLOWED_ORIGINS lists others)"
                return 403, error_body(["header", "origin"], message, "forbidden")
        kind = headers.get(b"content-type", b"").split(b";")[0].strip().lower()
        if kind != b"application/json":
            shown = kind.decode("latin-1") or "none"
            return 415, error_body(
                ["header", "content-type"], f"is {shown!r}; a body must be application/json", "unsupported_media_type"
            )
        return None
