"""What is checked before a request's body is read: its host, its key, its declared size.

A pure ASGI middleware, so that a wrong key gets its 401 (and an oversized body its 413) at once,
from the headers alone, with nothing parsed on the event loop: a 48 MB body with a wrong key
used to hold the loop (and /healthz) for 9 s. The key is compared as bytes in constant time (a
non-ASCII header is simply wrong, not an error). Without a key, the service only answers to a
loopback Host: a page on another site cannot reach it through DNS rebinding.
"""

from __future__ import annotations

import hmac
import json

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from service.config import LOOPBACK_NAMES


class BodyTooLargeError(Exception):
    pass


def error_body(loc: list[str], message: str, kind: str) -> bytes:
    return json.dumps({"detail": [{"loc": loc, "msg": message, "type": kind}]}).encode()


async def answer(send: Send, status: int, body: bytes) -> None:
    headers = [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())]
    await send({"type": "http.response.start", "status": status, "headers": headers})
    await send({"type": "http.response.body", "body": body})


def _host_name(host: bytes) -> str:
    text = host.decode("latin-1")
    return text[1 : text.index("]")] if text.startswith("[") and "]" in text else text.rsplit(":", 1)[0]


class Guard:
    def __init__(self, app: ASGIApp, key: bytes | None, prefix: str, max_body_bytes: int) -> None:
        self.app = app
        self.key = key
        self.prefix = prefix
        self.max_body_bytes = max_body_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = dict(scope.get("headers", []))
        refusal = self._refusal(scope["path"], headers)
        if refusal is not None:
            await answer(send, *refusal)
            return
        received = 0

        async def limited() -> Message:
            nonlocal received
            message = await receive()
            received += len(message.get("body", b""))
            if received > self.max_body_bytes:
                raise BodyTooLargeError
            return message

        try:
            await self.app(scope, limited, send)
        except BodyTooLargeError:
            await answer(send, 413, self._too_large())

    def _too_large(self) -> bytes:
        return error_body(["body"], f"exceeds this service's limit of {self.max_body_bytes} bytes", "too_large")

    def _refusal(self, path: str, headers: dict[bytes, bytes]) -> tuple[int, bytes] | None:
        protected = path == self.prefix or path.startswith(self.prefix + "/")
        if self.key is None and _host_name(headers.get(b"host", b"localhost")) not in LOOPBACK_NAMES:
            return 400, error_body(["header", "host"], "this service answers loopback hosts only (no key set)", "host")
        if protected and self.key is not None and not hmac.compare_digest(headers.get(b"x-api-key", b""), self.key):
            return 401, error_body(["header", "x-api-key"], "missing or wrong X-API-Key", "unauthorized")
        declared = headers.get(b"content-length")
        if declared is not None and declared.isdigit() and int(declared) > self.max_body_bytes:
            return 413, self._too_large()
        return None
