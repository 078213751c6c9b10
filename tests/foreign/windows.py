"""Foreign windows: the independent physics, a command family, sensor noise of its own kind.

``draw`` returns an ``ema-window/1`` *document* (what a client sends) and the truth, never one of
our own objects: tests parse it through the public contract like any user's data.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from tests.foreign import commands
from tests.foreign.commands import Command
from tests.foreign.physics import THESIS, Drive, Effects, Flight, Ground, Health, Setup, simulate

THESIS_NOMINAL = Health()

NOISE = {"position_deg": 0.01, "motor_speed_radps": 0.5, "current_a": 0.05, "hinge_moment_nm": 2.0}
QUANTUM = {"position_deg": 0.0025, "current_a": 0.005}  # resolver and ADC resolution


@dataclass(frozen=True)
class Draw:
    document: dict
    truth: dict[str, float]  # FDJ, eta_O, eta_A, FSJ
    family: str
    setup: Setup = field(repr=False)
    command: Command = field(repr=False)
    duration_s: float
    preroll_s: float

    def clean_signals(self, health: Health | None = None, effects: Effects | None = None) -> dict[str, np.ndarray]:
        """This window's signals without sensor noise, drawn again, with another health or other effects if given."""
        setup = replace(self.setup, health=health or self.setup.health, effects=effects or self.setup.effects)
        return simulate(setup, self.command, self.duration_s, self.preroll_s)


def filtered(white: np.ndarray, width: int) -> np.ndarray:
    """Unit-variance noise behind a ``width``-sample moving average (an averaging ADC, a FIR anti-aliasing
    filter): correlated over ``width`` samples, then not at all (``ema.model.noise`` draws AR(1) instead)."""
    if width <= 1:
        return white
    return np.convolve(white, np.ones(width) / np.sqrt(width), mode="valid")


def filter_widths(seed: int) -> dict[str, int]:
    """Sensors behind moving-average filters, as a log might hold them: current 2–6 samples, speed and
    position 2–8, the hinge moment's strain-gauge amplifier 10–40 (1–4 ms at 10 kHz)."""
    rng = np.random.default_rng(30_000 + seed)
    return {
        "current_a": int(rng.integers(2, 7)),
        "motor_speed_radps": int(rng.integers(2, 9)),
        "position_deg": int(rng.integers(2, 9)),
        "hinge_moment_nm": int(rng.integers(10, 41)),
    }


def through_filters(drawn: Draw, widths: Mapping[str, int]) -> Draw:
    """``drawn`` with each named sensor's logged signal, noise and all, through a causal moving average
    of its width, then quantized again: a real filter delays the signal by (width − 1) / 2 samples
    (``draw``'s ``filter_samples`` filters the noise alone)."""
    signals = {name: list(values) for name, values in drawn.document["signals"].items()}
    for name, width in widths.items():
        values = np.asarray(signals[name])
        values = np.convolve(np.concatenate([np.full(width - 1, values[0]), values]), np.ones(width) / width, "valid")
        if name in QUANTUM:
            values = QUANTUM[name] * np.round(values / QUANTUM[name])
        signals[name] = values.tolist()
    return replace(drawn, document={**drawn.document, "signals": signals})


def with_hinge_gain(drawn: Draw, gain: float) -> Draw:
    """``drawn`` with its hinge moment logged ``gain`` times the true one, noise and all (a strain gauge's
    bridge calibrated off; the loop never reads it, so the motion is the same)."""
    signals = dict(drawn.document["signals"])
    signals["hinge_moment_nm"] = (gain * np.asarray(signals["hinge_moment_nm"])).tolist()  # not quantized
    return replace(drawn, document={**drawn.document, "signals": signals})


def with_spikes(drawn: Draw, seed: int) -> Draw:
    """``drawn`` with EMI spikes and bit errors as a log might hold them: 1–5 on each sensor, 50–500
    noise stds, one in four doubled on the next sample (the product repairs runs of up to 3)."""
    rng = np.random.default_rng(40_000 + seed)
    signals = {name: list(values) for name, values in drawn.document["signals"].items()}
    for name, sigma in NOISE.items():
        n = len(signals[name])
        for at in rng.choice(np.arange(20, n - 20), size=int(rng.integers(1, 6)), replace=False):
            size = float(rng.choice([-1, 1]) * rng.uniform(50, 500) * sigma)
            for k in range(at, at + (2 if rng.uniform() < 0.25 else 1)):
                signals[name][k] += size
    return replace(drawn, document={**drawn.document, "signals": signals})


