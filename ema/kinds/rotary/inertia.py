"""An actuator's J_M over its windows: one reading from many, and a replaced part said.

J_M stays with the build, so the readings of an actuator's windows (those that told a heavier rotor from a weaker
motor) are one quantity read many times: combined by inverse variance since it last changed, a change or a
scatter beyond their stds said. The prognosis reports it beside the trends; the rotary kind lends it to a window
that cannot read it (``ema.kinds.rotary.other_windows``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.documents.window_facts import InertiaReading

NAMED_WINDOWS = 10  # the latest windows an actuator's J_M names as read by (all weigh in)
SCATTER_NOTED = 3.0  # stds (a reading's from the others', or the Birge ratio) from which J_M readings disagree


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
