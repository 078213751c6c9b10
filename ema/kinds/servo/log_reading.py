"""A servo's window made ready: its document completed by the log, its controller checked, its motion read.

- The controller's constants the document leaves out are the log's (``ema-window/1`` ``constants``); one both
  give differently is refused naming it, and one neither gives is refused naming the document's field.
- The log is the controller's own: its rate must be the controller's (within ``RATE_TOLERANCE``).
- The position sensor's step is the document's, else the smallest step the log's position takes (0: a sensor
  without one, where fewer than ``MIN_QUANTIZED`` of the steps are whole multiples of it).
- The command is recomputed from the set point and the position with the document's controller: a log whose
  command does not follow it (RMS beyond ``CONTROLLER_TOLERANCE`` of the command's) was run under another
  controller, and the window's own simulations would not be its (note ``controller_mismatch``).
  The command is linear in the loop's two gains, so a least-squares solution reads the gains the log's command
  does follow (``log_loop``); where they reproduce it, the note says them beside the document's.
- The loop the window is simulated with, and whose gains set the loop's bandwidth, is the one the log ran: the
  document's gains, or, where the log does not follow them but follows others, those. Simulations at gains the
  loop did not run would move otherwise, and the physics solution's bias read on them, subtracted from the window's
  solution (``ema.estimate.assess``), would not be the window's. The note says both pairs.
- A log's command may hold more than its controller's: an excitation added for identification, a feed-forward,
  a disturbance the drive adds. Where no gains reproduce the whole command, the command is the document's loop
  plus an added command, the logged one less the loop's at every sample (``added_command``), unless the loop's
  own terms explain most of that departure (then it is a gain's, the sign's or the filter's error, and the
  note says no gains reproduce the log); where the document's gains are off as well, the gains most samples
  follow (``trimmed_loop``: a least-squares solution without the samples an added pulse holds). Every simulation adds
  the added command to its controller's, the training runs as well as the check: a loop left to its controller
  would move otherwise than the log's. The note ``added_command`` says so, with its size.
- The loop's bandwidth (the document's, else the natural frequency √(kp·kv·g/M) of the position loop, M from a
  first solution) sets the inverse model's filters (``ema.kinds.servo.inverse``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.least_squares import coefficients
from ema.estimate.stats import below_zero, rms, robust_variance
from ema.kinds.servo.closed_loop import ServoLoop, ServoRuns, simulate_servo
from ema.kinds.servo.inverse import Motion, inverse_columns, load_motion, refuse_still, solve_inverse
from ema.model.actuator import ServoActuator
from ema.model.checks import InputError
from ema.model.servo import Servo
from ema.model.window import ServoWindow

RATE_TOLERANCE = 0.01
CONTROLLER_TOLERANCE = 0.02
MIN_QUANTIZED = 0.9
MIN_LOOP_SAMPLES = 10  # unclipped samples a log's own loop gains are read from, at least
# A sample whose command departs from the loop's by more than this many robust stds of the departures holds a
# command the loop does not give (a pulse of an excitation stands out by hundreds; a gain's rounding by none).
ADDED_MADS = 6.0
TRIMMED_SOLVES = 4  # least-squares solutions of the loop's gains, each without the samples the last one left far off
# A departure from the loop's command that the loop's own terms explain beyond this share of its energy is the
# loop's error (a gain, the sign, the filter), not a command added to it.
MAX_LOOP_SHARE = 0.5
PROVISIONAL_BANDWIDTH_SHARE = 0.02  # a first solution's loop bandwidth, as a share of the rate (20 Hz at 1 kHz)
POSITIVE = ("mass_kg", "fdj_n", "viscous_ns_per_m", "viscous_up_ns_per_m", "viscous_down_ns_per_m")


@dataclass(frozen=True)
class ServoPrepared:
    window: ServoWindow
    servo: Servo  # the document's section completed by the log
    loop: ServoLoop
    motion: Motion
    force_n: np.ndarray  # the drive's force less the external load, over the motion's samples
    loaded: bool  # the window carries an external load
    bandwidth_hz: float
    effects: dict[str, float]  # the document's adopted effects (name -> its nonlinear constant)
    notes: list[Note]
    disturbed: np.ndarray | None = None  # (rows,) the decimated rows a force the log lacks disturbs (calibration's)
    added_command: np.ndarray | None = None  # (N,) [the command's unit] the log's command beyond its controller's

    def closed_loop(self, lanes: np.ndarray, phase: np.ndarray | None = None) -> ServoRuns:
        """Each row of ``lanes`` (L, ``LANE_PARAMETERS``) run over the window as its log ran: its set point, its
        load, its added command, from its first state (position and speed), its sensor at ``phase`` (L,)."""
        s, rate = self.window.signals, self.window.sample_rate_hz
        start = (float(s["position_m"][0]), float((s["position_m"][1] - s["position_m"][0]) * rate))
        return simulate_servo(
            s["set_point_m"],
            lanes,
            self.loop,
            load_n=s.get("load_n"),
            added_command=self.added_command,
            start=start,
            phase=phase,
        )


def completed(actuator: ServoActuator, window: ServoWindow) -> Servo:
    """The document's servo section with the log's constants; InputError naming what neither gives."""
    assert actuator.servo is not None  # the kind's own section (ema.kinds)
    servo = actuator.servo.with_constants(window.constants, "window.constants")
    missing = servo.missing()
    if missing:
        raise InputError(f"actuator.servo.{missing[0]}", "neither the document nor the log gives it")
    return servo


def resolution(position_m: np.ndarray) -> float:
    """The position sensor's step: the smallest step the log takes, where the steps are its whole multiples."""
    steps = np.abs(np.diff(position_m))
    moving = steps[steps > 1e-12]
    if len(moving) < 10:
        return 0.0
    step = float(np.min(moving))
    multiples = moving / step
    whole = np.abs(multiples - np.round(multiples)) < 0.02
    return step if np.mean(whole) >= MIN_QUANTIZED else 0.0