def noisy(
    signals: dict[str, np.ndarray],
    rng: np.random.Generator,
    level: float,
    filter_samples: Mapping[str, int] = {},
    samples_rng: np.random.Generator | None = None,
) -> dict[str, np.ndarray]:
    """Gaussian noise at ``level`` × NOISE (each signal ±30 % around it), each sensor's behind its
    ``filter_samples`` moving average if given, then sensor quantization. The levels come from ``rng``,
    the samples from ``samples_rng`` if given (another realization at the same levels), else ``rng``."""
    out = {}
    for name, values in signals.items():
        sigma = NOISE.get(name, 0.0) * level * rng.uniform(0.7, 1.3)
        width = filter_samples.get(name, 1)
        white = rng.standard_normal(len(values) + width - 1)  # drawn either way: the next levels stay
        if samples_rng is not None:
            white = samples_rng.standard_normal(len(white))
        noisy_values = values + sigma * filtered(white, width)
        if name in QUANTUM:
            noisy_values = QUANTUM[name] * np.round(noisy_values / QUANTUM[name])
        out[name] = noisy_values
    return out


def draw(
    seed: int,
    family: str = "thesis",
    *,
    health: Health | None = None,
    effects: Effects = Effects(),
    flight: Flight | Ground | None = None,
    duration_s: float = 0.5,
    sample_rate_hz: float = 10_000.0,
    noise_level: float = 1.0,
    preroll_s: float | None = None,
    filter_samples: Mapping[str, int] = {},
    noise_seed: int | None = None,
    drive: Drive = THESIS,
    nominal: Health = THESIS_NOMINAL,
) -> Draw:
    """One window. Unset health and flight are drawn (health within ±20 % of ``nominal``'s FDJ and FSJ and
    η_O in the thesis's range); windows of the flight families start mid-motion (a pre-roll of 20–100 ms),
    the thesis family and ground sweeps from rest. A ``noise_seed`` draws another realization of the same
    window's sensor noise (levels and filters kept). On the ground (``Ground``) the window names no flight
    condition and its hinge moment is the load cell's."""
    rng = np.random.default_rng(seed)
    if health is None:
        health = Health(
            fdj_nm=nominal.fdj_nm * rng.uniform(0.8, 1.2),
            fsj_nm=nominal.fsj_nm * rng.uniform(0.8, 1.2),
            eta_o=rng.uniform(0.68, 0.98),
        )
    if flight is None:
        flight = Flight(airspeed_mps=rng.uniform(100.0, 210.0), altitude_m=rng.uniform(0.0, 9000.0))
    if preroll_s is None:
        preroll_s = 0.0 if family in ("thesis", "sweep") else float(rng.uniform(0.02, 0.1))
    command = commands.BY_NAME[family](rng, duration_s)
    setup = Setup(health, effects, flight, sample_rate_hz, drive)
    samples_rng = None if noise_seed is None else np.random.default_rng(noise_seed)
    signals = noisy(simulate(setup, command, duration_s, preroll_s), rng, noise_level, filter_samples, samples_rng)
    document = {
        "schema": "ema-window/1",
        "actuator_id": f"foreign/{family}",
        "window_id": f"{family}-{seed}",
        "sample_rate_hz": sample_rate_hz,
        "flight_condition": None
        if isinstance(flight, Ground)
        else {"airspeed_mps": flight.airspeed_mps, "altitude_m": flight.altitude_m},
        "signals": {name: values.tolist() for name, values in signals.items()},
    }
    truth = {"FDJ": health.fdj_nm, "eta_O": health.eta_o, "eta_A": health.eta_a(drive.gear_ratio), "FSJ": health.fsj_nm}
    return Draw(document, truth, family, setup, command, duration_s, preroll_s)


def worn(seed: int, **kwargs) -> Draw:
    """A worn actuator (FDJ 1.3–2.5× nominal, η_O 0.45–0.66: Case 1C's irreversible range included)."""
    rng = np.random.default_rng(10_000 + seed)
    fdj = 0.05 * rng.uniform(1.3, 2.5)
    health = Health(fdj_nm=fdj, fsj_nm=fdj * rng.uniform(1.6, 2.2), eta_o=rng.uniform(0.45, 0.66))
    return draw(seed, health=health, **kwargs)


def of_the_same_flight(drawn: Draw, seed: int, family: str = "cruise", duration_s: float = 1.0) -> Draw:
    """Another window of ``drawn``'s flight: the same actuator (health, effects, its sensors' offsets),
    flight condition and logger, a command of ``family``."""
    setup = drawn.setup
    other = draw(
        seed,
        family,
        health=setup.health,
        effects=setup.effects,
        flight=setup.flight,
        duration_s=duration_s,
        sample_rate_hz=setup.sample_rate_hz,
        drive=setup.drive,
    )
    other.document["actuator_id"] = drawn.document["actuator_id"]
    return other


__all__ = [
    "Draw",
    "Drive",
    "Effects",
    "Flight",
    "Ground",
    "Health",
    "draw",
    "filter_widths",
    "of_the_same_flight",
    "replace",
    "through_filters",
    "with_spikes",
    "worn",
]
