"""What the history refuses: another window under a stored key, and storage that cannot be used."""

from __future__ import annotations

from ema.prognosis.documents import Stored


class ConflictError(Exception):
    """A window posted under a stored (actuator_id, window_id) with other content: another window."""

    def __init__(self, stored: Stored, digest: str) -> None:
        super().__init__(
            f"window_id {stored.window_id!r} of actuator {stored.actuator_id!r} was stored at {stored.stored_at} "
            f"from other content (SHA-256 {str(stored.window.content_sha256)[:12]}…, this body's {digest[:12]}…): "
            "give a new window its own window_id"
        )
        self.stored = stored


class StorageError(Exception):
    """The history cannot be used; ``location`` names it (a file, or a database address without its password)."""

    def __init__(self, location: object, reason: str) -> None:
        super().__init__(f"{location}: {reason}")
        self.location = location
        self.path = location
        self.reason = reason