@dataclass(frozen=True)
class LoopGains:
    """A position loop's two gains, u = kv·(kp·(q_ref − q) − dq), and how far from the logged command they leave."""

    position_gain_per_s: float  # kp
    speed_gain_per_mps: float  # kv [the command's unit per m/s]
    off_share: float  # the RMS of the logged command less theirs, as a share of the command's RMS


def _filtered_speed(taps: list[float], position_m: np.ndarray, rate_hz: float) -> np.ndarray:
    """The controller's speed [m/s]: the position through its filter ``taps``, differenced (its first sample
    held before the log)."""
    padded = np.concatenate([np.full(len(taps) - 1, position_m[0]), position_m])
    filtered = np.convolve(padded, np.asarray(taps), mode="valid")
    return np.diff(filtered, prepend=filtered[0]) * rate_hz


def _command_limit(servo: Servo) -> float:
    """The command's saturation, ± in its unit (inf: none)."""
    return servo.command_limit if servo.command_limit is not None else np.inf


def commanded(servo: Servo, set_point_m: np.ndarray, position_m: np.ndarray, rate_hz: float) -> np.ndarray:
    """The command [its unit] the document's controller gives at each sample of the log."""
    assert servo.position_gain_per_s is not None and servo.speed_gain_per_mps is not None  # completed
    gains = LoopGains(servo.position_gain_per_s, servo.speed_gain_per_mps, 0.0)
    command = _loop_law(servo, gains, set_point_m, position_m, rate_hz)
    limit = _command_limit(servo)
    return np.clip(command, -limit, limit)


def _loop_law(
    servo: Servo, gains: LoopGains, set_point_m: np.ndarray, position_m: np.ndarray, rate_hz: float
) -> np.ndarray:
    """kv·(kp·(q_ref − q) − dq) at each sample, before the limit, dq through the document's speed filter."""
    speed = _filtered_speed(servo.speed_filter, position_m, rate_hz)
    return gains.speed_gain_per_mps * (gains.position_gain_per_s * (set_point_m - position_m) - speed)


def _logged_command(servo: Servo, window: ServoWindow) -> np.ndarray:
    """The command [its unit] the log recorded: its drive force over the drive's gain."""
    assert servo.drive_gain_n_per_unit is not None  # completed
    return window.signals["drive_force_n"] / servo.drive_gain_n_per_unit


