"""The calibration figure: the residual before and after, against the variable that explains it."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from training.calibration.channels import Residuals
from training.calibration.library import FOLLOWS, PRIMARY

LABELS = {
    "speed_radps": "motor speed [rad/s]",
    "current_a": "current [A]",
    "time_s": "time [s]",
    "position_rad": "elevator position [rad]",
    "motor_angle_rad": "motor angle mod 2π [rad]",
    "direction": "time [s]",
}


def residual_figure(
    before: Sequence[Residuals], after: Sequence[Residuals], effect: str | None, variable: str | None, path: Path
) -> Path:
    """Scatter of the residual (every 5th used sample, all windows) before and after, written as PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    channel = PRIMARY.get(effect or "", "torque")
    variable = variable or (FOLLOWS[effect] if effect else "speed_radps")
    x_name = "time_s" if variable == "direction" else variable
    figure, axis = plt.subplots(figsize=(7, 4))
    for label, found, colour in (("before", before, "tab:red"), ("after", after, "tab:blue")):
        x = np.concatenate([r.variables[x_name][r.mask] for r in found])[::5]
        y = np.concatenate([r.channels[channel][r.mask] for r in found])[::5]
        if x_name == "motor_angle_rad":
            x = np.mod(x, 2 * np.pi)
        axis.scatter(x, y, s=3, alpha=0.4, color=colour, label=label)
    unit = {"torque": "N·m", "kinematic": "rad", "hinge": "N·m"}[channel]
    axis.set(xlabel=LABELS.get(x_name, x_name), ylabel=f"{channel} residual [{unit}]")
    axis.set_title(f"calibration: {effect or 'no effect selected'}")
    axis.legend(markerscale=4)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)
    return path
