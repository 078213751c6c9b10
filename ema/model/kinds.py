"""Each kind of actuator as its documents see it: the signals of its windows, the section of its actuator
document, what its log map may name and in which units, and the unit its friction is read in.

One table (``KINDS``): the window, the actuator document and the log map ask it, and nothing compares a kind
with a literal. How each kind is read, simulated and calibrated is declared beside it in ``ema.kinds``.

- **rotary**: the thesis's elevator EMA, a current-piloted motor and a gear train; friction at the motor
  shaft (N·m).
- **linear**: a ball screw turned by a stepper, logged by a rig at its own rate; friction at the motor
  shaft (N·m), the drive's current read through what ``ema calibrate`` learned.
- **servo**: a linear axis whose drive takes a force command from a known position controller, everything
  logged on the load side (positions in m, forces in N): friction on the load (N).
- **geared**: a DC motor fed by PWM from its supply, a gear train and its own position loop, logged at the output
  shaft (angles in rad, the duty it applied, the supply) swinging a load of known mass and arm: friction at the
  output shaft (N·m).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

from ema.model.geared import GEARED_CONSTANTS
from ema.model.servo import SERVO_CONSTANTS
from ema.model.units import units_of


@dataclass(frozen=True)
class Role:
    """A quantity a log map may name: the window signal it becomes, whose name says its unit."""

    signal: str
    required: bool = True

    @property
    def units(self) -> Mapping[str, float]:
        """The units the log may write it in: unit -> factor to the signal's own (``ema.model.units.units_of``)."""
        return units_of(self.signal)


def _roles(optional: tuple[str, ...] = (), **signals: str) -> Mapping[str, Role]:
    """Each log-map role -> the window signal it becomes; ``optional``: roles a log may go without."""
    return MappingProxyType({role: Role(signal, role not in optional) for role, signal in signals.items()})


@dataclass(frozen=True)
class KindFacts:
    name: str
    summary: str
    section: str  # the actuator document's field that holds this kind's constants
    roles: Mapping[str, Role]  # log-map role -> signal; "position" may be given as "error" (set point less it)
    nominal_given: bool = False  # the document's author gives the nominal health (else ema calibrate learns it)
    static_friction: bool = False  # a window can show a break-away (FSJ)
    load_side: bool = False  # the log is on the load side: FDJ is the load's friction force
    recorded: tuple[str, ...] = ()  # the section's fields a log may record beside its signals (``constants``)
    measured: tuple[str, ...] = ()  # the signals its answer is read from: a dead one refuses a window
    simulated: bool = False  # ema simulate draws its windows (its simulator runs from a document alone)
    # How long the windows a recording of this kind is cut into unless told (the thesis's windows: a few commands of
    # the elevator each); None: a log is one window (a rig's run, a controller's log).
    cut_s: float | None = None

    def recorded_field(self, name: str) -> str | None:
        """Why a log of this kind cannot record the constant ``name`` (None: it can)."""
        if name in self.recorded:
            return None
        if not self.recorded:
            return f"a {self.name} actuator's log records no constants"
        return f"a {self.name} actuator's log records {', '.join(self.recorded)}, under its document's names"

    @property
    def friction_unit(self) -> str:
        """The unit FDJ is read in: a force on the load for a kind logged there, else a torque at the motor shaft."""
        return "N" if self.load_side else "N·m"

    @property
    def signals(self) -> tuple[str, ...]:
        """A window's signals, in order: its required roles'."""
        return tuple(role.signal for role in self.roles.values() if role.required)

    @property
    def optional_signals(self) -> tuple[str, ...]:
        return tuple(role.signal for role in self.roles.values() if not role.required)

    @property
    def all_signals(self) -> tuple[str, ...]:
        return self.signals + self.optional_signals

    def document_field(self, name: str) -> str:
        """The actuator document's field an answer's value ``name`` is held to (``FDJ`` -> ``fdj_nm`` or ``fdj_n``,
        ``eta_O`` -> ``eta_o``); a constant is its own field's name."""
        return {"FDJ": self.friction_field("fdj"), "eta_O": "eta_o", "eta_A": "eta_a", "FSJ": "fsj_nm"}.get(name, name)

    def friction_field(self, prefix: str) -> str:
        """The document's field of a friction value in this kind's unit (``fdj`` -> ``fdj_nm`` or ``fdj_n``)."""
        return f"{prefix}_{FRICTION_SUFFIX[self.friction_unit]}"


FRICTION_SUFFIX = MappingProxyType({"N·m": "nm", "N": "n"})

_ROTARY = KindFacts(
    name="rotary",
    cut_s=0.5,
    summary="a current-piloted motor and a gear train to a surface",
    section="drive",
    roles=_roles(
        set_point="command_deg",
        position="position_deg",
        motor_speed="motor_speed_radps",
        current="current_a",
        load="hinge_moment_nm",
    ),
    nominal_given=True,
    static_friction=True,
    measured=("position_deg", "motor_speed_radps", "current_a"),
    simulated=True,
)
_LINEAR = KindFacts(
    name="linear",
    summary="a ball screw turned by a stepper, its current read through what ema calibrate learned",
    section="screw",
    roles=_roles(set_point="command_mm", position="position_mm", current="current_a", load="load_n"),
    measured=("position_mm", "current_a"),
)
_SERVO = KindFacts(
    name="servo",
    summary="a linear axis driven by a force command from a known position controller, logged on the load side",
    section="servo",
    roles=_roles(
        set_point="set_point_m", position="position_m", force="drive_force_n", load="load_n", optional=("load",)
    ),
    load_side=True,
    recorded=SERVO_CONSTANTS,
    measured=("position_m", "drive_force_n"),
)
_GEARED = KindFacts(
    name="geared",
    summary="a DC motor, a gear train and its own position loop, logged at the output shaft, swinging a known load",
    section="geared",
    roles=_roles(
        set_point="set_point_rad",
        position="position_rad",
        duty="duty_ratio",
        supply="supply_v",
        motor_on="motor_on_flag",
        optional=("motor_on",),
    ),
    recorded=GEARED_CONSTANTS,
    measured=("position_rad", "duty_ratio"),  # a regulated supply may read one value throughout
)
KINDS: Mapping[str, KindFacts] = MappingProxyType({k.name: k for k in (_ROTARY, _LINEAR, _SERVO, _GEARED)})
DEFAULT_KIND = _ROTARY.name
KIND_NAMES = tuple(KINDS)
ALL_SIGNALS = tuple(dict.fromkeys(name for k in KINDS.values() for name in k.all_signals))


def kinds_with(fact: str) -> tuple[str, ...]:
    """The names of the kinds whose ``fact`` (a field of ``KindFacts``) is set: what a command serves."""
    return tuple(name for name, kind in KINDS.items() if getattr(kind, fact))


def facts(kind: str) -> KindFacts:
    return KINDS[kind]


def kind_of_signals(names: Iterable[str]) -> KindFacts | None:
    """The kind whose window carries exactly these signals (its own, and any of its optional ones), or None."""
    given = set(names)
    for kind in KINDS.values():
        if set(kind.signals) <= given <= set(kind.all_signals):
            return kind
    return None


def nearest_kind(names: Iterable[str]) -> KindFacts:
    """The kind these signals come closest to (most of its own signals among them): what a refusal names."""
    given = set(names)

    def closeness(kind: KindFacts) -> tuple[int, int]:
        return len(given & set(kind.signals)) - len(given - set(kind.all_signals)), -len(kind.signals)

    return max(KINDS.values(), key=closeness)
