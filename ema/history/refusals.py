"""What the history refuses: another window under a stored key, a withdrawn window posted again, and storage that
cannot be used."""

from __future__ import annotations

from ema.prognosis.documents import Stored, Withdrawal


class ConflictError(Exception):
    """A window posted under a stored (actuator_id, window_id) with other content: another window."""

    def __init__(self, stored: Stored, digest: str) -> None:
        super().__init__(
            f"window_id {stored.window_id!r} of actuator {stored.actuator_id!r} was stored at {stored.stored_at} "
            f"from other content (SHA-256 {str(stored.window.content_sha256)[:12]}…, this body's {digest[:12]}…): "
            "give a new window its own window_id"
        )
        self.stored = stored


class WithdrawnError(Exception):
    """A window posted under a key an operator withdrew: it stays withdrawn (a retry or a replay would otherwise
    put it back in the trend)."""

    def __init__(self, withdrawal: Withdrawal) -> None:
        super().__init__(
            f"window_id {withdrawal.window_id!r} of actuator {withdrawal.actuator_id!r} was withdrawn at "
            f"{withdrawal.withdrawn_at} ({withdrawal.reason}): it stays out of the history; a new reading of the "
            "actuator is posted under a window_id of its own"
        )
        self.withdrawal = withdrawal


class VersionContentionError(Exception):
    """Writers of one actuator's documents kept taking the version this one asked for: put it again."""

    def __init__(self, actuator_id: str, attempts: int) -> None:
        super().__init__(
            f"other writers took actuator {actuator_id!r}'s next document version {attempts} times running: "
            "put the document again"
        )


class StorageError(Exception):
    """The history cannot be used; ``location`` names it (a file, or a database address without its password)."""

    def __init__(self, location: object, reason: str) -> None:
        super().__init__(f"{location}: {reason}")
        self.location = location
        self.path = location
        self.reason = reason
