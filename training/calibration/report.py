"""The ``ema-calibration/1`` report, assembled from what the calibration loop found."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from sim.window import Window
from training.calibration.channels import Residuals
from training.calibration.library import FOLLOWS
from training.calibration.selection import MIN_BIC_GAIN, Blocks, Choice

SCHEMA = "ema-calibration/1"
TARGETS = ("FDJ", "eta_O")


def residual_rms(found: Sequence[Residuals]) -> dict[str, float]:
    """RMS of each reported residual over all windows."""
    keys = found[0].rms_report
    return {k: float(np.sqrt(np.mean([r.rms_report[k] ** 2 for r in found]))) for k in keys}


def unexplained(structure: Mapping[str, float], steps: Sequence[dict[str, Any]]) -> dict[str, Any] | None:
    """Structure no named effect accounts for: contenders the windows cannot tell apart, or a
    variable the residual still follows."""
    contenders = steps[-1].get("contenders") if steps else None
    if contenders:
        variable = FOLLOWS[contenders[0]]
        both = " and ".join(contenders)
        described = f"the residual follows {variable}; {both} both fit it, and these windows cannot tell which"
        return {"variable": variable, "bic_gain": structure.get(variable), "description": described}
    strongest = max(structure, key=lambda name: structure[name])
    if structure[strongest] > MIN_BIC_GAIN:
        described = f"the residual torque varies systematically with {strongest}, and no candidate explains it"
        return {"variable": strongest, "bic_gain": structure[strongest], "description": described}
    return None


def calibration_report(
    windows: Sequence[Window],
    estimates: tuple[dict[str, float], dict[str, float]],
    found: tuple[Sequence[Residuals], Sequence[Residuals]],
    candidates: list[dict[str, Any]],
    chosen: Sequence[Choice],
    steps: list[dict[str, Any]],
    structure: Mapping[str, float],
    blocks: Blocks,
    truth: Mapping[str, float] | None,
) -> dict[str, Any]:
    """Everything but the fitted parameters, which the loop adds once refined."""
    before, after = estimates
    report: dict[str, Any] = {
        "schema": SCHEMA,
        "n_windows": len(windows),
        "residual_rms_before": residual_rms(found[0]),
        "residual_rms_after": residual_rms(found[1]),
        "candidates": candidates,
        "selected_effect": chosen[0].candidate.effect if chosen else None,
        "selected_effects": [c.candidate.effect for c in chosen],
        "selection": {**steps[0], "block_length_samples": blocks.length, "effective_samples": blocks.n},
        "selection_steps": steps,
        "unexplained_structure": unexplained(structure, steps),
        "estimates_before": before,
        "estimates_after": after,
    }
    if truth is not None:
        for when, values in (("before", before), ("after", after)):
            report[f"error_{when}"] = {k: abs(values[k] - float(truth[k])) for k in TARGETS}
            report[f"error_pct_{when}"] = {k: 100 * abs(values[k] / float(truth[k]) - 1) for k in TARGETS}
    return report
