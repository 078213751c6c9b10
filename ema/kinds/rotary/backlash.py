"""The backlash channel: the dead band read from the motor angle against the elevator angle.

While the motor drives the elevator, d = θ_m/n − θ_u sits at c + (B/2)·sgn(ω): the motor pushes
on one face of the dead band, then on the other. Solving that step (a level per window, since
θ_m is only known up to where the shaft started in the band) reads the total width B, over the
samples where the elevator moves with the motor (after a reversal the motor first crosses the
band, d between the faces, and a wide band read over those samples comes out narrow). The noise
copies, simulated with the nominal band, give the reading's own spread and bias: a band of any
size is named when it stands ``NAME_Z`` of those stds from them, and its extra width is the
difference. The copies are replicas of the base model as estimated, without what the torque channel
adopts; where it does not reproduce the window (an equation error R times the copies'), they
understate every spread about R-fold, and the spread is widened by R: a torque constant at half its
value, or a hinge-moment bias of 500 N·m, moves the motor differently enough to shift the reading,
and is not a worn dead band, even once the torque channel has named it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ema.calibration.limits import NAME_Z
from ema.estimate.least_squares import coefficients
from ema.kinds.rotary.equations import Equations
from ema.kinds.rotary.selection import floor_rms, residual_rms

MIN_ENGAGED = 50  # samples pushing on each face
# The reading's floor: the dead band read kinematically moves with dynamics the model gets wrong, and the copies
# share the model's dynamics, so their spread alone understates it (docs/calibration.md): a band is named wider
# only beyond NAME_Z of this share of its nominal width.
RESOLUTION = 0.05


@dataclass(frozen=True)
class BacklashReading:
    width_rad: float  # B read from the measured windows
    null_mean_rad: float  # read from the copies (nominal band)
    null_std_rad: float
    mismatch: float = 1.0  # equation error over the copies' (≥ 1): how far the copies are from the window

    @property
    def extra_rad(self) -> float:
        return self.width_rad - self.null_mean_rad

    @property
    def z(self) -> float:
        spread = max(self.null_std_rad * max(self.mismatch, 1.0), RESOLUTION * abs(self.null_mean_rad), 1e-12)
        return self.extra_rad / spread

    @property
    def significant(self) -> bool:
        # One-sided: wear widens a dead band. A reading well below the nominal one means the step
        # model does not hold (a band so wide the motor seldom pushes on both faces), not a tight gear.
        return self.z >= NAME_Z


def width_rad(e: Equations) -> float:
    """Least squares of d on a level per window and sgn(ω)/2, over the samples where the motor drives
    the elevator (while it crosses the band d is between the faces): the total dead-band width."""
    rows = e.variables["engaged"] > 0
    direction = e.variables["direction"][rows]
    if min(np.sum(direction > 0), np.sum(direction < 0)) < MIN_ENGAGED:
        rows = np.ones(e.m, dtype=bool)  # too few pushes on one face to read it: all sliding samples
    levels = (e.window[rows, None] == np.unique(e.window)[None, :]).astype(float)
    design = np.concatenate([levels, 0.5 * e.variables["direction"][rows, None]], axis=1)
    return float(coefficients(design, e.kinematic[rows])[-1])


def read_backlash(measured: Equations, copies: Sequence[Equations]) -> BacklashReading:
    """The dead band against the copies', their spread widened by how far their model is from the window."""
    null = [width_rad(c) for c in copies]
    mismatch = residual_rms(measured, []) / max(floor_rms(copies), 1e-300)
    return BacklashReading(width_rad(measured), float(np.mean(null)), float(np.std(null, ddof=1)), mismatch)