def document_loop(servo: Servo, window: ServoWindow) -> LoopGains:
    """The document's gains, and how far the logged command is from what they give; past the filter's and the
    difference's start (as many samples as taps), which read positions from before the window: a log cut from a
    longer one starts in motion."""
    s, start = window.signals, len(servo.speed_filter)
    logged = _logged_command(servo, window)
    off = rms(logged[start:] - commanded(servo, s["set_point_m"], s["position_m"], window.sample_rate_hz)[start:])
    assert servo.position_gain_per_s is not None and servo.speed_gain_per_mps is not None  # completed
    return LoopGains(servo.position_gain_per_s, servo.speed_gain_per_mps, float(off / max(rms(logged), 1e-300)))


def log_loop(servo: Servo, window: ServoWindow, among: np.ndarray | None = None) -> LoopGains | None:
    """The gains the logged command follows through the document's speed filter: the command is linear in
    kv·kp and kv, so least squares over the samples the limit does not clip (past the filter's start; of those
    ``among`` (N,) marks, where given) reads them. None where it reads no stable loop (gains not both positive,
    or too few samples to read two from)."""
    start = len(servo.speed_filter)
    logged = _logged_command(servo, window)[start:]
    limit = _command_limit(servo)
    free = np.abs(logged) < limit
    if among is not None:
        free &= among[start:]
    if free.sum() < MIN_LOOP_SAMPLES:
        return None
    columns = _loop_columns(servo, window)[free]
    stiffness, kv = coefficients(columns, logged[free])
    if not (stiffness > 0 and kv > 0):
        return None
    off = rms(logged[free] - columns @ np.array([stiffness, kv]))
    return LoopGains(float(stiffness / kv), float(kv), float(off / max(rms(logged[free]), 1e-300)))


def _loop_columns(servo: Servo, window: ServoWindow) -> np.ndarray:
    """(N − taps, 2) the loop's own terms past the speed filter's start: the position error and the filtered speed
    negated, of which the command is kv·kp times the first plus kv times the second."""
    s, start = window.signals, len(servo.speed_filter)
    speed = _filtered_speed(servo.speed_filter, s["position_m"], window.sample_rate_hz)[start:]
    return np.column_stack([(s["set_point_m"] - s["position_m"])[start:], -speed])


def departure(servo: Servo, window: ServoWindow, gains: LoopGains) -> np.ndarray:
    """(N,) the logged command less the loop's with ``gains``: what the loop does not give. 0 where both sit at the
    same limit (the loop gives it), and before the speed filter's start (it reads positions from before the log)."""
    s, limit = window.signals, _command_limit(servo)
    loop = _loop_law(servo, gains, s["set_point_m"], s["position_m"], window.sample_rate_hz)
    logged = _logged_command(servo, window)
    out = logged - loop
    out[(np.abs(logged) >= limit) & (np.clip(loop, -limit, limit) == logged)] = 0.0
    out[: len(servo.speed_filter)] = 0.0
    return out


def loops_own(values: np.ndarray) -> np.ndarray:
    """(N,) the samples whose command the loop gives: departing by at most ``ADDED_MADS`` robust stds."""
    spread = float(np.sqrt(robust_variance(values)))
    return np.abs(values - np.median(values)) <= ADDED_MADS * spread + 1e-12 * float(np.max(np.abs(values)))


def trimmed_loop(servo: Servo, window: ServoWindow) -> LoopGains | None:
    """The gains most of the logged command follows: ``log_loop`` solved ``TRIMMED_SOLVES`` times more, each without
    the samples the last solution's gains leave beyond ``ADDED_MADS`` robust stds (an added command's)."""
    gains = log_loop(servo, window)
    for _ in range(TRIMMED_SOLVES - 1):
        if gains is None:
            return None
        gains = log_loop(servo, window, loops_own(departure(servo, window, gains)))
    return gains


@dataclass(frozen=True)
class AddedCommand:
    """A log's command read as a loop's plus a command added to it."""

    gains: LoopGains
    values: np.ndarray  # (N,) [the command's unit]


