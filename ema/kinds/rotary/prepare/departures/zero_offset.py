"""A sensor off zero: the current or the hinge moment logged with a constant added, read and removed.

A strain gauge drifts with temperature, a Hall current sensor has an offset; either leaves T_R a
constant c beyond friction (k_T·i₀ from the current, b/n from the hinge moment), which Eq. 5.1's
t = sgn(ω)(T_R − C·ω) reads as c·sgn(ω): friction, unless it is taken off.

With motion both ways c·sgn(ω) is told from FDJ, so it is solved beside it (``SolveSettings(offset=
True)``) and read where the solution with it explains the window ``DECISIVE_Z`` stds better than the solution
without (the likelihood ratio of their equation errors, ``equation_z``). The offset's own jackknife
std is no test: where one direction's samples gather in a few time blocks, leaving those out leaves
c unread. Which sensor is off matters: a hinge moment off by b also shifts |T_ext|, whose k·|T_ext|
term then moves FDJ by about k·b/n. The two readings differ only where |T_ext| comes near zero or
varies, so both are made: the current corrected by i₀, or the hinge moment by b, each solved again until
no constant is left (|H − b| is not linear in b, and k_T·I is cut at the motor's peak torque). Their
likelihoods (the equation errors' RSS, over about one independent value per reconstruction kernel)
weigh them; the window is corrected by the weighted mix, which puts the answer between the readings,
and each target's std grows by their disagreement (``conditioning.widened``): an offset the window
cannot place is an uncertainty, said as one.

Where the motion goes one way, no offset can be read. A drive keeps its sensors' zero for a power-on,
so such a window is read with the zero a window of the same flight read moving both ways
(``carried``, FDJ's std carrying that reading's ``zero_std_nm``); where the flight has none, FDJ's std
carries an offset a sensor may keep unseen (``UNSEEN_CURRENT_OFFSET_A``). A short window moving both
ways takes its flight's zero where that holds on it (``flight_zero``, more precise than its own);
where it does not, a sensor drifted or the drive was powered up again, and the window's own reading
stands. A note says which.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.stats import DECISIVE_Z, odds_weight
from ema.kinds.rotary.evidence import rms_log_likelihood_ratio
from ema.kinds.rotary.physics.features import solve_as_read
from ema.kinds.rotary.physics.friction import FrictionSolution, SolveSettings
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

# A flight's zero holds on a window where, taken off it, the constant left lies within this many stds of none: a
# sensor that drifted (or a power-on between) shows, and the window's own reading is taken.
HOLDS_Z = 3.0
# Where the motion goes one way, an offset is FDJ's twin and cannot be read: FDJ then rests on the sensors
# being on zero, and its std carries the offset a Hall sensor keeps after its power-up zeroing (~0.2 % of
# the thesis drive's 22.5 A).
UNSEEN_CURRENT_OFFSET_A = 0.05
# Solves of a sensor's offset: the hinge moment's moves |H − b| (each solve cuts what is left by ~k), the
# current's is lost where k_T·I meets the motor's peak torque (worn windows saturate more, and need more solves).
OFFSET_ITERATIONS = 4
OFFSET_SOLVE = SolveSettings(offset=True)


@dataclass(frozen=True)
class ZeroOffset:
    """A constant T_R holds beyond friction, and how it was taken off the window (all 0: none found)."""

    torque_nm: float = 0.0  # c at the motor shaft
    torque_std_nm: float = 0.0
    hinge_share: float = 0.0  # the weight of "the hinge moment is off" against "the current is off"
    hinge_nm: float = 0.0  # taken off the logged hinge moment
    current_a: float = 0.0  # taken off the logged current
    spread: dict[str, float] = field(default_factory=dict)  # per target, the std what is unknown of it adds
    one_way: bool = False  # the motion goes one way: no offset could be read, FDJ's std carries an unseen one
    # the std of the zero as read, at the motor shaft (c's own, which sensor holds it; one read as none: |c| too)
    zero_std_nm: float = 0.0
    carried_from: str | None = None  # the window of the same flight whose zero was taken off instead
    unheld_from: str | None = None  # the window of the same flight whose zero did not hold on this one ...
    unheld_z: float = 0.0  # ... by how many stds

    @property
    def read(self) -> bool:
        """Read on this window, moving both ways (not carried, not the unread default)."""
        return not self.one_way and self.carried_from is None and self.zero_std_nm > 0.0


def _shifted(signals: dict[str, np.ndarray], hinge_nm: float = 0.0, current_a: float = 0.0) -> dict[str, np.ndarray]:
    return dict(
        signals, hinge_moment_nm=signals["hinge_moment_nm"] - hinge_nm, current_a=signals["current_a"] - current_a
    )


def sensor_offset(
    signals: dict[str, np.ndarray], rate: float, torque_nm: float, sensor: str, drive: DriveConstants
) -> float:
    """The offset of ``sensor`` (``hinge_nm`` or ``current_a``) that leaves no constant in T_R: from the
    shaft's c in the sensor's unit, solved again as the reading moves (``OFFSET_ITERATIONS``)."""
    per_nm = drive.gear_ratio if sensor == "hinge_nm" else 1.0 / drive.torque_constant_nm_per_a
    offset = per_nm * torque_nm
    for _ in range(OFFSET_ITERATIONS):
        left = solve_as_read(_shifted(signals, **{sensor: offset}), rate, drive, OFFSET_SOLVE).term("offset")[0]
        if not np.isfinite(left):
            break
        offset += per_nm * float(left)
    return offset


def log_likelihood_ratio(worse: FrictionSolution, better: FrictionSolution, rate: float) -> float:
    """ln of the likelihood ratio of two solutions of one window, by their equation errors
    (``rms_log_likelihood_ratio``)."""
    errors, used = (float(worse.residual_rms_nm[0]), float(better.residual_rms_nm[0])), float(worse.n_sliding[0])
    return rms_log_likelihood_ratio(*errors, used, rate, resolution_nm=float(worse.resolution_nm[0]))


def equation_z(plain: FrictionSolution, with_offset: FrictionSolution, rate: float) -> float:
    """How many stds the offset's solution explains the window better by: √(2·ln LR), as for one parameter."""
    return float(np.sqrt(max(0.0, 2.0 * log_likelihood_ratio(plain, with_offset, rate))))


