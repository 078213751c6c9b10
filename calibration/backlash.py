"""The backlash channel: the dead band read from the motor angle against the elevator angle.

While the motor drives the elevator, d = θ_m/n − θ_u sits at c + (B/2)·sgn(ω): the motor pushes
on one face of the dead band, then on the other. Fitting that step (a level per window, since
θ_m is only known up to where the shaft started in the band) reads the total width B. The noise
copies, simulated with the nominal band, give the reading's own spread and bias: a band of any
size is named when it stands ``MIN_Z`` of those stds from them, and its extra width is the
difference.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from calibration.equations import Equations
from calibration.selection import MIN_Z


@dataclass(frozen=True)
class BacklashReading:
    width_rad: float  # B read from the measured windows
    null_mean_rad: float  # read from the copies (nominal band)
    null_std_rad: float

    @property
    def extra_rad(self) -> float:
        return self.width_rad - self.null_mean_rad

    @property
    def z(self) -> float:
        return self.extra_rad / max(self.null_std_rad, 1e-12)

    @property
    def significant(self) -> bool:
        return abs(self.z) >= MIN_Z


def width_rad(e: Equations) -> float:
    """Least squares of d on a level per window and sgn(ω)/2: the total dead-band width."""
    levels = (e.window[:, None] == np.unique(e.window)[None, :]).astype(float)
    design = np.concatenate([levels, 0.5 * e.variables["direction"][:, None]], axis=1)
    return float(np.linalg.lstsq(design, e.kinematic, rcond=None)[0][-1])


def read_backlash(measured: Equations, copies: Sequence[Equations]) -> BacklashReading:
    null = [width_rad(c) for c in copies]
    return BacklashReading(width_rad(measured), float(np.mean(null)), float(np.std(null, ddof=1)))
