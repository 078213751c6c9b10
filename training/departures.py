"""What a window shows beyond the spec's model, read in turn, each on the window the last corrected: a
sensor off zero (``training.zero_offset``), the drive's k_T and J_M (``training.drive_constants``), the
viscous coefficient (``training.viscosity``).

A drive constant, seen before it is read, passes in part for an offset (a thesis window's current logged
1.5 % low read as 2.2 mN·m off zero, which left FDJ 11 % of range off once the scale was read too), so
where one is read the offset is read again on the corrected window (the logged current is s·I + i₀:
corrected, then zeroed). Where the window cannot tell γ from ΔJ, both are carried to the end: what is
read after them moves with the choice (a worn gust window read γ where J_M was 0.5 % light, then its
viscous coefficient 0.63x, FDJ 66 % of range off; read with ΔJ instead, 1.0x and right), so the stds
grow by ``UNDECIDED_SHARE`` of how far the two ends lie apart.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from sim.params import ActuatorParams
from sim.window import Window
from training.baseline import fit_friction
from training.drive_constants import UNDECIDED_SHARE, DriveConstants, read_drive_constants
from training.preprocess import as_read
from training.viscosity import Viscosity, read_viscosity
from training.zero_offset import ZeroOffset, read_zero_offset, zeroed


@dataclass(frozen=True)
class Departures:
    window: Window  # zeroed, its current on the spec's k_T
    offset: ZeroOffset = field(default_factory=ZeroOffset)
    drive: DriveConstants = field(default_factory=DriveConstants)
    viscosity: Viscosity = field(default_factory=Viscosity)

    @property
    def actuator(self) -> ActuatorParams:
        """What every reconstruction and fit of the window reads it with: the spec's, J_M and C as read."""
        return self.viscosity.actuator(self.drive.actuator)

    def answer(self) -> dict[str, float]:
        """FDJ and η_O of Eq. 5.1's fit of the window as read."""
        rate = self.window.sample_rate_hz
        fitted = fit_friction(as_read(self.window.signals, rate), rate, self.actuator)
        return {name: float(value) for name, value in fitted.values().items()}


def read_departures(window: Window, actuator: ActuatorParams = ActuatorParams()) -> Departures:
    """The window corrected for what it shows beyond ``actuator``, and what that was (module docstring)."""
    offset = read_zero_offset(window, actuator)
    drive = read_drive_constants(zeroed(window, offset), actuator)
    read = _along(window, offset, drive)
    if drive.alternative is None:
        return read
    mine, other = read.answer(), _along(window, offset, drive.alternative).answer()
    spread = {name: float(np.hypot(drive.spread[name], UNDECIDED_SHARE * (mine[name] - other[name]))) for name in mine}
    return replace(read, drive=replace(drive, spread=spread))


def _along(window: Window, offset: ZeroOffset, drive: DriveConstants) -> Departures:
    """The offset read first (again on the corrected window where a drive constant was read), then C."""
    if drive.stds:
        window = drive.corrected(window)
        offset = read_zero_offset(window, drive.actuator)
    window = zeroed(window, offset)
    return Departures(window, offset, drive, read_viscosity(window, drive.actuator))
