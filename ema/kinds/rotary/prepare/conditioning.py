"""A logged window made ready for the pipeline: isolated glitches repaired, a bounded number of
samples, its signals checked to tell one story (``ema.kinds.rotary.prepare.consistency``: a sign, unit or
sample rate the log got wrong is refused, naming the field), its sensors on one clock
(``ema.kinds.rotary.prepare.alignment``), what it shows beyond the actuator document's model read and undone
(``ema.kinds.rotary.prepare.departures.read``: a sensor off zero, the drive's k_T and J_M, the hinge moment's
gain, the viscous coefficient), how likely its hinge moment is out of step
(``ema.kinds.rotary.prepare.step_lag``), and what was done to it.

A sensor's sample that jumps away from both neighbours and straight back (an EMI spike, a bit
error) is no measurement, nor is a burst of a few of them (``MAX_GLITCH_RUN``, ``MAX_GLITCH_S``: at
1 kHz, a current pulse as the motion reverses looks like a 2–3 sample burst), and a few of them
move every answer. A run is a glitch when all its samples stand more than ``GLITCH_STDS`` noise stds
beyond both flanking samples, which agree with each other, and more than ``GLITCH_ACTIVITY`` times
the median step around them and the steps into them: a 1 kHz log's fastest legitimate turns stand
far out in noise stds, but not against the steps around them. It is replaced by the line between
its flanks, before the averaging below would smear it, and counted in the result. (A sample beyond
the window format's plausible range is refused before this, naming it.)

Logs come at 1–100 kHz and last 0.1–10 s. The simulator runs at 1 µs whatever the log rate, but
every later stage costs per logged sample, and a batch of simulations records every sample of every
simulation. So the window is averaged over f adjacent samples first: interval means of interval
means are the interval means of the longer intervals, exactly, which is also what the simulations
record at the lower rate. ``f`` keeps the rate at or below ``MAX_RATE_HZ`` (the 2 ms reconstruction
needs no more) and the samples at or below ``RESAMPLED_MAX_SAMPLES``: memory and time grow at most linearly
with the duration, and are bounded. A window of up to 10 s is kept at ``KERNEL_FREE_RATE_HZ`` or more
where it was logged so: below it the 2 ms kernel spans few samples and reads J_M low
(``ema.kinds.rotary.prepare.departures.drive_constants``), and a long window's stds are small enough to show it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.stats import white_noise_std
from ema.kinds.rotary.prepare.alignment import Lags, aligned
from ema.kinds.rotary.prepare.consistency import Consistency
from ema.kinds.rotary.prepare.departures.aircraft_check import TOLERANCE, aircraft_note, check_against_aircraft
from ema.kinds.rotary.prepare.departures.drive_constants import KERNEL_FREE_RATE_HZ, DriveReading, drive_constants_note
from ema.kinds.rotary.prepare.departures.hinge_gain import hinge_gain_note
from ema.kinds.rotary.prepare.departures.read import Departures, Known, history_note, read_departures
from ema.kinds.rotary.prepare.departures.viscosity import viscosity_note
from ema.kinds.rotary.prepare.departures.zero_offset import offset_note
from ema.kinds.rotary.prepare.stale import Stale, line_between_flanks, stale_note, without_stale
from ema.kinds.rotary.prepare.step_lag import StepLag, step_lag, step_lag_note
from ema.kinds.rotary.prepare.verdict import check_consistency, kinematics_note
from ema.kinds.rotary.simulator.batch import COMMAND_MARGIN_DEG
from ema.model.actuator import RotaryActuator
from ema.model.bounds import DEFAULT_SAMPLE_RATE_HZ
from ema.model.noise import NOISY_SIGNALS
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

MAX_RATE_HZ = DEFAULT_SAMPLE_RATE_HZ
RESAMPLED_MAX_SAMPLES = int(10.0 * KERNEL_FREE_RATE_HZ)  # a 10 s window (0.1–10 s are answered) at the unbiased rate
GLITCH_STDS = 30.0
GLITCH_ACTIVITY = 5.0
ACTIVITY_HALF_WIDTH = 10  # samples each side whose median step sets the signal's local activity
MAX_GLITCH_RUN = 3  # adjacent samples; a longer excursion may be a real event ...
MAX_GLITCH_S = 3e-4  # ... and so may a shorter one at a low rate: a current pulse at a reversal lasts 2–3 ms


@dataclass(frozen=True)
class Prepared:
    document: RotaryActuator  # the actuator's document the window is read with
    factor: int  # adjacent samples averaged into one
    original_samples: int
    original_rate_hz: float
    command_clipped_fraction: float  # share of command samples past the end stops (the actuator saturates)
    glitches: dict[str, int]  # per sensor, samples of glitches replaced by the line between their flanks
    consistency: Consistency  # how its signals relate: the kinematic gain, the loop, Eq. 5.1's readings
    lags: Lags  # how late the current (behind the speed) and the hinge moment were logged, undone
    departures: Departures  # what it shows beyond the document's model (an offset, k_T and J_M, g, C), undone
    step: StepLag  # how likely its hinge moment is out of step, where that is too unclear to refuse it
    stale: Stale = field(default_factory=Stale)  # sensors that repeated one value while the shaft slid: cut out

    @property
    def window(self) -> RotaryWindow:
        """What the pipeline processes: averaged, aligned, corrected for its departures."""
        return self.departures.window

    @property
    def drive_as_read(self) -> DriveConstants:
        """What every reconstruction and solution of the window reads it with: the document's, J_M and C as read."""
        return self.departures.drive_as_read


