"""Admission and the job queue: one pipeline at a time, at most ``max_queue`` waiting, whatever the timing.

One pipeline already uses the whole thread budget (the simulator's pool; the network's BLAS on one thread),
so running two side by side would only slow both (with the Ray backend, ``slots`` run at once on
the cluster). A request is *admitted* once its body is read and parsed: a slow upload holds its
connection, not a place in the queue. At most ``slots`` + ``max_queue`` hold a place; a request that
arrives when they are all taken gets 503 at once, before its body is read, with a Retry-After from
measured job times (what bodies in flight may hold is ``service.guard``'s). Bodies are parsed one
at a time on a thread of their own, so that the event loop (and /healthz) keeps its share of the
interpreter. A waiting request whose client hangs up leaves the queue;
a running one is told to stop at its next stage (``Cancelled``), and its slot is freed when its
thread returns, not when the client leaves: the next job never starts beside it.
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import threading
import time
from collections.abc import Awaitable, Callable, Hashable, Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import Any, TypeVar

T = TypeVar("T")
POLL_S = 0.2  # how often a waiting or running request looks at its client


class OverloadedError(Exception):
    """No room now; ``retry_after_s`` is when to try again."""

    def __init__(self, reason: str, retry_after_s: int) -> None:
        super().__init__(reason)
        self.retry_after_s = retry_after_s


class CancelledError(Exception):
    """The client went away; the job stopped at a stage boundary."""


class Ticket:
    """A place in the service: taken at arrival, given back when the request ends, however it ends."""

    def __init__(self, runner: JobRunner) -> None:
        self.runner = runner
        self.cancel = threading.Event()

    def __enter__(self) -> Ticket:
        return self

    def __exit__(self, *_: object) -> None:
        self.runner.admitted -= 1
        self.runner.last_busy = time.monotonic()


class Shared:
    """One computation that several requests wait for: the first to ask runs it, the others wait for its end
    (each still holding its place in the queue). It is stopped only once every one of them has left."""

    def __init__(self) -> None:
        self.done = asyncio.Event()
        self.waiters = 0

    async def wait(self, gone: Callable[[], Awaitable[bool]]) -> None:
        """Until the computation ends; CancelledError where this request's client leaves first."""
        self.waiters += 1
        try:
            while not self.done.is_set():
                with contextlib.suppress(TimeoutError):
                    await asyncio.wait_for(self.done.wait(), POLL_S)
                if not self.done.is_set() and await gone():
                    raise CancelledError("the client left while its window was being estimated for another request")
        finally:
            self.waiters -= 1

    def gone(self, leader: Callable[[], Awaitable[bool]]) -> Callable[[], Awaitable[bool]]:
        """The computation's own ``gone``: its first client has left and nobody waits for it any more."""

        async def everyone() -> bool:
            return self.waiters == 0 and await leader()

        return everyone


class Sharing:
    """The computations under way, by key (an actuator's window): a second request for one waits for it."""

    def __init__(self) -> None:
        self._running: dict[Hashable, Shared] = {}

    def running(self, key: Hashable) -> Shared | None:
        return self._running.get(key)

    @contextlib.contextmanager
    def lead(self, key: Hashable) -> Iterator[Shared]:
        """This request computes ``key``; those that ask meanwhile wait for it, and are told when it ends."""
        shared = self._running[key] = Shared()
        try:
            yield shared
        finally:
            del self._running[key]
            shared.done.set()


class JobRunner:
    """``slots`` jobs at a time: one on this computer (it uses every core), more when Ray runs them elsewhere."""

    def __init__(self, max_queue: int, queue_timeout_s: float, slots: int = 1) -> None:
        self.max_queue = max_queue
        self.queue_timeout_s = queue_timeout_s
        self.slots = slots
        self._executor = ThreadPoolExecutor(max_workers=slots, thread_name_prefix="ema-pipeline")
        self.parser = ThreadPoolExecutor(max_workers=1, thread_name_prefix="ema-parse")
        self._slot = asyncio.Semaphore(slots)
        self.admitted = 0  # running + waiting
        self.running = 0
        self.last_busy = -math.inf  # time.monotonic() when the last request gave its place back
        self.sharing = Sharing()  # on the event loop only
        self._mean_job_s = 1.0  # until measured

    @property
    def queued(self) -> int:
        return self.admitted - self.running

    def quiet_for(self) -> float:
        """Seconds since the last request ended, with none running or waiting (0 while one does)."""
        return 0.0 if self.admitted else time.monotonic() - self.last_busy

    def retry_after_s(self) -> int:
        return max(1, math.ceil(self._mean_job_s * max(self.admitted, 1) / self.slots))

    def _full(self) -> None:
        if self.admitted >= self.slots + self.max_queue:
            places = self.slots + self.max_queue
            raise OverloadedError(
                f"all {places} places are taken: {self.running} job(s) running, {self.queued} waiting for a slot or "
                f"storing an answer (EMA_MAX_QUEUE {self.max_queue})",
                self.retry_after_s(),
            )

    def admit(self) -> Ticket:
        """A place, or OverloadedError at once when slots + max_queue requests hold one."""
        self._full()
        self.admitted += 1
        return Ticket(self)

    def receiving(self) -> None:
        """Before a body is read: OverloadedError at once if the queue is full already (the body would only wait
        to be refused)."""
        self._full()

    async def _acquire(self, gone: Callable[[], Awaitable[bool]]) -> None:
        deadline = time.monotonic() + self.queue_timeout_s
        while True:
            try:
                await asyncio.wait_for(self._slot.acquire(), timeout=min(POLL_S, max(deadline - time.monotonic(), 0)))
                return
            except TimeoutError:
                if await gone():
                    raise CancelledError("the client left while waiting") from None
                if time.monotonic() >= deadline:
                    raise OverloadedError(
                        f"not started within {self.queue_timeout_s:g} s", self.retry_after_s()
                    ) from None

    async def run(self, ticket: Ticket, gone: Callable[[], Awaitable[bool]], job: Callable[..., T], *args: Any) -> T:
        """Run ``job(*args)`` in the worker thread once the slot is free; ``gone`` says the client left."""
        await self._acquire(gone)
        self.running += 1
        started = time.perf_counter()
        future = asyncio.get_running_loop().run_in_executor(self._executor, job, *args)
        future.add_done_callback(lambda _: self._finished(started))
        while not future.done():
            await asyncio.wait([future], timeout=POLL_S)
            if not future.done() and await gone():
                ticket.cancel.set()  # the job stops at its next stage; the slot frees when it does
        return future.result()

    def _finished(self, started: float) -> None:
        self._mean_job_s = 0.7 * self._mean_job_s + 0.3 * (time.perf_counter() - started)
        self.running -= 1
        self._slot.release()

    def shutdown(self) -> None:
        self.parser.shutdown(wait=True, cancel_futures=True)
        self._executor.shutdown(wait=True, cancel_futures=True)
