"""What other windows of an actuator read that one window may not, gathered from their results.

Two facts outlive a window: the sensors' zero, which a drive keeps for a power-on (a window of the
same ``flight_id``, moving both ways, reads it: ``ema.kinds.rotary.prepare.departures.zero_offset``), and J_M,
which stays with the build (a window that tells a heavier rotor from a weaker motor reads it:
``ema.kinds.rotary.prepare.departures.read``).
The service gathers them from its history before it estimates a window, the fleet from the windows of
its run; ``known_from`` hands them to conditioning. J_M's readings are combined as the prognosis reads them
(``ema.kinds.rotary.inertia``).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from ema.estimate.documents.window_facts import (
    HistoryReadings,
    InertiaReading,
    RotaryWindowInfo,
    SensorZero,
    WindowInfo,
)
from ema.kinds.base import NOTHING_LENT, Borrowed, Lent
from ema.kinds.rotary.inertia import combined_inertia
from ema.kinds.rotary.prepare.departures.read import Known
from ema.kinds.rotary.prepare.departures.zero_offset import ZeroOffset
from ema.model.document import Document


def best_zero(zeros: Iterable[SensorZero]) -> SensorZero | None:
    """The most precise of a flight's sensor zeros (a drive keeps one zero for a power-on), or None."""
    return min(zeros, key=lambda zero: zero.torque_std_nm, default=None)


def lent(zeros: Iterable[SensorZero], inertias: Sequence[InertiaReading]) -> HistoryReadings:
    """What an actuator's stored windows lend another: the most precise of its flight's sensor ``zeros``, and
    J_M from its ``inertias`` (oldest first) since it last changed. The one policy of the service's history,
    the fleet's run and ``ema estimate --history``."""
    return HistoryReadings(sensor_zero=best_zero(zeros), inertia=combined_inertia(inertias))


def lent_by(info: WindowInfo) -> Lent:
    """What a window's answer lends the others of its actuator: its sensors' zero (to its flight's windows) and
    the J_M it read (to every window), each None where it read none."""
    if not isinstance(info, RotaryWindowInfo):
        return NOTHING_LENT  # a window read without the rotary's prepare stage (logged slowly) lends nothing
    zero, inertia = info.sensor_zero, info.inertia_read
    return Lent(
        to_flight=None if zero is None else zero.model_dump_json(),
        to_actuator=None if inertia is None else inertia.model_dump_json(),
    )


def borrowed(kept: Borrowed) -> HistoryReadings:
    """What the kept loans of an actuator's other windows (``lent_by``'s JSON, oldest first) lend one window."""
    zeros = [SensorZero.model_validate_json(text) for text in kept.from_flight]
    return lent(zeros, [InertiaReading.model_validate_json(text) for text in kept.from_actuator])


def inertia_readings(infos: Iterable[WindowInfo]) -> list[InertiaReading]:
    """The J_M each of ``infos`` read, in their order (those that read one)."""
    return [info.inertia_read for info in infos if isinstance(info, RotaryWindowInfo) and info.inertia_read]


def waits_for_the_run(info: WindowInfo) -> bool:
    """Whether a window answered alone could not tell J_M: it is answered again once the run's windows have read it."""
    return isinstance(info, RotaryWindowInfo) and info.inertia_undecided


def as_readings(history: Document | None) -> HistoryReadings | None:
    """``history`` as what the rotary's windows borrow (what the registry hands a kind is its own class)."""
    assert history is None or isinstance(history, HistoryReadings), type(history)
    return history


def wanted(read: WindowInfo, others: Document | None) -> HistoryReadings | None:
    """What a window answered alone (``read``) would be answered again with: its flight's sensor zero where it
    read none or a less precise one (conditioning takes it where it holds), J_M where it could not tell a
    heavier rotor from a weaker motor; None where the others lend it nothing it lacks."""
    lending = as_readings(others)
    if lending is None:
        return None
    zero = lending.sensor_zero
    own = read.sensor_zero if isinstance(read, RotaryWindowInfo) else None
    takes_zero = zero is not None and (own is None or zero.torque_std_nm < own.torque_std_nm)
    inertia = lending.inertia if waits_for_the_run(read) else None
    if not takes_zero and inertia is None:
        return None
    return HistoryReadings(sensor_zero=zero if takes_zero else None, inertia=inertia)


def known_from(history: Document | None) -> Known:
    """A flight's sensor zero and an actuator's J_M as conditioning takes them."""
    history = as_readings(history)
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
