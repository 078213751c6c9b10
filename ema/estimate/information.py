"""Information before answers: a window whose channels carry nothing is refused before it is read, and an answer
outside what its document allows is never a reading.

A dead channel (a sensor unplugged, a log map's scale of 0, a variable mapped twice) reads as a measurement of a
perfect machine: its least squares find a friction of 1e-9 N with a std to match, and a trend takes it. So, before a
window of any kind is read, each signal its answer is read from (its kind's ``measured``) is checked:

- **dead**: one value throughout (zero or any other);
- **stuck**: one value repeated over ``STUCK_SHARE`` of the window (a frozen reading with a live one beside it);
- **no more than a step**: two values only, a channel that flips one step of its resolution;
- **the set point as the position**: the two sample for sample the same (one variable mapped twice).

Each is refused naming the signal and why (exit 2, HTTP 422). After it is read, every value of the answer that has a
field in the actuator's document is held to that field's bounds (``out_of_bounds``): a mass of 1e8 kg from
positions declared in µm is refused naming the bound, never stored.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ema.model.checks import InputError
from ema.model.kinds import KINDS
from ema.model.window import Window

STUCK_SHARE = 0.9  # one value over this share of the window's samples: a frozen channel


def longest_run(values: np.ndarray) -> int:
    """The most samples in a row holding one value."""
    if len(values) == 0:
        return 0
    changes = np.flatnonzero(np.diff(values) != 0)
    edges = np.concatenate([[-1], changes, [len(values) - 1]])
    return int(np.max(np.diff(edges)))


def too_few_levels(values: np.ndarray) -> str | None:
    """Why ``values`` take fewer than three distinct values (one throughout, or two: a step of its resolution; a
    working sensor shows its noise), or None; in one pass each, no sort (a window's every channel, before every
    reading)."""
    first = values[0]
    others = values[values != first]
    if others.size == 0:
        return f"is {first:g} throughout: a dead or stuck sensor, or a log map's scale of 0; nothing to read"
    if np.all(others == others[0]):
        low, high = sorted((float(first), float(others[0])))
        return f"holds two values only ({low:g}, {high:g}): stuck at a step of its resolution, not a measurement"
    return None


def dead_channel(name: str, values: np.ndarray) -> str | None:
    """Why signal ``name`` carries nothing to read (module docstring), or None."""
    why = too_few_levels(values)
    if why is not None:
        return why
    run = longest_run(values)
    if run >= STUCK_SHARE * len(values):
        return f"holds one value for {run} of its {len(values)} samples in a row: a frozen sensor"
    return None


def refuse_empty_channels(window: Window, field: str = "signals") -> None:
    """InputError naming the first signal of ``window`` that carries nothing its kind reads (module docstring)."""
    facts = KINDS[window.kind]
    for name in facts.measured:
        why = dead_channel(name, window.signals[name])
        if why is not None:
            raise InputError(f"{field}.{name}", why)
    set_point, position = facts.roles["set_point"].signal, facts.roles["position"].signal
    if np.array_equal(window.signals[set_point], window.signals[position]):
        raise InputError(
            f"{field}.{position}",
            f"is {set_point} sample for sample: the log map likely maps one variable to both (a loop never follows "
            "its set point exactly)",
        )


def bounds_of(model: type, name: str) -> tuple[float | None, bool, float | None, bool] | None:
    """(low, low inclusive, high, high inclusive) of a pydantic model's field ``name``, or None without bounds."""
    field = getattr(model, "model_fields", {}).get(name)
    if field is None:
        return None
    low = high = None
    low_in = high_in = True
    for rule in field.metadata:
        for attribute, inclusive, is_low in (
            ("gt", False, True),
            ("ge", True, True),
            ("lt", False, False),
            ("le", True, False),
        ):
            value = getattr(rule, attribute, None)
            if value is None:
                continue
            if is_low:
                low, low_in = float(value), inclusive
            else:
                high, high_in = float(value), inclusive
    return None if low is None and high is None else (low, low_in, high, high_in)


def out_of_bounds(
    values: Mapping[str, float],
    models: tuple[Any, ...],
    field: str,
    *,
    fields: Mapping[str, str] | None = None,
    why: str = "not a reading (a channel scaled into another unit, or mapped wrong?)",
) -> None:
    """InputError naming the first of ``values`` outside its document field's bounds (the first of ``models``, the
    document's classes, that has a field of its name, or of the name ``fields`` gives it: an answer's ``FDJ`` is a
    document's ``fdj_nm``)."""
    for name, value in values.items():
        document_field = name if fields is None else fields.get(name, name)
        bounds = next((b for model in models if (b := bounds_of(model, document_field)) is not None), None)
        if bounds is None:
            continue
        low, low_in, high, high_in = bounds
        below = low is not None and (value < low or (value == low and not low_in))
        above = high is not None and (value > high or (value == high and not high_in))
        if below or above:
            limit = f"{'≥' if low_in else '>'} {low:g}" if below else f"{'≤' if high_in else '<'} {high:g}"
            raise InputError(
                f"{field}.{name}",
                f"reads {value:.4g}, where the actuator's document allows {limit}: {why}",
            )
