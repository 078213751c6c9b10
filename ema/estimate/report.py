"""What every kind's report says the same way: "% of range" and "weakly determined", defined here, once, against the
actuator's healthy range (the result, the CLI's table and the benchmarks read them), and the learn stage as an answer
reports it. Each kind writes its own ``ema-estimate/1`` from its stages' outputs (the rotary's:
``ema.kinds.rotary.report``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ema.estimate.config import PipelineConfig
from ema.estimate.documents import LearnedInfo
from ema.model.params import HealthRanges

if TYPE_CHECKING:  # SciPy's optimizers: a window read without a network (quasi-static) never loads it
    from ema.estimate.learn.network import LearnedNetwork

# ±2 std wider than this share of the healthy range: the window is said to determine the parameter weakly.
WEAK_SHARE_OF_RANGE = 0.10


def share_of_range(name: str, amount: float, ranges: HealthRanges) -> float:
    """``amount`` (in the parameter's unit) as a share of the width of its healthy range."""
    low, high = ranges.of(name)
    return amount / (high - low)


def weakly_determined(name: str, std: float, ranges: HealthRanges) -> bool:
    """±2 std wider than ``WEAK_SHARE_OF_RANGE`` of ``name``'s healthy range."""
    return share_of_range(name, 2 * std, ranges) > WEAK_SHARE_OF_RANGE


def learned_info(network: LearnedNetwork, config: PipelineConfig) -> LearnedInfo:
    """What the learn stage did as an answer reports it: ``network``, the first member's."""
    return LearnedInfo(
        epochs=network.epochs,
        stop_reason=network.stop_reason,
        val_mse=network.val_mse,
        test_mse=network.test_mse,
        members=config.members,
        hidden_units=config.hidden_units,
    )
