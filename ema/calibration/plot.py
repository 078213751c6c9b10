"""What ``ema calibrate --figure`` draws, whatever the kind: series of one quantity against one variable."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Series:
    label: str
    x: Sequence[float]
    y: Sequence[float]


@dataclass(frozen=True)
class ResidualPlot:
    title: str
    x_label: str
    y_label: str
    series: list[Series] = field(default_factory=list)
