"""Each stage's seconds, as ``ema-estimate/1``'s ``timings_s`` reports them."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator

from ema.estimate.documents import Timings


class Stopwatch:
    """Each stage's seconds, announced to ``on_stage`` as it starts (which may raise to stop the job there)."""

    def __init__(self, on_stage: Callable[[str], None] | None) -> None:
        self.on_stage = on_stage or (lambda _: None)
        self.seconds: dict[str, float] = {}

    @contextlib.contextmanager
    def __call__(self, name: str, announcement: str) -> Iterator[None]:
        self.on_stage(announcement)
        started = time.perf_counter()
        yield
        self.seconds[name] = time.perf_counter() - started

    def timings(self) -> Timings:
        return Timings(**self.seconds, total=sum(self.seconds.values()))
