"""What a kind reads a slow window by (``QuasiStaticReading``): how its logged motion becomes speed and load, how its
drive's current becomes torque, and what its document learned of its healthy runs. Each kind that reads slow
windows hands one to ``ema.estimate.quasistatic.slow_window`` (``ema.kinds``): the reading here knows no kind.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.quasistatic.stretches import Repeatability, Rest, TorqueReading
from ema.model.actuator import ActuatorDocument
from ema.model.window import Window


@dataclass(frozen=True)
class HealthyRuns:
    """What a document learned of its actuator's healthy runs (``ema calibrate``), that a window's FDJ is judged by."""

    eta_o_std: float  # of the nominal η_O (0: taken as exact)
    healthy_set_nm: float | None  # how far a healthy set's mean sits off the nominal (None: not learned)
    loads_n: list[float] | None  # the loads the runs were learned at
    fell: str  # what a fall of friction means on this kind
    rose: str  # and a rise


@dataclass(frozen=True)
class QuasiStaticReading:
    """What a kind reads a slow window by: its motion and load (``ema.estimate.quasistatic.stretches``), what its
    drive's current says of the torque (with a note where the window's current at rest departs from the
    document's), how its healthy runs scattered and what else they taught (None: nothing learned)."""

    motion: Callable[[Window, float], tuple[np.ndarray, np.ndarray]]
    torque: Callable[[ActuatorDocument, Rest | None], tuple[TorqueReading, Note | None]]
    spread: Callable[[ActuatorDocument], Repeatability] = lambda _: Repeatability()
    healthy: Callable[[ActuatorDocument], HealthyRuns | None] = lambda _: None
