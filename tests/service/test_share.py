"""The view's share of the machine: a turn's work, then a pause that keeps its share, however many ask."""

from __future__ import annotations

import asyncio
import time

import pytest

from ema.service.share import Share


def _busy(seconds: float) -> None:
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        pass


async def _viewers(share: Share, viewers: int, turns: int, work_s: float) -> float:
    async def viewer() -> None:
        for _ in range(turns):
            async with share.turn():
                _busy(work_s)

    started = time.perf_counter()
    await asyncio.gather(*(viewer() for _ in range(viewers)))
    return time.perf_counter() - started


@pytest.mark.parametrize("fraction", [0.25, 0.5])
def test_many_viewers_take_no_more_than_the_share(fraction):
    """5 viewers × 4 turns of 10 ms: 0.2 s of work, so at least 0.2 s / fraction less the last pause."""
    work_s, turns = 0.2, 20
    elapsed = asyncio.run(_viewers(Share(fraction), viewers=5, turns=4, work_s=work_s / turns))
    least = work_s / fraction - (work_s / turns) * (1 / fraction - 1)
    assert elapsed >= least * 0.95
    assert elapsed <= least * 3  # waiting is the share's, not more


def test_a_whole_share_never_waits():
    elapsed = asyncio.run(_viewers(Share(1.0), viewers=3, turns=3, work_s=0.01))
    assert elapsed < 0.09 * 3


@pytest.mark.parametrize("fraction", [0.0, -0.5, 1.5])
def test_a_share_is_a_fraction(fraction):
    with pytest.raises(ValueError, match="fraction"):
        Share(fraction)
