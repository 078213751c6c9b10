"""What other windows of an actuator read that one window may not, gathered from their results.

Two facts outlive a window: the sensors' zero, which a drive keeps for a power-on (a window of the
same ``flight_id``, moving both ways, reads it: ``ema.estimate.prepare.departures.zero_offset``), and J_M,
which stays with the build (a window that tells a heavier rotor from a weaker motor reads it:
``ema.estimate.prepare.departures.read``).
The service gathers them from its history before it estimates a window, the fleet from the windows of
its run; ``known_from`` hands them to conditioning.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.documents.window_facts import HistoryReadings, InertiaReading, SensorZero, WindowInfo
from ema.estimate.prepare.departures.read import Known
from ema.estimate.prepare.departures.zero_offset import ZeroOffset

NAMED_WINDOWS = 10  # the latest windows an actuator's J_M names as read by (all weigh in)
SCATTER_NOTED = 3.0  # stds (a reading's from the others', or the Birge ratio) from which J_M readings disagree


def best_zero(zeros: Iterable[SensorZero]) -> SensorZero | None:
    """The most precise of a flight's sensor zeros (a drive keeps one zero for a power-on), or None."""
    return min(zeros, key=lambda zero: zero.torque_std_nm, default=None)


def _arrays(readings: Sequence[InertiaReading]) -> tuple[np.ndarray, np.ndarray]:
    """The readings' factors and inverse variances."""
    return np.array([r.factor for r in readings]), 1.0 / np.maximum([r.std for r in readings], 1e-12) ** 2


def _weighted(readings: Sequence[InertiaReading]) -> tuple[float, float, float]:
    """(inverse-variance mean, its std, Birge ratio: how many times their stds the readings scatter) of
    at least one reading (the ratio 1 for one)."""
    factors, weights = _arrays(readings)
    mean = float(np.sum(weights * factors) / np.sum(weights))
    chi2 = float(np.sum(weights * (factors - mean) ** 2))
    birge = float(np.sqrt(chi2 / (len(readings) - 1))) if len(readings) > 1 else 1.0
    return mean, float(1.0 / np.sqrt(np.sum(weights))), birge


def since_change(readings: Sequence[InertiaReading]) -> Sequence[InertiaReading]:
    """The readings since J_M last changed: split where the two parts' means stand furthest apart, by more
    than ``SCATTER_NOTED`` stds of them (each std scaled by its part's Birge ratio, so readings that only
    scatter beyond their stds do not pass for a change), the later part at least two readings; else all."""
    n = len(readings)
    if n < 3:
        return readings
    factors, weights = _arrays(readings)
    centred = factors - factors.mean()  # the sums' differences below lose no digits to the common 1.0x
    sums = [np.cumsum(weights * centred**p) for p in range(3)]  # Σw, Σwf, Σwf² of the first k readings

    def parts(k: np.ndarray, before: bool) -> tuple[np.ndarray, np.ndarray]:
        s0, s1, s2 = (c[k - 1] if before else c[-1] - c[k - 1] for c in sums)
        count = k if before else n - k
        chi2 = np.maximum(s2 - s1**2 / s0, 0.0)
        birge = np.where(count > 1, np.sqrt(chi2 / np.maximum(count - 1, 1)), 1.0)
        return s1 / s0, np.maximum(birge, 1.0) / np.sqrt(s0)

    k = np.arange(1, n - 1)  # the later part holds readings k … n−1, two at least
    (mean_before, std_before), (mean_after, std_after) = parts(k, True), parts(k, False)
    z = np.abs(mean_after - mean_before) / np.hypot(std_before, std_after)
    best = int(np.argmax(z))
    return readings[k[best] :] if z[best] > SCATTER_NOTED else readings


