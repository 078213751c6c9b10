"""Careless exports of a window: a sign convention, a unit or a sample rate a log got wrong (test-only).

Each slip scales fields of an ``ema-window/1`` document as an export script might, and names the
field the product should refuse it by.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Slip:
    factors: dict[str, float]  # signal name (or "sample_rate_hz") -> what the export multiplied it by
    field: str  # the field a refusal should name
    early_s: dict[str, float] = dataclasses.field(default_factory=dict)  # signal name -> how early the export logged it


SLIPS: dict[str, Slip] = {
    "speed of the other sign": Slip({"motor_speed_radps": -1.0}, "signals.motor_speed_radps"),
    "position of the other sign": Slip({"position_deg": -1.0}, "signals.position_deg"),
    "both motion signals of the other sign": Slip(
        {"position_deg": -1.0, "motor_speed_radps": -1.0}, "signals.position_deg"
    ),
    "position in radians": Slip({"position_deg": math.pi / 180}, "signals.position_deg"),
    "sample rate stated twice the log's": Slip({"sample_rate_hz": 2.0}, "sample_rate_hz"),
    "sample rate stated half the log's": Slip({"sample_rate_hz": 0.5}, "sample_rate_hz"),
    "command in radians": Slip({"command_deg": math.pi / 180}, "signals.command_deg"),
    "current of the other sign": Slip({"current_a": -1.0}, "signals.current_a"),
    "hinge moment of the other sign": Slip({"hinge_moment_nm": -1.0}, "signals.hinge_moment_nm"),
    "hinge moment in kN·m": Slip({"hinge_moment_nm": 1e-3}, "signals.hinge_moment_nm"),
    "hinge moment in lbf·in": Slip({"hinge_moment_nm": 8.8507}, "signals.hinge_moment_nm"),
    "hinge moment in lbf·ft": Slip({"hinge_moment_nm": 0.73756}, "signals.hinge_moment_nm"),
    "current and hinge moment of the other sign": Slip(
        {"current_a": -1.0, "hinge_moment_nm": -1.0}, "signals.current_a"
    ),
    "hinge moment not logged (zeros)": Slip({"hinge_moment_nm": 0.0}, "signals.hinge_moment_nm"),
    "current a tenth (a shunt's volts)": Slip({"current_a": 0.1}, "signals.current_a"),
    "current 0.71x (RMS for amplitude)": Slip({"current_a": 0.7071}, "signals.current_a"),
    "current 20 ms out of step": Slip({}, "signals.current_a", {"current_a": 0.02}),
    "hinge moment 5 ms out of step": Slip({}, "signals.hinge_moment_nm", {"hinge_moment_nm": 0.005}),
    "hinge moment 10 ms out of step": Slip({}, "signals.hinge_moment_nm", {"hinge_moment_nm": 0.01}),
    "hinge moment 20 ms out of step": Slip({}, "signals.hinge_moment_nm", {"hinge_moment_nm": 0.02}),
}


def exported(document: dict, slip: Slip) -> dict:
    """``document`` as the careless export wrote it (a channel logged early holds its last value at the end)."""
    factors, rate = slip.factors, document["sample_rate_hz"]
    signals = {name: [v * factors.get(name, 1.0) for v in values] for name, values in document["signals"].items()}
    for name, early_s in slip.early_s.items():
        n = round(early_s * rate)
        signals[name] = signals[name][n:] + signals[name][-1:] * n
    return {**document, "signals": signals, "sample_rate_hz": rate * factors.get("sample_rate_hz", 1.0)}
