"""A sensor that repeats one value where a working one shows its noise: a logger that stopped updating, or
a gap it filled in. A short run is bridged by the line between its flanks; past a kernel's span, the window
is read from the stretch without such runs that holds the most sliding motion.

Two faults of real flight logs leave such a run in an otherwise noisy signal: a sensor or bus that
stops updating while the logger keeps writing its last value, and a gap the logger fills with zeros.
Left in, they are read as physics: a frozen speed or a current at zero is friction to Eq. 5.1.

A run of ``r`` repeats (``r + 1`` equal samples, at least ``MIN_STALE_SAMPLES``) is stale where

1. the sensor's noise spans its resolution (its white noise std, read outside the runs, at least its
   smallest step): a sensor quantized coarser than its noise sits on one level wherever its signal is
   flat, as a frozen one does, and there the two cannot be told apart;
2. the signal's own repeats elsewhere make it improbable: m·pʳ < ``STALE_CHANCE``, m the pairs of
   neighbours, p the share of them equal outside the run (Laplace's rule); or it stands off both
   flanking samples by ``DROPOUT_STDS`` noise stds: a gap filled with zeros, which repeats alone
   would rarely find. A glitch (``conditioning.repaired``) is 3 samples at most, and one sample far
   off is the evidence there; a flat run of four is already rare;
3. for a motion sensor, the shaft slides during it by the other one (the speed for the position; the
   position's travel, or the frozen value itself, for the speed): a speed derived from an encoder may
   read 0 at rest, a resolver one count through a hold. A torque sensor that shows its noise never
   repeats a value, at rest or not, and the simulations replay the logged load through the holds too.

A stale run inside the window and no longer than the reconstruction kernel (2 ms) is replaced by the
line between its flanking samples, as a glitch is: the kernel averages over as much, and cutting
the window there would lose more than the bridge costs. A longer one cuts the window to the stretch
between such runs with the most sliding samples (``window.read_span``); both are counted
(``window.stale_samples``) and said in a note. Where that stretch holds fewer than
``ema.kinds.rotary.physics.friction.MIN_SLIDING_KERNELS`` kernel widths of sliding samples, the window is refused
naming the sensor and its run. A sensor that repeats one value over the whole window is left to
``verdict.check_logged``, which names it as not logged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.stats import white_noise_std
from ema.kinds.rotary.physics.friction import MIN_SLIDING_KERNELS, SolveSettings, sliding_mask
from ema.kinds.rotary.simulator.residual import DERIVATIVE_SPAN_S, kernel_samples
from ema.model.checks import InputError
from ema.model.noise import NOISY_SIGNALS
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

MIN_STALE_SAMPLES = 4  # equal samples: fewer is the glitch repair's (3 at most)
STALE_CHANCE = 1e-6  # expected number of such runs in a working sensor of this signal's repeat rate
NOISE_SAMPLES = 20  # outside the runs, to read a sensor's noise from: fewer, and it is not judged
DROPOUT_STDS = 10.0  # a flat run this far from both flanks, in noise stds, is a gap filled in
TRAVEL_STDS = 4.0  # a frozen speed's run: the position's travel across it, in stds of its kernel means


@dataclass(frozen=True)
class StaleRun:
    signal: str
    start: int  # first sample of the run of equal values
    stop: int  # one past its last
    value: float

    def describe(self, rate_hz: float) -> str:
        return (
            f"repeats {self.value:g} exactly over samples {self.start}–{self.stop - 1} "
            f"({1e3 * (self.stop - self.start) / rate_hz:.1f} ms)"
        )


@dataclass(frozen=True)
class Stale:
    bridged: tuple[StaleRun, ...] = ()  # replaced by the line between their flanks
    cut: tuple[StaleRun, ...] = ()  # left out with the rest of the window beyond them
    span: tuple[int, int] | None = None  # [start, stop) of the logged samples read; None: all of them
    rate_hz: float = 1.0

    @property
    def samples(self) -> dict[str, int]:
        """Per sensor, the samples of its stale runs."""
        counts: dict[str, int] = {}
        for run in (*self.bridged, *self.cut):
            counts[run.signal] = counts.get(run.signal, 0) + run.stop - run.start
        return counts


def edges(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(starts, stops) of the runs of True in ``mask``."""
    steps = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return np.flatnonzero(steps == 1), np.flatnonzero(steps == -1)


