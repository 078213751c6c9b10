"""What other windows of an actuator read that one window may not, gathered from their results.

Two facts outlive a window: the sensors' zero, which a drive keeps for a power-on (a window of the
same ``flight_id``, moving both ways, reads it: ``training.zero_offset``), and J_M, which stays with
the build (a window that tells a heavier rotor from a weaker motor reads it: ``training.departures``).
The service gathers them from its history before it estimates a window, the fleet from the windows of
its run; ``known_from`` hands them to conditioning.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import replace

import numpy as np

from training.departures import Known
from training.documents import HistoryReadings, InertiaReading, SensorZero, WindowInfo
from training.zero_offset import ZeroOffset

NAMED_WINDOWS = 10  # the latest windows an actuator's J_M names as read by (all weigh in)


def best_zero(zeros: Iterable[SensorZero]) -> SensorZero | None:
    """The most precise of a flight's sensor zeros (a drive keeps one zero for a power-on), or None."""
    return min(zeros, key=lambda zero: zero.torque_std_nm, default=None)


def combined_inertia(readings: Sequence[InertiaReading]) -> InertiaReading | None:
    """J_M of an actuator from its windows' readings, oldest first: their inverse-variance mean, its std
    scaled by the Birge ratio where they scatter more than their stds allow (a reading's std too small
    shows in the scatter, not in the answer); or None without one."""
    if not readings:
        return None
    factors = np.array([r.factor for r in readings])
    weights = 1.0 / np.maximum([r.std for r in readings], 1e-12) ** 2
    mean = float(np.sum(weights * factors) / np.sum(weights))
    std = float(1.0 / np.sqrt(np.sum(weights)))
    if len(readings) > 1:
        chi2 = float(np.sum(weights * (factors - mean) ** 2))
        std *= max(1.0, float(np.sqrt(chi2 / (len(readings) - 1))))
    names = [name for r in readings for name in r.window_ids][-NAMED_WINDOWS:]
    return InertiaReading(factor=mean, std=std, window_ids=names)


def readings_of(windows: Iterable[WindowInfo], flight_id: str | None) -> HistoryReadings:
    """What the results of other windows of an actuator read (their ``window`` parts, oldest first): the
    most precise sensor zero of ``flight_id``'s, J_M from every one that told it apart."""
    zeros, inertias = [], []
    for info in windows:
        if info.sensor_zero is not None and flight_id is not None and info.flight_id == flight_id:
            zeros.append(info.sensor_zero)
        if info.inertia_read is not None:
            inertias.append(info.inertia_read)
    return HistoryReadings(sensor_zero=best_zero(zeros), inertia=combined_inertia(inertias))


def known_from(history: HistoryReadings | None) -> Known:
    """A flight's sensor zero and an actuator's J_M as conditioning takes them."""
    if history is None:
        return Known()
    zero, inertia, carried = history.sensor_zero, history.inertia, None
    if zero is not None:
        carried = ZeroOffset(hinge_nm=zero.hinge_nm, current_a=zero.current_a, zero_std_nm=zero.torque_std_nm)
        carried = replace(carried, carried_from=zero.window_id)
    if inertia is None:
        return Known(zero=carried)
    return Known(carried, inertia.factor, inertia.std, tuple(inertia.window_ids))
