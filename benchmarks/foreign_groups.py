"""The named groups of foreign windows the accuracy benchmarks draw (``tests.foreign``), and their seeds.

Each group is a function of a seed; the effects a group adds are drawn per seed in the foreign
implementation's own forms, unlogged, as a real drive would have them.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from tests.foreign.windows import (
    Draw,
    Effects,
    draw,
    filter_widths,
    through_filters,
    with_hinge_gain,
    with_spikes,
    worn,
)

FAMILIES = ("thesis", "cruise", "gust", "doublet", "steps")


def groups() -> dict[str, Callable[..., Draw]]:
    """Named groups of windows, each a function of a seed (keywords pass on to ``draw``: ``noise_level=0``
    gives the same window without its sensor noise)."""
    out: dict[str, Callable[..., Draw]] = {f: (lambda s, f=f, **kw: draw(s, f, **kw)) for f in FAMILIES}
    out["long window (2 s, cruise)"] = lambda s, **kw: draw(s, "cruise", duration_s=2.0, **kw)
    out["short window (0.1 s, gust)"] = lambda s, **kw: draw(s, "gust", duration_s=0.1, **kw)
    out["low log rate (1-2 kHz)"] = lambda s, **kw: draw(
        s, FAMILIES[s % 5], sample_rate_hz=(1_000.0, 2_000.0)[s % 2], **kw
    )
    out["high log rate (50-100 kHz)"] = lambda s, **kw: draw(
        s, FAMILIES[s % 5], sample_rate_hz=(50_000.0, 100_000.0)[s % 2], **kw
    )
    out["odd log rate (3 kHz, 12.8 kHz)"] = lambda s, **kw: draw(
        s, FAMILIES[s % 5], sample_rate_hz=(3_000.0, 12_800.0)[s % 2], **kw
    )
    for family in FAMILIES:
        out[f"worn, {family}"] = lambda s, f=family, **kw: worn(s, family=f, **kw)
    out["drive unlike the document's"] = lambda s, **kw: draw(s, FAMILIES[s % 5], effects=unlike_the_spec(s), **kw)
    out["sensors behind filters"] = lambda s, **kw: through_filters(draw(s, FAMILIES[s % 5], **kw), filter_widths(s))
    out["noise behind filters, not the signal"] = lambda s, **kw: draw(
        s, FAMILIES[s % 5], filter_samples=filter_widths(s), **kw
    )
    out["sensor glitches"] = lambda s, **kw: with_spikes(draw(s, FAMILIES[s % 5], **kw), s)
    out["sensors off zero"] = lambda s, **kw: draw(s, FAMILIES[s % 5], effects=off_zero(s), **kw)
    out["viscous friction 1.2-2x the document's"] = lambda s, **kw: draw(s, FAMILIES[s % 5], effects=viscous(s), **kw)
    out["worn, sensors off zero"] = lambda s, **kw: worn(s, family=FAMILIES[s % 5], effects=off_zero(s), **kw)
    out["worn, viscous 1.2-2x"] = lambda s, **kw: worn(s, family=FAMILIES[s % 5], effects=viscous(s), **kw)
    out["held position"] = lambda s, **kw: draw(s, "hold", **kw)
    # appended: a group's seeds follow its place in this list (``group_seed``)
    out["k_T, current gain or J_M off"] = lambda s, **kw: draw(s, FAMILIES[s % 5], effects=drive_off(s), **kw)
    out["worn, k_T, current gain or J_M off"] = lambda s, **kw: worn(
        s, family=FAMILIES[s % 5], effects=drive_off(s), **kw
    )
    out["hinge moment gain 0.95-1.05x"] = lambda s, **kw: with_hinge_gain(draw(s, FAMILIES[s % 5], **kw), hinge_gain(s))
    out["longest window (10 s, 10 kHz)"] = lambda s, **kw: draw(s, FAMILIES[s % 5], duration_s=10.0, **kw)
    return out


def unlike_the_spec(seed: int) -> Effects:
    """A drive whose loop departs from the document's, unlogged: bus ±10 %, position gain ±2 %, the command
    reaching the loop up to 50 µs late, the loop reading a speed as noisy as the logged one (up to 0.5 rad/s)."""
    rng = np.random.default_rng(20_000 + seed)
    return Effects(
        supply_voltage_factor=rng.uniform(0.9, 1.1),
        position_gain_factor=rng.uniform(0.98, 1.02),
        loop_delay_s=rng.uniform(0.0, 5e-5),
        loop_noise_radps=rng.uniform(0.0, 0.5),
        loop_noise_seed=seed,
    )


def off_zero(seed: int) -> Effects:
    """A sensor off zero, unlogged: in turn the hinge moment by 1–10 N·m and the current by 0.04–0.25 A
    (the same torque at the shaft; the current's offset is fed back to its loop, too)."""
    rng = np.random.default_rng(30_000 + seed)
    sign = float(rng.choice([-1.0, 1.0]))
    if seed % 2:
        return Effects(current_bias_a=sign * rng.uniform(0.04, 0.25))
    return Effects(hinge_bias_nm=sign * rng.uniform(1.0, 10.0))


def viscous(seed: int) -> Effects:
    """Viscous friction 1.2–2x the document's C (a cold grease), unlogged, as a change of temperature is."""
    return Effects(viscous_factor=float(np.random.default_rng(40_000 + seed).uniform(1.2, 2.0)))


def drive_off(seed: int) -> Effects:
    """A drive constant off the document's, unlogged: in turn k_T 0.95–1.05x (the magnets warm or cold), the
    current sensor's gain 0.97–1.03 (fed back to its loop, too) and J_M 0.9–1.1x."""
    value = np.random.default_rng(50_000 + seed).uniform(-1.0, 1.0)
    return (
        Effects(torque_constant_gain=1.0 + 0.05 * value),
        Effects(current_sensor_gain=1.0 + 0.03 * value),
        Effects(inertia_factor=1.0 + 0.1 * value),
    )[seed % 3]


def hinge_gain(seed: int) -> float:
    """The hinge moment's logged over its true value, 0.95–1.05: a strain-gauge bridge calibrated off."""
    return float(np.random.default_rng(70_000 + seed).uniform(0.95, 1.05))


def group_seed(group: str, i: int, first: int = 7000) -> int:
    """The seed of window ``i`` of ``group``: each group its own thousand, so groups never share a window."""
    return first + 1000 * list(groups()).index(group) + i
