"""The viscous coefficient a window shows, read where it departs from the document's.

The document fixes C_M; a grease's viscosity is not fixed (it grows several-fold in the cold), and
an excess ΔC·|ω| left in the residual is read as friction. Where a window slides at one speed the
two are twins, but most windows slide across 100–600 rad/s (the accelerations to and from slew),
and there ΔC is solved beside FDJ (``SolveSettings(viscous=True)``).

Freeing C costs FDJ precision where C is right, so a change is read only where it stands
``DECISIVE_Z`` stds out and is ``MIN_CHANGE`` of the document's C or more. Then every estimator of
the window uses the read C, the solutions and the simulations alike, and the stds of FDJ and η_O grow by
what C's own std moves them (``spread``; its floor, ``READ_ERROR_OF_C``, as the reconstruction's
bias follows the speed a little).

Where the speed hardly varies (one way, at slew), ΔC cannot be solved at all, and the stds carry a C
``UNSEEN_SHARE`` off the document's either way, as the offset stage carries an unseen sensor offset.
Where the change does not stand out, the window is read with the document's C, but not as if it had
shown C to be right: as for a hinge moment out of step (``ema.kinds.rotary.prepare.step_lag``), the story
"C is off by the change the window leans to" is weighed against the document's by the likelihood
ratio of the nested solution (z²/2, z over the std with its floor) and a prior of e⁻⁴: its weight w.
Each target's std grows by √w·|gap|, the gap what reading C so would change, and a note says so
from ``NOTE_WEIGHT``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.stats import DECISIVE_Z, odds_weight
from ema.kinds.rotary.evidence import UNDECIDED_NOTE_WEIGHT, UNDECIDED_PRIOR_LOG_ODDS
from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.friction import SolveSettings, solve_friction
from ema.kinds.rotary.prepare.departures.drive_constants import UNDECIDED_SHARE
from ema.kinds.rotary.simulator.effects import EffectSet
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

MIN_CHANGE = 0.1  # of the document's C
# A floor of C's std, of the document's C: the reconstruction's bias follows the speed a little, beyond what the
# jackknife sees.
READ_ERROR_OF_C = 0.025
# Where the speed hardly varies (one way at slew) C·|ω| is FDJ's twin and ΔC cannot be solved: the stds then
# carry a C this share of the document's off, either way (the spread of C over a fleet a third of it cold).
UNSEEN_SHARE = 0.3
CHANGE_BOUNDS_NMS = (
    -5e-5,
    5e-3,
)  # what the simulator's viscous effect accepts (``simulator.effects``)
VISCOUS_SOLVE = SolveSettings(offset=True, viscous=True)
# A change that stands out is solved again beside a scale of the motor torque: at the drive's top speed the
# speed falls as the load grows, so C·|ω| follows the load, and a current read a few per cent high (which scales
# the aiding and the opposing load's share alike, against Eq. 3.4) reads as a viscous change. Where it no longer
# stands out there, the window cannot tell the two: C stays the document's, and the stds carry
# ``UNDECIDED_SHARE`` of what reading the change would move.
BESIDE_A_GAIN = SolveSettings(offset=True, viscous=True, torque_scale=True)
# the prior odds of "C is off" where the change does not stand out, and the note's weight (as step_lag's)
PRIOR_LOG_ODDS, NOTE_WEIGHT = UNDECIDED_PRIOR_LOG_ODDS, UNDECIDED_NOTE_WEIGHT


@dataclass(frozen=True)
class Viscosity:
    """The change of the viscous coefficient read on a window (0: the document's), and what its std adds."""

    change_nms: float = 0.0  # ΔC [N·m·s/rad] at the motor shaft
    change_std_nms: float = 0.0
    spread: dict[str, float] = field(default_factory=dict)  # per target, the std C's uncertainty adds
    spec_nms: float = 0.0  # the C_M it was read against
    leaning_nms: float = 0.0  # where no change was read: the ΔC the window leans to, weighed into ``spread``
    leaning_weight: float = 0.0  # the posterior weight of "C is off by ``leaning_nms``"
    unseen: bool = False  # the window cannot tell C·|ω| from FDJ: ``spread`` carries a C ``UNSEEN_SHARE`` off
    gain_alike: bool = False  # a change (``leaning_nms``) stood out that a current gain explains as well

    @property
    def factor(self) -> float:
        """The coefficient read over the document's (1 where none was read, or the document's is 0)."""
        return 1.0 + self.change_nms / self.spec_nms if self.change_nms and self.spec_nms > 0 else 1.0

    @property
    def leaning_factor(self) -> float:
        """The coefficient the window leans to, over the document's."""
        return 1.0 + self.leaning_nms / self.spec_nms if self.spec_nms > 0 else 1.0

    def drive_as_read(self, spec: DriveConstants) -> DriveConstants:
        """The actuator every solution of the window reads it with."""
        return replace(spec, viscous_nms=spec.viscous_nms + self.change_nms) if self.change_nms else spec

    def effects(self) -> EffectSet:
        """What every simulation of the window adds to the document's model."""
        return EffectSet({"viscous": {"coefficient_nms": self.change_nms}}) if self.change_nms else EffectSet()


def read_viscosity(window: RotaryWindow, spec: DriveConstants) -> Viscosity:
    """ΔC where it stands out, with FDJ's and η_O's change across C ± its std; elsewhere the document's C,
    with what the change the window leans to would move them, by its weight (module docstring)."""
    rate = window.sample_rate_hz
    seen = as_read(window.signals, rate)
    solved = solve_friction(seen, rate, spec, VISCOUS_SOLVE)
    change, std = float(solved.term("viscous")[0]), float(solved.term_std("viscous")[0])
    if not (np.isfinite(change) and std > 0):  # the speed hardly varies: C·|ω| is FDJ's twin
        return _unseen(seen, rate, spec)
    stands_out = abs(change) > max(DECISIVE_Z * std, MIN_CHANGE * spec.viscous_nms)
    std = float(np.hypot(std, READ_ERROR_OF_C * spec.viscous_nms))
    if not stands_out:
        return _leaning(seen, rate, spec, change, std)
    change = float(np.clip(change, *CHANGE_BOUNDS_NMS))
    beside = solve_friction(seen, rate, spec, BESIDE_A_GAIN)
    if not abs(float(beside.term("viscous")[0])) > DECISIVE_Z * float(beside.term_std("viscous")[0]):
        return _gain_alike(seen, rate, spec, change)
    return Viscosity(change, std, _half_change(seen, rate, spec, change, std), spec.viscous_nms)


def _gain_alike(seen: dict[str, np.ndarray], rate: float, spec: DriveConstants, change: float) -> Viscosity:
    """The document's C where ``change`` stands out alone but not beside a gain of the motor torque (``BESIDE_A_GAIN``),
    with ``UNDECIDED_SHARE`` of what reading it would move each target in the stds."""
    spec_read, off_read = _targets_at(seen, rate, spec, (0.0, change))
    spread = {name: float(UNDECIDED_SHARE * abs(off_read[name] - spec_read[name])) for name in spec_read}
    return Viscosity(spread=spread, spec_nms=spec.viscous_nms, leaning_nms=change, gain_alike=True)


def _targets_at(
    seen: dict[str, np.ndarray], rate: float, spec: DriveConstants, changes: tuple[float, ...]
) -> list[dict[str, float]]:
    """FDJ and η_O read with the document's C plus each change."""
    solutions = (solve_friction(seen, rate, replace(spec, viscous_nms=spec.viscous_nms + d)) for d in changes)
    return [{name: float(value) for name, value in solution.values().items()} for solution in solutions]


def _half_change(
    seen: dict[str, np.ndarray], rate: float, spec: DriveConstants, change: float, std: float
) -> dict[str, float]:
    """Per target, half its change across the document's C plus ``change`` ± ``std``: the std that uncertainty adds."""
    low, high = _targets_at(seen, rate, spec, (change - std, change + std))
    return {name: abs(high[name] - low[name]) / 2 for name in low}


def _unseen(seen: dict[str, np.ndarray], rate: float, spec: DriveConstants) -> Viscosity:
    """The document's C where the window cannot tell C·|ω| from FDJ, with the stds carrying a change of
    ``UNSEEN_SHARE`` of it either way (module docstring)."""
    spread = _half_change(seen, rate, spec, 0.0, UNSEEN_SHARE * spec.viscous_nms)
    if not all(np.isfinite(v) for v in spread.values()):
        return Viscosity()  # too little sliding motion to solve at all: the physics solution says so next
    return Viscosity(spread=spread, spec_nms=spec.viscous_nms, unseen=True)


def _leaning(seen: dict[str, np.ndarray], rate: float, spec: DriveConstants, change: float, std: float) -> Viscosity:
    """The document's C, with the story "off by ``change``" weighed into the stds (module docstring)."""
    weight = odds_weight((change / std) ** 2 / 2 + PRIOR_LOG_ODDS)
    change = float(np.clip(change, *CHANGE_BOUNDS_NMS))
    spec_read, off_read = _targets_at(seen, rate, spec, (0.0, change))
    spread = {name: float(np.sqrt(weight) * abs(off_read[name] - spec_read[name])) for name in spec_read}
    if not all(np.isfinite(v) for v in spread.values()):
        return Viscosity()
    return Viscosity(spread=spread, spec_nms=spec.viscous_nms, leaning_nms=change, leaning_weight=weight)


def viscosity_note(viscosity: Viscosity) -> list[Note]:
    """The change, or what the window could not tell of it, for the result's notes."""
    if viscosity.unseen:
        return [
            Note(
                code="viscosity_unseen",
                text="the speed hardly varies: a viscous coefficient off the document's (a cold grease) would read as "
                "FDJ here, "
                f"and cannot be told from it (the stds include a coefficient {100 * UNSEEN_SHARE:.0f} % off either "
                f"way)",
            )
        ]
    if viscosity.gain_alike:
        return [
            Note(
                code="viscosity_leaning",
                text="friction follows the speed as a viscous coefficient of "
                f"{_against(viscosity, viscosity.leaning_nms)} would, and as a current read a few per cent off "
                "would (at top speed the speed falls as the load grows): the window cannot tell them apart; read "
                "with the document's coefficient, the stds include what the other reading would change",
            )
        ]
    if not viscosity.change_nms:
        return _leaning_note(viscosity)
    return [
        Note(
            code="viscosity",
            text=f"the viscous coefficient reads {_against(viscosity, viscosity.change_nms, viscosity.change_std_nms)} "
            "(a cold or aged grease): every estimator of this window used it, and the stds "
            "include "
            "its uncertainty; read with the document's, C·|ω| would have passed for friction",
        )
    ]


def _against(viscosity: Viscosity, change_nms: float, std_nms: float | None = None) -> str:
    """A coefficient the window reads, against the document's: as a factor of it, or where the document's is 0,
    in N·m·s/rad."""
    if viscosity.spec_nms > 0:
        spread = "" if std_nms is None else f" ± {std_nms / viscosity.spec_nms:.2f}"
        return f"{1.0 + change_nms / viscosity.spec_nms:.2f}{spread} times the document's"
    spread = "" if std_nms is None else f" ± {std_nms:.3g}"
    return f"{change_nms:.3g}{spread} N·m·s/rad where the document's is 0"


def _leaning_note(viscosity: Viscosity) -> list[Note]:
    if viscosity.leaning_weight < NOTE_WEIGHT:
        return []
    return [
        Note(
            code="viscosity_leaning",
            text=f"the viscous coefficient leans to {_against(viscosity, viscosity.leaning_nms)}, "
            f"too unclear to read (weight {viscosity.leaning_weight:.2f}); read with the document's, the stds include "
            "what that "
            "coefficient would change",
        )
    ]