def second_weight(first: FrictionSolution, second: FrictionSolution, rate: float) -> float:
    """The weight of the second of two readings of a window against the first: their likelihoods, equal
    odds before."""
    return odds_weight(log_likelihood_ratio(first, second, rate))


def read_zero_offset(window: RotaryWindow, drive: DriveConstants, carried: ZeroOffset | None = None) -> ZeroOffset:
    """The window's constant torque beyond friction, where the solution with it explains the window ``DECISIVE_Z``
    stds better, and the two readings of it (module docstring) weighed; the zero ``carried`` from a window
    of the same flight where it is the more precise and holds here (``flight_zero``); where the motion goes
    one way, the carried zero, or the note that none is known."""
    rate, signals = window.sample_rate_hz, dict(window.signals)
    found = solve_as_read(signals, rate, drive, OFFSET_SOLVE)
    if float(found.term_std("offset")[0]) == 0.0:  # too little motion the other way (``eta_search.MIN_OFFSET_BALANCE``)
        unseen = UNSEEN_CURRENT_OFFSET_A * drive.torque_constant_nm_per_a
        known = carried or ZeroOffset(zero_std_nm=unseen)
        return replace(known, one_way=True, spread={"FDJ": known.zero_std_nm})
    own = own_reading(signals, rate, drive, found)
    if carried is None or carried.zero_std_nm >= own.zero_std_nm:
        return own
    return flight_zero(signals, rate, drive, carried, own)


