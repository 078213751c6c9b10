"""The motor's torque per logged current, read where it departs from the spec's k_T.

T_R starts from k_T·I, and two things scale it that a log does not show: a magnet's k_T falls about
0.1 %/K as the motor warms (NdFeB; SmCo a third of that), and a Hall current sensor carries a gain
error of about 1 %. Either leaves T_R short by γ·k_T·I, with γ the motor's true torque per spec k_T·I
less one, and k_T·I is mostly the hinge load and the inertia: on 15 foreign windows with k_T
0.95–1.05x the spec's, FDJ was read a mean 53 % of its range off, up to 258 %, some at 14 stds.

γ·k_T·I is told from friction because friction follows the direction and |T_ext| while k_T·I follows
the signed load and the acceleration, so γ is fitted beside FDJ (``FitSettings(torque_scale=True)``,
with the offset and ΔC free too, which it might otherwise pass for) and read where the fit with it
explains the window ``MIN_Z`` stds better (``zero_offset.equation_z``). On the same 15 windows every
γ stood 5–22 stds out and was read within 0.001 (FDJ then within 1.5 % of range); on 420 clean
foreign windows of every group the z stayed under 2.6. Where k_T·I meets the motor's peak torque
the spec's model cuts it, so a scale moves nothing there: the current is rescaled and the fit
repeated until no γ is left (``ITERATIONS``). The window goes on with its current rescaled, every
estimator sees the spec's k_T, and FDJ's and η_O's stds grow by what γ's std moves them.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from sim.params import ActuatorParams
from sim.window import Window
from training.baseline import FitSettings, FrictionFit, fit_friction
from training.preprocess import as_read
from training.zero_offset import equation_z

MIN_Z = 4.0  # stds by which the fit with γ must explain the window better
ITERATIONS = 3  # refits after rescaling: each settles what the peak torque's cut left of γ
SCALE_FIT = FitSettings(offset=True, viscous=True, torque_scale=True)
WITHOUT_SCALE = FitSettings(offset=True, viscous=True)


@dataclass(frozen=True)
class TorqueScale:
    """The motor torque per spec k_T·I read on a window, less one (0: the spec's), and what its std adds."""

    gain: float = 0.0  # γ
    gain_std: float = 0.0
    spread: dict[str, float] = field(default_factory=dict)  # per target, the std γ's uncertainty adds

    @property
    def factor(self) -> float:
        """The motor's torque per spec k_T·I: what the logged current is multiplied by."""
        return 1.0 + self.gain


def _fit(window: Window, actuator: ActuatorParams, factor: float, settings: FitSettings) -> FrictionFit:
    rate = window.sample_rate_hz
    signals = dict(window.signals, current_a=factor * window.signals["current_a"])
    return fit_friction(as_read(signals, rate), rate, actuator, settings)


def read_torque_scale(window: Window, actuator: ActuatorParams = ActuatorParams()) -> TorqueScale:
    """γ where it stands out (module docstring), with FDJ's and η_O's change across γ ± its std."""
    rate = window.sample_rate_hz
    found = _fit(window, actuator, 1.0, SCALE_FIT)
    gain, std = float(found.torque_scale[0]), float(found.torque_scale_std[0])
    if not (np.isfinite(gain) and std > 0):  # the window cannot tell γ from FDJ (``baseline._fitted``)
        return TorqueScale()
    if equation_z(_fit(window, actuator, 1.0, WITHOUT_SCALE), found, rate) <= MIN_Z:
        return TorqueScale()
    for _ in range(ITERATIONS):
        left = float(_fit(window, actuator, 1.0 + gain, SCALE_FIT).torque_scale[0])
        gain = (1.0 + gain) * (1.0 + left) - 1.0
    low, high = (_fit(window, actuator, 1.0 + gain + d, FitSettings()) for d in (-std, std))
    spread = {
        "FDJ": abs(float(high.fdj_nm[0] - low.fdj_nm[0])) / 2,
        "eta_O": abs(float(high.eta_o[0] - low.eta_o[0])) / 2,
    }
    return TorqueScale(gain, std, spread)


def rescaled(window: Window, scale: TorqueScale) -> Window:
    """``window`` with its current multiplied by the scale read: the spec's k_T then gives the motor's torque."""
    if not scale.gain:
        return window
    return replace(window, signals=dict(window.signals, current_a=scale.factor * window.signals["current_a"]))


def torque_scale_note(scale: TorqueScale) -> str | None:
    """The scale in words for the result's notes, or None."""
    if not scale.gain:
        return None
    return (
        f"the motor gives {scale.factor:.4f} ± {scale.gain_std:.4f} times the spec's k_T·I (k_T moves with the "
        "magnets' temperature, a current sensor has a gain error): the current was rescaled before every "
        "estimator, and the stds include the scale's uncertainty; read with the spec's, the load and inertia "
        "it scales would have passed for friction"
    )