def averaging_factor(n_samples: int, rate_hz: float) -> int:
    """The smallest f with rate / f ≤ MAX_RATE_HZ and n / f ≤ RESAMPLED_MAX_SAMPLES."""
    return max(1, math.ceil(rate_hz / MAX_RATE_HZ - 1e-9), math.ceil(n_samples / RESAMPLED_MAX_SAMPLES - 1e-9))


def glitch_floor(values: np.ndarray) -> float:
    """The least departure a glitch has: ``GLITCH_STDS`` noise stds (or quantization steps, for a log
    without visible noise, whose one-step flicker is no glitch)."""
    steps = np.abs(np.diff(values))
    resolution = float(steps[steps > 0].min()) if np.any(steps > 0) else 0.0
    return GLITCH_STDS * max(white_noise_std(values), resolution)


def glitch_starts(values: np.ndarray, run: int, floor: float) -> np.ndarray:
    """Where ``run`` adjacent samples all leave both flanking samples, which agree with each other, on
    the same side by more than ``floor`` and ``GLITCH_ACTIVITY`` times the median step around either
    flank and the steps into the flanks (module docstring): the index of each run's first."""
    n = len(values)
    if n < run + 2:
        return np.zeros(0, dtype=np.int64)
    first, last = values[: n - run - 1], values[run + 1 :]  # the flanks of the runs starting at 1 … n−run−1
    inner = np.stack([values[1 + j : n - run + j] for j in range(run)])
    jump = np.maximum(inner.min(axis=0) - np.maximum(first, last), np.minimum(first, last) - inner.max(axis=0))
    jump[np.abs(last - first) > jump] = 0.0  # the flanks must agree with each other
    steps, half = np.abs(np.diff(values)), ACTIVITY_HALF_WIDTH
    starts = [
        k + 1
        for k in np.flatnonzero(jump > floor)  # few: the activity is read only around these
        if 1 <= k < n - run - 2  # the steps into the flanks, and the median steps around them:
        and max(steps[k - 1], steps[k + run + 1]) * GLITCH_ACTIVITY < jump[k]  # a current pulse's are not
        and jump[k] > GLITCH_ACTIVITY * max(np.median(steps[max(0, j - half) : j + half + 1]) for j in (k, k + run))
    ]
    return np.array(starts, dtype=np.int64)