def equal_runs(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(starts, stops) of the runs of two or more successive equal samples."""
    starts, stops = edges(values[1:] == values[:-1])  # the runs of equal neighbours, pair k = samples k, k + 1
    return starts, stops + 1


def line_between_flanks(values: np.ndarray, start: int, stop: int) -> np.ndarray:
    """The samples [``start``, ``stop``) as the line between samples ``start − 1`` and ``stop``."""
    share = np.arange(1, stop - start + 1) / (stop - start + 1)
    return values[start - 1] + share * (values[stop] - values[start - 1])


def noise_outside(values: np.ndarray, starts: np.ndarray, stops: np.ndarray) -> float | None:
    """The sensor's white noise std read outside the runs [``starts``, ``stops``) (a robust std, which a run
    over most of the window would bring to 0), or None where it does not span the resolution (module
    docstring, 1) or too few samples are left to read it."""
    outside = np.ones(len(values), dtype=bool)
    for start, stop in zip(starts, stops, strict=True):
        outside[start:stop] = False
    rest = values[outside]
    steps = np.abs(np.diff(rest))
    moved = steps[steps > 0]
    if len(rest) < NOISE_SAMPLES or not len(moved):
        return None
    noise = white_noise_std(rest)
    return noise if noise >= float(moved.min()) else None


def improbable(repeats: int, repeats_in_signal: int, pairs: int) -> bool:
    """Whether a run of ``repeats`` successive equal neighbours is improbable for a signal of ``pairs``
    neighbours, ``repeats_in_signal`` of them equal (module docstring, 2: the share outside the run)."""
    share = (repeats_in_signal - repeats + 1) / (pairs - repeats + 2)
    return math.log(pairs) + repeats * math.log(share) < math.log(STALE_CHANCE)


def stands_off(values: np.ndarray, run: StaleRun, jump: float) -> bool:
    """Whether ``run`` lies further than ``jump`` from both its flanking samples (module docstring, 2)."""
    if run.start == 0 or run.stop == len(values):
        return False
    return bool(min(abs(values[run.start - 1] - run.value), abs(values[run.stop] - run.value)) > jump)


def slides_during(window: RotaryWindow, drive: DriveConstants, run: StaleRun) -> bool:
    """Whether the shaft slides during ``run`` of a motion sensor by the other one (module docstring, 3): the
    speed past the sliding speed (``SolveSettings.sliding_speed_radps``) for the position; for the speed, its
    frozen value past it, or the position
    travelling ``TRAVEL_STDS`` of its noise at that mean speed or faster. True for a torque sensor."""
    signals, rate = window.signals, window.sample_rate_hz
    sliding_radps = SolveSettings().sliding_speed_radps(drive)
    if run.signal in ("current_a", "hinge_moment_nm"):
        return True
    if run.signal == "position_deg":
        return bool(np.any(np.abs(signals["motor_speed_radps"][run.start : run.stop]) > sliding_radps))
    if abs(run.value) > sliding_radps:
        return True
    width = kernel_samples(rate)  # the position's means over a kernel's width, from the run's start to its end
    position = signals["position_deg"]
    around = position[max(0, run.start - width // 2) : run.stop + width // 2]
    means = np.convolve(around, np.ones(width) / width, mode="valid") if len(around) > width else np.zeros(1)
    travel_deg = float(np.ptp(means))
    mean_speed = np.deg2rad(travel_deg) * drive.gear_ratio * rate / (run.stop - run.start)
    return travel_deg > TRAVEL_STDS * white_noise_std(position) / math.sqrt(width) and mean_speed > sliding_radps


def stale_runs(window: RotaryWindow, drive: DriveConstants) -> tuple[StaleRun, ...]:
    """Every sensor's stale runs (module docstring), in the order of the samples."""
    n, found = window.n_samples, []
    for name in NOISY_SIGNALS:
        values = window.signals[name]
        starts, stops = equal_runs(values)
        long = (stops - starts >= MIN_STALE_SAMPLES) & (stops - starts < n)  # a whole window: consistency's
        noise = noise_outside(values, starts[long], stops[long]) if long.any() else None
        if noise is None:
            continue
        repeats, jump = int(np.sum(stops - starts - 1)), DROPOUT_STDS * noise
        for start, stop in zip(starts[long], stops[long], strict=True):
            run = StaleRun(name, int(start), int(stop), float(values[start]))
            unlikely = improbable(run.stop - run.start - 1, repeats, n - 1) or stands_off(values, run, jump)
            if unlikely and slides_during(window, drive, run):
                found.append(run)
    return tuple(sorted(found, key=lambda r: r.start))


