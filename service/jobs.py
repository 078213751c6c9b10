"""The bounded job queue: CPU-bound pipelines run off the event loop, one at a time on all cores.

One pipeline already uses every core (Numba's prange, torch's intra-op threads), so running two
side by side would only slow both. Up to ``max_queue`` requests wait their turn; one more, or
one that waits longer than ``queue_timeout_s``, gets 503 with Retry-After instead of a hang.
"""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any, TypeVar

T = TypeVar("T")


class OverloadedError(Exception):
    """No room now; ``retry_after_s`` is when to try again."""

    def __init__(self, reason: str, retry_after_s: int) -> None:
        super().__init__(reason)
        self.retry_after_s = retry_after_s


class JobRunner:
    def __init__(self, max_queue: int, queue_timeout_s: float, initializer: Callable[[], None] | None = None) -> None:
        self.max_queue = max_queue
        self.queue_timeout_s = queue_timeout_s
        self._executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="ema-pipeline", initializer=initializer)
        self._slot = asyncio.Semaphore(1)
        self.running = 0
        self.queued = 0
        self._mean_job_s = 2.0  # until measured

    def retry_after_s(self) -> int:
        return max(1, math.ceil(self._mean_job_s * (self.queued + self.running)))

    async def run(self, job: Callable[..., T], *args: Any) -> T:
        """Run ``job(*args)`` in the worker thread once the slot is free; raise OverloadedError if it cannot be soon."""
        if self.running and self.queued >= self.max_queue:
            raise OverloadedError(f"queue full ({self.queued} waiting)", self.retry_after_s())
        self.queued += 1
        try:
            await asyncio.wait_for(self._slot.acquire(), timeout=self.queue_timeout_s)
        except TimeoutError:
            raise OverloadedError(f"not started within {self.queue_timeout_s:g} s", self.retry_after_s()) from None
        finally:
            self.queued -= 1
        self.running += 1
        started = time.perf_counter()
        future = asyncio.get_running_loop().run_in_executor(self._executor, job, *args)
        # The slot is freed when the job ends, not when its request goes away: a client that hangs up
        # cannot stop a thread, and the next job must not start beside it.
        future.add_done_callback(lambda _: self._finished(started))
        return await asyncio.shield(future)

    def _finished(self, started: float) -> None:
        self._mean_job_s = 0.7 * self._mean_job_s + 0.3 * (time.perf_counter() - started)
        self.running -= 1
        self._slot.release()

    def shutdown(self) -> None:
        self._executor.shutdown(wait=True, cancel_futures=True)