def repaired(window: RotaryWindow) -> tuple[RotaryWindow, dict[str, int]]:
    """``window`` with each sensor's glitches (runs of up to ``MAX_GLITCH_RUN`` samples and
    ``MAX_GLITCH_S``, but single samples at any rate) replaced by the line between their flanks, and
    how many samples were."""
    signals, counts = dict(window.signals), {}
    longest = min(MAX_GLITCH_RUN, max(1, int(MAX_GLITCH_S * window.sample_rate_hz + 1e-9)))
    for name in NOISY_SIGNALS:
        values, replaced = signals[name].copy(), 0
        floor = glitch_floor(values)
        for run in range(1, longest + 1):
            for start in glitch_starts(values, run, floor):
                values[start : start + run] = line_between_flanks(values, start, start + run)
                replaced += run
        if replaced:
            signals[name], counts[name] = values, replaced
    return (replace(window, signals=signals) if counts else window), counts


def prepare(
    window: RotaryWindow, actuator: RotaryActuator, spec_only: bool = False, known: Known | None = None
) -> Prepared:
    """Cut ``window`` to a stretch its sensors kept updating in (``ema.kinds.rotary.prepare.stale``), repair its
    glitches, average it down to the pipeline's sizes, check its signals agree
    (``ema.kinds.rotary.prepare.consistency``: InputError naming the field), put its sensors on one clock
    (``ema.kinds.rotary.prepare.alignment``), read what it shows beyond ``actuator``
    (``ema.kinds.rotary.prepare.departures.read``) and weigh whether its hinge moment is out of step
    (``ema.kinds.rotary.prepare.step_lag``); say what it found. ``spec_only`` skips the departures and the step:
    ``calibration`` reads the document's model alone and names what departs. ``known``: what other windows of
    the actuator read (``departures.read_departures``)."""
    logged, spec = window.n_samples, actuator.params
    window, stale = without_stale(window, spec)
    window, glitches = repaired(window)
    factor = averaging_factor(window.n_samples, window.sample_rate_hz)
    command = window.signals["command_deg"]
    clipped = float(np.mean(np.abs(command) > spec.end_stop_deg + COMMAND_MARGIN_DEG))
    if factor > 1:
        n = window.n_samples // factor * factor
        signals = {name: values[:n].reshape(-1, factor).mean(axis=1) for name, values in window.signals.items()}
        window = replace(window, signals=signals, sample_rate_hz=window.sample_rate_hz / factor)
    consistent = check_consistency(window, spec)
    window, lags = aligned(window, spec)
    airframe = actuator.airframe
    aircraft = check_against_aircraft(window, actuator.hinge, airframe.tolerance if airframe else TOLERANCE)
    read = (
        Departures(window, DriveReading(spec), aircraft=aircraft)
        if spec_only
        else read_departures(window, actuator, aircraft, known or Known())
    )
    rate = read.window.sample_rate_hz * factor
    # with the departures left in, a lag absorbs what they leave (an offset above all): the story is no test there
    step = StepLag() if spec_only else step_lag(read.window, read.drive_as_read)
    return Prepared(actuator, factor, logged, rate, clipped, glitches, consistent, lags, read, step, stale)


def widened(stds: dict[str, float], prepared: Prepared) -> dict[str, float]:
    """Each std with what conditioning could not settle (an offset's readings, a lag's band, the viscous
    coefficient's std: their spreads, per target) added in quadrature."""
    read = prepared.departures
    spreads = (
        read.offset.spread,
        prepared.lags.spread,
        read.drive.spread,
        read.hinge.spread,
        read.aircraft.spread,
        read.viscosity.spread,
        prepared.step.spread,
    )
    return {name: float(np.sqrt(std**2 + sum(s.get(name, 0.0) ** 2 for s in spreads))) for name, std in stds.items()}