def best_stretch(window: RotaryWindow, runs: tuple[StaleRun, ...], drive: DriveConstants) -> tuple[int, int, int]:
    """(start, stop, sliding samples) of the stretch free of ``runs`` with the most sliding samples by the
    speed (the longest of equals)."""
    free = np.ones(window.n_samples, dtype=bool)
    for run in runs:
        free[run.start : run.stop] = False
    starts, stops = edges(free)
    moving = sliding_mask(window.signals, window.sample_rate_hz, drive)
    sliding = np.cumsum(np.concatenate([[0], moving & free]))
    if not len(starts):
        return 0, 0, 0
    best = max(range(len(starts)), key=lambda k: (sliding[stops[k]] - sliding[starts[k]], stops[k] - starts[k]))
    return int(starts[best]), int(stops[best]), int(sliding[stops[best]] - sliding[starts[best]])


def without_stale(window: RotaryWindow, drive: DriveConstants) -> tuple[RotaryWindow, Stale]:
    """``window`` with its short stale runs bridged and cut to its best stretch free of the long ones, and
    what was found; InputError naming the sensor where too little sliding motion is left (module docstring)."""
    rate, n = window.sample_rate_hz, window.n_samples
    runs = stale_runs(window, drive)
    if not runs:
        return window, Stale(rate_hz=rate)
    short = tuple(r for r in runs if r.stop - r.start <= kernel_samples(rate) and r.start > 0 and r.stop < n)
    signals = {name: values.copy() for name, values in window.signals.items()}
    for run in short:
        signals[run.signal][run.start : run.stop] = line_between_flanks(signals[run.signal], run.start, run.stop)
    cut = tuple(r for r in runs if r not in short)
    if not cut:
        return replace(window, signals=signals), Stale(short, rate_hz=rate)
    start, stop, sliding = best_stretch(window, cut, drive)
    needed = MIN_SLIDING_KERNELS * kernel_samples(rate)
    if sliding < needed:
        worst = max(cut, key=lambda r: r.stop - r.start)
        raise InputError(
            f"signals.{worst.signal}",
            f"{worst.describe(rate)}: a sensor that stopped updating, or a logging "
            f"gap filled in; the stretch without such a run holds {sliding} sliding samples, fewer than the {needed} "
            "a friction solution needs",
        )
    signals = {name: values[start:stop] for name, values in signals.items()}
    return replace(window, signals=signals), Stale(short, cut, (start, stop), rate)


def stale_note(stale: Stale) -> list[Note]:
    """The stale runs and what was done with them, for the result's notes."""
    runs = (*stale.bridged, *stale.cut)
    if not runs:
        return []
    listed = "; ".join(f"{run.signal} {run.describe(stale.rate_hz)}" for run in runs[:3])
    more = f" (and {len(runs) - 3} more runs)" if len(runs) > 3 else ""
    bridge_ms = 1e3 * DERIVATIVE_SPAN_S
    done = f"the runs of up to {bridge_ms:g} ms bridged by the line between their flanks" if stale.bridged else ""
    if stale.span is not None:
        start, stop = stale.span
        done += "; " if done else ""
        done += (
            f"read from samples {start}–{stop - 1} only ({(stop - start) / stale.rate_hz:.3g} s), the stretch free "
            "of the longer runs with the most sliding motion"
        )
    why = "where a working sensor shows its noise (it stopped updating, or a gap was filled in)"
    return [Note(code="stale_sensor", text=f"{listed}{more}, {why}: {done}", parameter=runs[0].signal)]