def own_reading(
    signals: dict[str, np.ndarray], rate: float, drive: DriveConstants, found: FrictionSolution
) -> ZeroOffset:
    """The offset the window reads itself from ``found``, Eq. 5.1's solution with one (module docstring)."""
    torque, std = float(found.term("offset")[0]), float(found.term_std("offset")[0])
    if not (np.isfinite(torque) and equation_z(solve_as_read(signals, rate, drive), found, rate) > DECISIVE_Z):
        return ZeroOffset(zero_std_nm=float(np.hypot(std, torque)) if np.isfinite(torque) else 0.0)
    current_a = sensor_offset(signals, rate, torque, "current_a", drive)
    hinge_nm = sensor_offset(signals, rate, torque, "hinge_nm", drive)
    as_current = solve_as_read(_shifted(signals, current_a=current_a), rate, drive)
    as_hinge = solve_as_read(_shifted(signals, hinge_nm=hinge_nm), rate, drive)
    share = second_weight(as_current, as_hinge, rate)
    apart = {
        "FDJ": float(as_hinge.fdj_nm[0] - as_current.fdj_nm[0]),
        "eta_O": float(as_hinge.eta_o[0] - as_current.eta_o[0]),
    }
    spread = {name: float(np.sqrt(share * (1.0 - share)) * abs(gap)) for name, gap in apart.items()}
    return ZeroOffset(
        torque_nm=torque,
        torque_std_nm=std,
        hinge_share=share,
        hinge_nm=share * hinge_nm,
        current_a=(1.0 - share) * current_a,
        spread=spread,
        zero_std_nm=float(np.hypot(std, spread["FDJ"])),
    )


def flight_zero(
    signals: dict[str, np.ndarray], rate: float, drive: DriveConstants, carried: ZeroOffset, own: ZeroOffset
) -> ZeroOffset:
    """The flight's zero ``carried``, where it holds on this window (taken off, the constant left lies within
    ``HOLDS_Z`` stds of none); else the window's ``own`` reading, with how far the flight's is off."""
    left = solve_as_read(_shifted(signals, carried.hinge_nm, carried.current_a), rate, drive, OFFSET_SOLVE)
    z = abs(float(left.term("offset")[0])) / float(np.hypot(left.term_std("offset")[0], carried.zero_std_nm))
    if not z <= HOLDS_Z:
        return replace(own, unheld_from=carried.carried_from, unheld_z=z)
    return replace(carried, spread={"FDJ": carried.zero_std_nm})


def zeroed(window: RotaryWindow, offset: ZeroOffset) -> RotaryWindow:
    """``window`` with the offset taken off its sensors."""
    if not offset.hinge_nm and not offset.current_a:
        return window
    return replace(window, signals=_shifted(dict(window.signals), offset.hinge_nm, offset.current_a))


def offset_note(offset: ZeroOffset) -> list[Note]:
    """The offset, or where the window's zero came from, for the result's notes."""
    if offset.carried_from is not None:
        why = "a sensor off zero would read as FDJ here" if offset.one_way else "it reads their zero less precisely"
        return [
            Note(
                code="sensor_zero_carried",
                text=f"the motion goes {'one way' if offset.one_way else 'both ways'}, but {why}: the sensors' zero is "
                f"the "
                f"one window {offset.carried_from} of the same flight read moving both ways ({offset.hinge_nm:.2f} N·m "
                f"of hinge moment and {offset.current_a:.3f} A of current taken off; FDJ's std includes its "
                f"{1e3 * offset.zero_std_nm:.2f} mN·m)",
            )
        ]
    if offset.one_way:
        return [
            Note(
                code="sensor_zero_unseen",
                text="the motion goes one way: a current or hinge moment sensor off zero would read as FDJ here, and "
                f"cannot be told from it (FDJ's std includes {1e3 * offset.spread['FDJ']:.1f} mN·m for one, a current "
                f"{UNSEEN_CURRENT_OFFSET_A:g} A off; a window of the same flight (flight_id) moving both ways reads "
                f"it)",
            )
        ]
    notes = []
    if offset.torque_nm:
        notes.append(
            Note(
                code="sensor_offset",
                text=f"T_R holds a constant {1e3 * offset.torque_nm:.2f} ± {1e3 * offset.torque_std_nm:.2f} mN·m "
                f"beyond "
                "friction: a sensor off zero (or friction that differs by direction), taken off as "
                f"{offset.hinge_nm:.2f} N·m of hinge moment and {offset.current_a:.3f} A of current (the hinge moment "
                f"is "
                f"the one off with weight {offset.hinge_share:.2f}; where the window cannot tell, the stds include "
                f"what "
                "that changes)",
            )
        )
    if offset.unheld_from:
        notes.append(
            Note(
                code="sensor_zero_unheld",
                text=f"the sensors' zero window {offset.unheld_from} of the same flight read does not hold here (taken "
                f"off, "
                f"the constant left stands {offset.unheld_z:.1f} stds off none: a sensor drifted, or the drive was "
                "powered up again), so the window's own reading is taken",
            )
        )
    return notes