def conditioning_done(prepared: Prepared) -> dict[str, Any]:
    """What conditioning did to the window, as the result's ``WindowInfo`` fields."""
    aircraft = prepared.departures.aircraft
    return {
        "command_clipped_fraction": prepared.command_clipped_fraction,
        "glitches_repaired": prepared.glitches,
        "stale_samples": prepared.stale.samples,
        "read_span": None if prepared.stale.span is None else list(prepared.stale.span),
        "kinematic_gain": prepared.consistency.travel_gain,
        "current_lag_s": prepared.lags.current_s,
        "hinge_lag_s": prepared.lags.hinge_s,
        "hinge_offset_nm": prepared.departures.offset.hinge_nm,
        "current_offset_a": prepared.departures.offset.current_a,
        "torque_scale": prepared.departures.drive.torque_factor,
        "inertia_factor": prepared.departures.drive.inertia_factor,
        "inertia_from": list(prepared.departures.inertia_from) or None,
        "inertia_undecided": prepared.departures.drive.alternative is not None,
        "viscous_factor": prepared.departures.viscosity.factor,
        "hinge_gain": prepared.departures.hinge.gain * aircraft.factor,
        "hinge_aircraft_ratio": aircraft.ratio if aircraft.readable else None,
        "hinge_aircraft_ratio_std": aircraft.ratio_std if aircraft.readable else None,
    }


def _lag_notes(lags: Lags) -> list[Note]:
    """The sensors found logged late, and what was done about it."""
    notes = []
    if lags.current_s:
        late, by = ("current", lags.current_s) if lags.current_s > 0 else ("speed", -lags.current_s)
        text = (
            f"the {late} is logged {1e6 * by:.0f} µs late (a sensor filter): advanced onto the other before Eq. 5.1, "
            "which it otherwise breaks at every acceleration"
        )
        notes.append(Note(code="current_lag", text=text))
    if lags.hinge_filter_s:
        text = (
            f"the hinge moment's noise is correlated as behind a filter delaying {1e6 * lags.hinge_filter_s:.0f} µs; "
            f"the deflection and Eq. 5.1 put weight {lags.hinge_weight:.2f} on the moment being late too: advanced "
            f"by {1e6 * lags.hinge_s:.0f} µs (the weighted lag) before Eq. 5.1, the stds include the lags' spread"
        )
        notes.append(Note(code="hinge_lag", parameter="hinge_moment_nm", text=text))
    return notes


def conditioning_notes(prepared: Prepared) -> list[Note]:
    """What conditioning did to the window and found in it, for the result's notes."""
    notes = []
    if prepared.command_clipped_fraction > 0:
        notes.append(
            Note(
                code="command_clipped",
                parameter="command_deg",
                text=(
                    f"{100 * prepared.command_clipped_fraction:.1f} % of the command lies past the end stops: "
                    "the actuator saturates there, and so do its simulations"
                ),
            )
        )
    notes.extend(_lag_notes(prepared.lags))
    found = (
        stale_note(prepared.stale),
        kinematics_note(prepared.consistency),
        offset_note(prepared.departures.offset),
        drive_constants_note(prepared.departures.drive),
        history_note(prepared.departures),
        hinge_gain_note(prepared.departures.hinge),
        aircraft_note(prepared.departures.aircraft),
        viscosity_note(prepared.departures.viscosity),
        step_lag_note(prepared.step),
    )
    notes.extend(note for group in found for note in group)
    if prepared.glitches:
        counts = ", ".join(f"{count} of {name}" for name, count in prepared.glitches.items())
        notes.append(
            Note(
                code="glitches_repaired",
                text=(
                    f"glitches replaced by the line between their flanking samples ({counts}): a sample, or a few, "
                    f"that left both flanks by over {GLITCH_STDS:g} noise stds and came straight back (EMI, bit errors)"
                ),
            )
        )
    return notes