def loop_share(servo: Servo, window: ServoWindow, values: np.ndarray) -> float:
    """The share of ``values``' energy (N,) that the loop's own terms (the position error and the filtered speed,
    at any gains) explain by least squares: near 1 where ``values`` is a gain's, the sign's or the filter's error."""
    columns, target = _loop_columns(servo, window), values[len(servo.speed_filter) :]
    solved = coefficients(columns, target)
    left = float(np.sum((target - columns @ solved) ** 2))
    return 1.0 - left / max(float(np.sum(target**2)), 1e-300)


def added_command(servo: Servo, window: ServoWindow, gains: LoopGains | None) -> AddedCommand | None:
    """The log's command as the loop with ``gains`` plus an added one, the departure (``departure``), where the loop's
    own terms explain at most ``MAX_LOOP_SHARE`` of it (else it is the loop's error, not a command added to it) and
    the logged command stays within the document's limit (no command added before the limit passes it); else
    None."""
    limit = _command_limit(servo)
    if gains is None or np.any(np.abs(_logged_command(servo, window)) > limit * (1 + 1e-9)):
        return None
    values = departure(servo, window, gains)
    if not np.any(values) or loop_share(servo, window, values) > MAX_LOOP_SHARE:
        return None
    return AddedCommand(gains, values)


@dataclass(frozen=True)
class FollowedLoop:
    """The loop a log ran, the command added to it (None: the loop's alone), and the note that says which."""

    gains: LoopGains
    added: AddedCommand | None = None
    note: Note | None = None


def followed_loop(servo: Servo, window: ServoWindow) -> FollowedLoop:
    """The loop the log follows: the document's gains where the log follows them within ``CONTROLLER_TOLERANCE``,
    else those its command follows (``log_loop``) where they do, else one of them plus a command added to it
    (``added_command``: the document's first); and the note (``controller_mismatch``, ``added_command``) where the
    document's gains alone do not give the command."""
    document = document_loop(servo, window)
    if document.off_share <= CONTROLLER_TOLERANCE:
        return FollowedLoop(document)
    differs = (
        f"the logged command differs from what the document's controller gives by {100 * document.off_share:.1f} % RMS"
    )
    own = log_loop(servo, window)
    if own is not None and own.off_share <= CONTROLLER_TOLERANCE:
        text = (
            f"{differs}, and follows kp {own.position_gain_per_s:.5g} 1/s, kv {own.speed_gain_per_mps:.5g} within "
            f"{100 * own.off_share:.1f} % where the document with the log's constants has kp "
            f"{document.position_gain_per_s:.5g}, kv {document.speed_gain_per_mps:.5g} (a gain, the drive gain or "
            "the filter is not the log's): the window is simulated with the gains it followed"
        )
        return FollowedLoop(own, note=Note(code="controller_mismatch", parameter="drive_force_n", text=text))
    added = added_command(servo, window, document) or added_command(servo, window, trimmed_loop(servo, window))
    if added is not None:
        return FollowedLoop(added.gains, added, _added_note(servo, window, added, document))
    text = (
        f"{differs}, and no gains of it reproduce it (its filter, limit or sign is not the log's): the "
        "window's own simulations are not its"
    )
    return FollowedLoop(document, note=Note(code="controller_mismatch", parameter="drive_force_n", text=text))


def _added_note(servo: Servo, window: ServoWindow, added: AddedCommand, document: LoopGains) -> Note:
    """``added_command``: the added command's size, and whose loop it is added to."""
    logged, values = _logged_command(servo, window), added.values
    gains = added.gains
    loop = (
        "the document's controller"
        if gains is document
        else f"a loop of kp {gains.position_gain_per_s:.5g} 1/s, kv {gains.speed_gain_per_mps:.5g} (the document's: "
        f"kp {document.position_gain_per_s:.5g}, kv {document.speed_gain_per_mps:.5g})"
    )
    text = (
        f"the logged command is {loop} plus a command added to it (an excitation, a feed-forward, a disturbance the "
        f"drive adds): {rms(values):.3g} RMS, {100 * rms(values) / max(rms(logged), 1e-300):.0f} % of the command's, "
        f"peak {float(np.max(np.abs(values))):.3g} in the command's unit. Every simulation adds it to the controller's"
    )
    return Note(code="added_command", parameter="drive_force_n", text=text)