def combined_inertia(readings: Sequence[InertiaReading]) -> InertiaReading | None:
    """J_M of an actuator from its windows' readings, oldest first, since it last changed (``since_change``):
    their inverse-variance mean, its std scaled by the Birge ratio where they scatter more than their
    stds allow (a reading's std too small shows in the scatter, not in the answer); or None without one."""
    if not readings:
        return None
    used = since_change(readings)
    mean, std, birge = _weighted(used)
    names = [name for r in used for name in r.window_ids][-NAMED_WINDOWS:]
    return InertiaReading(factor=mean, std=std * max(1.0, birge), window_ids=names)


def inertia_change_note(readings: Sequence[InertiaReading]) -> Note | None:
    """A note where an actuator's J_M readings do not agree (J_M stays with the build: a part was replaced,
    or readings are off): since which window it reads otherwise, or how far they scatter; or None."""
    if len(readings) < 2:
        return None
    used = since_change(readings)
    if len(used) < len(readings):
        before = _weighted(readings[: len(readings) - len(used)])[0]
        return Note(
            code="inertia_changed",
            text=(
                f"J_M read {before:.3f}x the document's before window {used[0].window_ids[0]} "
                f"and {_weighted(used)[0]:.3f}x "
                f"since ({len(used)} windows): a rotor, screw or gear replaced? The actuator's J_M is read since"
            ),
        )
    mean, _, birge = _weighted(readings)
    if birge < SCATTER_NOTED:
        return None
    low, high = min(r.factor for r in readings), max(r.factor for r in readings)
    return Note(
        code="inertia_scatter",
        text=(
            f"the {len(readings)} windows that read J_M read {low:.3f}–{high:.3f}x the document's, "
            f"{birge:.1f} times as far "
            f"apart as their stds allow (a part replaced, or readings gone wrong?): the actuator's J_M ({mean:.3f}) is "
            "said with its std widened as much"
        ),
    )


def lent(zeros: Iterable[SensorZero], inertias: Sequence[InertiaReading]) -> HistoryReadings:
    """What an actuator's stored windows lend another: the most precise of its flight's sensor ``zeros``, and
    J_M from its ``inertias`` (oldest first) since it last changed. The one policy of the service's history,
    the fleet's run and ``ema estimate --history``."""
    return HistoryReadings(sensor_zero=best_zero(zeros), inertia=combined_inertia(inertias))


def readings_of(windows: Iterable[WindowInfo], flight_id: str | None) -> HistoryReadings:
    """What the results of other windows of an actuator (their ``window`` parts, oldest first) lend a window
    of ``flight_id`` (``lent``)."""
    zeros, inertias = [], []
    for info in windows:
        if info.sensor_zero is not None and flight_id is not None and info.flight_id == flight_id:
            zeros.append(info.sensor_zero)
        if info.inertia_read is not None:
            inertias.append(info.inertia_read)
    return lent(zeros, inertias)


def wanted(read: WindowInfo, others: HistoryReadings) -> HistoryReadings | None:
    """What a window answered alone (``read``) would be answered again with: its flight's sensor zero where it
    read none or a less precise one (conditioning takes it where it holds), J_M where it could not tell a
    heavier rotor from a weaker motor; None where the others lend it nothing it lacks."""
    zero = others.sensor_zero
    own = read.sensor_zero
    takes_zero = zero is not None and (own is None or zero.torque_std_nm < own.torque_std_nm)
    inertia = others.inertia if read.inertia_undecided else None
    if not takes_zero and inertia is None:
        return None
    return HistoryReadings(sensor_zero=zero if takes_zero else None, inertia=inertia)


def known_from(history: HistoryReadings | None) -> Known:
    """A flight's sensor zero and an actuator's J_M as conditioning takes them."""
    if history is None:
        return Known()
    zero, inertia, carried = history.sensor_zero, history.inertia, None
    if zero is not None:
        carried = ZeroOffset(
            hinge_nm=zero.hinge_nm,
            current_a=zero.current_a,
            zero_std_nm=zero.torque_std_nm,
            carried_from=zero.window_id,
        )
    if inertia is None:
        return Known(zero=carried)
    return Known(carried, inertia.factor, inertia.std, tuple(inertia.window_ids))
