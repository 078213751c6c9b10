"""A bounded share of the machine for work that is not the estimates' (the operator's view).

``Share(fraction)`` admits one piece of work at a time and, after a piece that took ``t`` seconds, lets the next one
start only ``t · (1 / fraction − 1)`` seconds later: whatever the number of viewers and however fast they reload,
the view uses at most ``fraction`` of one core, and the estimates keep the rest. A viewer waits its turn on the
event loop, which costs nothing.
"""

from __future__ import annotations

import asyncio
import time
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager


class Share:
    def __init__(self, fraction: float) -> None:
        if not 0 < fraction <= 1:
            raise ValueError(f"a share is a fraction in (0, 1], not {fraction}")
        self.fraction = fraction
        self._lock = asyncio.Lock()
        self._free_at = 0.0

    @asynccontextmanager
    async def turn(self) -> AsyncIterator[None]:
        """Wait for this share's turn, then hold it while the work runs."""
        async with self._lock:
            wait = self._free_at - time.monotonic()
            if wait > 0:
                await asyncio.sleep(wait)
            started = time.monotonic()
            try:
                yield
            finally:
                spent = time.monotonic() - started
                self._free_at = time.monotonic() + spent * (1 / self.fraction - 1)