def bandwidth(servo: Servo, mass_kg: float, gains: LoopGains) -> float:
    """The position loop's bandwidth [Hz]: the document's, else the natural frequency √(kp·kv·g/M)/2π of the loop
    with ``gains`` (those the log follows: ``followed_loop``)."""
    if servo.bandwidth_hz is not None:
        return servo.bandwidth_hz
    assert servo.drive_gain_n_per_unit  # completed
    stiffness = gains.position_gain_per_s * gains.speed_gain_per_mps * servo.drive_gain_n_per_unit
    return float(np.sqrt(stiffness / mass_kg) / (2 * np.pi))


def document_effects(servo: Servo) -> dict[str, float]:
    """The effects the document adopted (``ema calibrate``), as the inverse model's columns name them."""
    return {**servo.effects, **({"viscous_down": 1.0} if servo.viscous_down_ns_per_m is not None else {})}


def refuse_reversed_signs(values: dict[str, float], stds: dict[str, float]) -> None:
    """Raise unless the solution reads a positive mass and a friction that opposes the motion (no ``POSITIVE``
    constant ``below_zero``): a force that pushes against the acceleration, or aids the motion it should brake,
    is a log whose force and position disagree in sign or in time, and no constant read from it means anything."""
    wrong = below_zero({name: values[name] for name in POSITIVE if name in values}, stds)
    if wrong:
        read = ", ".join(f"{name} {values[name]:.4g} ± {stds[name]:.2g}" for name in wrong)
        raise InputError(
            "signals.drive_force_n",
            f"the solution reads {read}: the force pushes against the motion it drives (a force or position logged "
            "with the other sign, the log map's sign, or a log played backwards)",
        )


def _window_motion(position_m: np.ndarray, rate_hz: float, bandwidth_hz: float, step_m: float) -> Motion:
    """The logged load's motion (``load_motion``), refused where it never leaves its sensor's noise."""
    motion = load_motion(position_m, rate_hz, bandwidth_hz, step_m)
    refuse_still(motion, position_m)
    return motion


def prepare_servo(window: ServoWindow, actuator: ServoActuator) -> ServoPrepared:
    """The window ready for its physics (module docstring); InputError naming what cannot be read."""
    servo = completed(actuator, window)
    rate = servo.controller_rate_hz or window.sample_rate_hz
    if abs(window.sample_rate_hz / rate - 1.0) > RATE_TOLERANCE:
        raise InputError(
            "sample_rate_hz",
            f"{window.sample_rate_hz:g} Hz, but the controller runs at {rate:g} Hz: a servo's log is its controller's",
        )
    s = window.signals
    load = s.get("load_n", np.zeros(window.n_samples))
    step = servo.position_resolution_m if servo.position_resolution_m is not None else resolution(s["position_m"])
    mass = servo.mass_kg
    if mass is None and servo.bandwidth_hz is None:  # a first solution, for the loop's natural frequency
        first = _window_motion(s["position_m"], rate, PROVISIONAL_BANDWIDTH_SHARE * rate, step)
        forces = (s["drive_force_n"] - load)[first.samples]
        mass = solve_inverse(forces, inverse_columns(first), first).values["mass_kg"]
    followed = followed_loop(servo, window)
    gains = followed.gains
    loop_hz = bandwidth(servo, max(float(mass or 1.0), 1e-6), gains)
    motion = _window_motion(s["position_m"], rate, loop_hz, step)
    assert servo.drive_gain_n_per_unit  # completed
    loop = ServoLoop(
        position_gain_per_s=gains.position_gain_per_s,
        speed_gain_per_mps=gains.speed_gain_per_mps,
        drive_gain_n_per_unit=servo.drive_gain_n_per_unit,
        command_limit=_command_limit(servo),
        period_s=1.0 / rate,
        resolution_m=step,
        taps=tuple(servo.speed_filter),
    )
    notes = [followed.note] if followed.note is not None else []
    loaded = bool(np.any(load != 0.0))
    if not loaded:
        notes.append(
            Note(code="no_load", parameter="eta_O", text="the window carries no external load: η_O is not shown")
        )
    return ServoPrepared(
        window, servo, loop, motion, (s["drive_force_n"] - load)[motion.samples], loaded, loop_hz,
        document_effects(servo), notes, added_command=None if followed.added is None else followed.added.values,
    )  # fmt: skip
