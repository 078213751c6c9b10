"""The drive's k_T and J_M as a window shows them, read where they depart from the document's.

T_R = k_T·I − J_M·dω/dt + H_e/n takes both constants from the actuator document, and a real drive
has neither exactly: a magnet's k_T falls about 0.1 %/K as the motor warms and a Hall current
sensor carries a gain error of about 1 % (T_R then misses γ·k_T·I); a rotor, screw and gear train
reflect an inertia the document rounds (T_R then holds ΔJ·dω/dt too much). Both terms are large
beside friction, so a small error in either moves FDJ by much of its range.

Friction follows the direction and |T_ext|; k_T·I follows the signed load and the acceleration,
dω/dt the acceleration alone. So each constant is solved beside FDJ, with the offset and ΔC free,
and read where the solution with it explains the window ``DECISIVE_Z`` stds better than the solution without
(``zero_offset.equation_z``). Never both together: γ and ΔJ/J_M equal make a gain of the hinge
moment's term, and the noise the two columns share with the target would read one. Where both
stand out alone, the likelihood ratio of the two readings decides if it can (``DECISIVE``); where it
cannot (a heavier rotor in a window where the motor saturates as it accelerates, which a weaker
motor explains as well), γ is read and the stds carry what ΔJ would change (``UNDECIDED_SHARE``).
The current carries γ (I' = (1 + γ)·I, solved again up to ``ITERATIONS`` times, as the motor's peak
torque cuts k_T·I), the window's actuator carries ΔJ; FDJ's and η_O's stds grow by what each
constant's std moves them.

A current logged in other units (a tenth of it, a shunt's voltage) reads as a γ or a ΔJ no drive
has (``PLAUSIBLE``), and the window is refused naming the current (``no_drive_error``). A current
off by 1.4x or 0.7x (RMS against amplitude) is not refused: a heavy rotor reads alike, so the stds
carry both stories (``unit_story``). The measurements that set these bounds are in
``docs/evidence.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.stats import DECISIVE_Z
from ema.kinds.rotary.physics.features import solve_as_read
from ema.kinds.rotary.physics.friction import FrictionSolution, SolveSettings
from ema.kinds.rotary.prepare.departures.zero_offset import equation_z, log_likelihood_ratio
from ema.model.checks import InputError
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

ITERATIONS = 3  # solves of the corrected window at most: each settles what the peak torque's cut left
SETTLED = 0.01  # of the constant's std: what a solve may leave
BESIDE = SolveSettings(offset=True, viscous=True)  # what each constant is solved beside
FIELDS = {"torque_scale": "torque_scale", "inertia": "inertia_kgm2"}  # the solution's nuisance -> the field it reads
# Beyond these no drive runs (γ: k_T from −55 to 125 °C and a sensor's gain; ΔJ: of J_M): a read past them
# is something else the model lacks, which the check reports.
PLAUSIBLE = {"torque_scale": 0.2, "inertia": 0.5}
# Stds of its own by which a γ solved alone must pass PLAUSIBLE for the current to be refused (``no_drive_error``):
# a window whose blocks split the accelerations unevenly reads γ loosely, and must not be refused on that.
SCALE_STDS = 2.0
# Where both stand out, the log-likelihood ratio of the two readings that decides for each. The bounds are
# asymmetric: the sensor noise sits in both columns as in the target and favours one, and a heavier rotor that
# saturates the motor as a weaker one would leans far towards γ. Short of these, the window cannot tell them apart.
DECISIVE = {"inertia": 12.0, "torque_scale": -30.0}
# Undecided, γ is read (k_T moves with temperature from flight to flight, J_M stays with the build), and the
# stds grow by this share of what reading ΔJ instead would change (``ema.kinds.rotary.prepare.departures.read``).
UNDECIDED_SHARE = 0.6
# The 2 ms reconstruction reads J_M low where its kernel spans few samples (the bias shrinks as h²). ΔJ's std
# carries this share of J_M at 1 kHz, scaled by (1 kHz / rate)². The bias is systematic, so averaging windows does
# not shrink it: the history keeps J_M only from windows processed at KERNEL_FREE_RATE_HZ or more
# (``ema.estimate.report``).
KERNEL_INERTIA_SHARE = 0.01
KERNEL_FREE_RATE_HZ = 5_000.0


@dataclass(frozen=True)
class DriveReading:
    """γ and ΔJ read on a window (0: the document's), and what their stds add to FDJ's and η_O's."""

    spec: DriveConstants  # the drive's constants the departures are read against
    torque_scale: float = 0.0  # γ: the motor's torque is (1 + γ)·k_T·I
    inertia_kgm2: float = 0.0  # ΔJ beyond the document's J_M
    stds: dict[str, float] = field(default_factory=dict)  # per field read, its std
    spread: dict[str, float] = field(default_factory=dict)  # per target, the std the constants' uncertainty adds
    alternative: DriveReading | None = None  # where the window did not tell ΔJ from this γ: the ΔJ reading
    unit_scale: float = 0.0  # γ solved alone beyond any motor, its answer's gap in ``spread`` (``unit_story``)

    @property
    def torque_factor(self) -> float:
        """The motor's torque per spec k_T·I."""
        return 1.0 + self.torque_scale

    @property
    def inertia_factor(self) -> float:
        """The inertia at the motor shaft over the document's J_M."""
        return 1.0 + self.inertia_kgm2 / self.spec.inertia_kgm2

    @property
    def drive_as_read(self) -> DriveConstants:
        """The actuator the window's T_R is reconstructed with: the document's, its J_M as read."""
        return replace(self.spec, inertia_kgm2=self.spec.inertia_kgm2 + self.inertia_kgm2)

    def added(self, left: FrictionSolution) -> DriveReading:
        """These constants with what a solution of the corrected window left of them."""
        scale = self.torque_factor * (1.0 + float(left.term("torque_scale")[0])) - 1.0
        return replace(self, torque_scale=scale, inertia_kgm2=self.inertia_kgm2 + float(left.term("inertia")[0]))

    def corrected(self, window: RotaryWindow) -> RotaryWindow:
        """``window`` with its current on the document's k_T: I' = (1 + γ)·I."""
        if not self.torque_scale:
            return window
        return replace(window, signals=dict(window.signals, current_a=self.torque_factor * window.signals["current_a"]))


def _solve(window: RotaryWindow, drive: DriveConstants, settings: SolveSettings) -> FrictionSolution:
    return solve_as_read(window.signals, window.sample_rate_hz, drive, settings)


def read_drive_constants(window: RotaryWindow, drive: DriveConstants) -> DriveReading:
    """γ or ΔJ where it stands out (module docstring), with FDJ's and η_O's change across it ± its std. Where
    both do, the likelier if the window decides (``DECISIVE``); else γ, with ΔJ beside it as the
    ``alternative`` (``ema.kinds.rotary.prepare.departures.read`` replays both, or widens the stds by their gap)."""
    rate = window.sample_rate_hz
    plain = _solve(window, drive, BESIDE)
    alone = {name: _solve(window, drive, replace(BESIDE, **{name: True})) for name in FIELDS}
    gamma = beyond_any_motor(plain, alone["torque_scale"], rate)
    refusal = no_drive_error(gamma, alone["inertia"], drive)
    if refusal is not None:
        raise refusal
    read = _read_constants(window, drive, plain, alone)
    if read.alternative is not None:
        read = replace(read, alternative=unit_story(read.alternative, gamma, plain, alone))
    return unit_story(read, gamma, plain, alone)


def _read_constants(
    window: RotaryWindow, drive: DriveConstants, plain: FrictionSolution, alone: dict[str, FrictionSolution]
) -> DriveReading:
    rate = window.sample_rate_hz
    found = [name for name in FIELDS if _stands_out(plain, alone[name], name, rate, drive)]
    readings = {name: _reading(window, drive, name, alone[name]) for name in found}
    if not readings:
        return DriveReading(spec=drive)
    if len(readings) == 1:
        return _with_spread(window, next(iter(readings.values()))[0])
    (scale, scale_solution), (inertia, inertia_solution) = readings["torque_scale"], readings["inertia"]
    ratio = log_likelihood_ratio(scale_solution, inertia_solution, rate)  # for the inertia
    if ratio >= DECISIVE["inertia"] or ratio <= DECISIVE["torque_scale"]:
        return _with_spread(window, inertia if ratio > 0 else scale)
    return replace(_with_spread(window, scale), alternative=_with_spread(window, inertia))


def beyond_any_motor(plain: FrictionSolution, scale: FrictionSolution, rate: float) -> float:
    """γ solved alone (``scale``) where it lies beyond any motor, ``PLAUSIBLE`` by ``SCALE_STDS`` of its std,
    and stands ``DECISIVE_Z`` out; else 0."""
    gamma, std = float(scale.term("torque_scale")[0]), float(scale.term_std("torque_scale")[0])
    beyond = abs(gamma) > PLAUSIBLE["torque_scale"] + SCALE_STDS * std and equation_z(plain, scale, rate) > DECISIVE_Z
    return gamma if beyond else 0.0


def no_drive_error(gamma: float, inertia_alone: FrictionSolution, spec: DriveConstants) -> InputError | None:
    """The error naming the current where Eq. 5.1 balances the window only with a motor torque per k_T·I
    and an inertia no drive has, each solved alone (``gamma`` from ``beyond_any_motor``; ΔJ, its rival
    where the motor saturates, beyond ``PLAUSIBLE`` too): a current in other units (a tenth: γ = 9). None
    otherwise."""
    inertia = float(inertia_alone.term("inertia")[0]) / spec.inertia_kgm2
    if not (gamma and abs(inertia) >= PLAUSIBLE["inertia"]):
        return None
    return InputError(
        "signals.current_a",
        f"Eq. 5.1 balances the window only with the motor giving {1 + gamma:.3g}x the document's k_T·I (a k_T of "
        f"{(1 + gamma) * spec.torque_constant_nm_per_a:.3g} N·m/A against its {spec.torque_constant_nm_per_a:g}), or "
        f"with J_M {1 + inertia:.3g}x the document's {spec.inertia_kgm2:g} kg·m², beyond any drive's departure "
        f"(±{PLAUSIBLE['torque_scale']:.0%}, ±{PLAUSIBLE['inertia']:.0%}): is the actuator's document the right one? "
        "Else the current is in other units, or a shunt's voltage",
    )


def unit_story(
    read: DriveReading, gamma: float, plain: FrictionSolution, alone: dict[str, FrictionSolution]
) -> DriveReading:
    """``read`` with the story of a current in other units weighed in, where γ solved alone lies beyond any
    motor (``gamma`` from ``beyond_any_motor``) and yet ΔJ reads a drive: a current logged 0.71x (RMS for
    amplitude) reads as a rotor ~0.7x as heavy with other friction, and a rotor 1.3–1.45x as heavy as a
    current logged 1.41x, alike. Each target's std grows by the full gap between the γ reading's answer
    and ``read``'s: neither story can be ruled out, so the answer must cover both."""
    if not gamma:
        return read
    reference = (alone["inertia"] if read.inertia_kgm2 else plain).values()
    gap = {name: abs(float(value) - float(reference[name])) for name, value in alone["torque_scale"].values().items()}
    spread = {name: float(np.hypot(read.spread.get(name, 0.0), gap[name])) for name in gap}
    return replace(read, unit_scale=gamma, spread=spread)


def _stands_out(plain: FrictionSolution, alone: FrictionSolution, name: str, rate: float, spec: DriveConstants) -> bool:
    """The solution with constant ``name`` explains the window ``DECISIVE_Z`` stds better, read within ``PLAUSIBLE``."""
    relative = float(alone.term(name)[0]) / (spec.inertia_kgm2 if name == "inertia" else 1.0)
    return bool(
        np.isfinite(relative)
        and alone.term_std(name)[0] > 0  # else the window cannot tell it from FDJ (``eta_search.solved_terms``)
        and abs(relative) < PLAUSIBLE[name]
        and equation_z(plain, alone, rate) > DECISIVE_Z
    )


def _reading(
    window: RotaryWindow, drive: DriveConstants, name: str, first: FrictionSolution
) -> tuple[DriveReading, FrictionSolution]:
    """Constant ``name``, solved again on the corrected window until nothing is left, its std ΔJ's with the
    kernel's (``kernel_inertia_std``); and the last solution (its likelihood)."""
    settings, std = replace(BESIDE, **{name: True}), float(first.term_std(name)[0])
    kernel = kernel_inertia_std(window.sample_rate_hz, drive) if name == "inertia" else 0.0
    read, left = DriveReading(spec=drive, stds={FIELDS[name]: float(np.hypot(std, kernel))}), first
    for _ in range(ITERATIONS + 1):
        read = read.added(left)
        left = _solve(read.corrected(window), read.drive_as_read, settings)
        if abs(float(left.term(name)[0])) < SETTLED * std:  # ΔJ is linear: settled at once; γ within a few
            break
    return read, left


def kernel_inertia_std(rate_hz: float, spec: DriveConstants) -> float:
    """The std [kg·m²] the reconstruction's kernel at ``rate_hz`` adds to ΔJ (``KERNEL_INERTIA_SHARE``)."""
    return KERNEL_INERTIA_SHARE * (1_000.0 / rate_hz) ** 2 * spec.inertia_kgm2


def _plain(window: RotaryWindow, read: DriveReading) -> dict[str, float]:
    solved = _solve(read.corrected(window), read.drive_as_read, SolveSettings())
    return {name: float(value) for name, value in solved.values().items()}


def _with_spread(window: RotaryWindow, read: DriveReading) -> DriveReading:
    """``read`` with, per target, half the change of the plain solution across each read constant ± its std, in
    quadrature."""
    spread = {"FDJ": 0.0, "eta_O": 0.0}
    for key, std in read.stds.items():
        low, high = (_plain(window, replace(read, **{key: getattr(read, key) + d})) for d in (-std, std))
        spread = {target: float(np.hypot(spread[target], (high[target] - low[target]) / 2)) for target in spread}
    return replace(read, spread=spread)


def drive_constants_note(read: DriveReading) -> list[Note]:
    """The constants, and the story of a current in other units, for the result's notes."""
    notes = []
    constants = _constants_note(read)
    if constants is not None:
        notes.append(Note(code="drive_constants", text=constants))
    if read.unit_scale:
        kt = read.spec.torque_constant_nm_per_a
        notes.append(
            Note(
                code="current_units",
                parameter="current_a",
                text=(
                    f"Eq. 5.1 balances the window as well with the motor giving {1 + read.unit_scale:.3g}x the "
                    f"document's "
                    f"k_T·I (a k_T of {(1 + read.unit_scale) * kt:.3g} N·m/A against its {kt:g}), which no drive "
                    f"departs by: "
                    "the actuator's document may not be this actuator's, or the current is logged in other units (RMS "
                    "for "
                    "amplitude?); the stds include what that reading would change"
                ),
            )
        )
    return notes


def _constants_note(read: DriveReading) -> str | None:
    found = []
    if read.torque_scale:
        found.append(
            f"the motor gives {read.torque_factor:.4f} ± {read.stds['torque_scale']:.4f} times "
            "the document's k_T·I (k_T "
            "moves with the magnets' temperature, a current sensor has a gain error)"
        )
    if read.inertia_kgm2:
        found.append(
            f"the inertia at the motor is {read.inertia_factor:.4f} ± "
            f"{read.stds['inertia_kgm2'] / read.spec.inertia_kgm2:.4f} times the document's J_M"
        )
    if not found:
        return None
    if read.alternative is not None:
        found.append(
            f"or, about as likely, the inertia at the motor is {read.alternative.inertia_factor:.3f} times the "
            "document's J_M (the window tells the two apart too little: the stds include what reading that instead "
            "would change)"
        )
    used = "the first" if read.alternative is not None else "it"
    return (
        "; ".join(found) + f". Every estimator read the window with {used}, and the stds include its "
        "uncertainty; read with the document's constants, the load and inertia it moves would have passed for friction"
    )
