"""The rotary kind: the thesis's elevator EMA, a current-piloted motor and a gear train to a surface; this folder
holds everything only it needs (its pipeline, its output-error check, its calibration loop, its synthetic windows).

A window at 1 kHz or more goes through the whole pipeline (``ema.kinds.rotary.pipeline``), one logged slower is
read quasi-statically (``ema.estimate.quasistatic``); its calibration is the loop of ``ema.kinds.rotary.calibration``,
which reads windows at 1 kHz or more. The pipeline and the loop train networks: each is imported by the method
that runs it, so that a process that reads only slow logs, or another kind's, never loads SciPy's optimizers
(half a second of a one-shot command).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ema.calibration.plot import ResidualPlot, Series
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import STAGES, Estimate, Note
from ema.estimate.documents.window_facts import HistoryReadings, RotaryWindowInfo, WindowInfo
from ema.estimate.quasistatic.slow_window import QUASI_STATIC_STAGES
from ema.kinds.base import (
    WARM_UP,
    Borrowed,
    Calibrated,
    CalibrationRequest,
    Cost,
    Lent,
    Request,
    SensorGain,
    learned_lines,
    read_quasi_statically,
)
from ema.kinds.rotary.motor_reading import MOTOR_READING
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS, ActuatorDocument, RotaryActuator, as_kind
from ema.model.bounds import HIGH_RATE_HZ
from ema.model.checks import InputError
from ema.model.document import Document
from ema.model.kinds import KINDS, KindFacts
from ema.model.params import HealthParams
from ema.model.window import RotaryWindow, Window, as_window

if TYPE_CHECKING:
    from ema.kinds.rotary.calibration import Calibrator

VARIABLE_LABELS = {
    "speed_radps": "motor speed |ω| [rad/s]",
    "current_a": "current · sgn(ω) [A]",
    "time_s": "time in the window [s]",
    "position_rad": "elevator position [rad]",
    "motor_angle_rad": "motor angle mod 2π [rad]",
    "direction": "direction of motion",
    "load_nm": "load at the shaft, + aiding [N·m]",
}


@dataclass(frozen=True)
class Rotary:
    facts: KindFacts = KINDS["rotary"]

    def stages(self, window: Window) -> tuple[str, ...]:
        return STAGES if window.high_rate else QUASI_STATIC_STAGES

    def estimate(self, window: Window, request: Request) -> Estimate:
        if not window.high_rate:
            return read_quasi_statically(window, request, MOTOR_READING)
        from ema.kinds.rotary.other_windows import as_readings
        from ema.kinds.rotary.pipeline import estimate_window  # the network's (module docstring)

        return estimate_window(
            window,
            request.config,
            actuator=as_kind(request.actuator, RotaryActuator),
            version=request.version,
            on_stage=request.on_stage,
            spec_only=request.spec_only,
            history=as_readings(request.history),
        )

    def calibrate(self, windows: Sequence[Window], request: CalibrationRequest) -> Calibrated:
        for i, window in enumerate(windows):
            if not window.high_rate:
                raise InputError(
                    f"windows.{i}.sample_rate_hz",
                    f"{window.sample_rate_hz:g} Hz: a rotary actuator's calibration simulates its windows and reads "
                    f"them at {HIGH_RATE_HZ:g} Hz or more",
                )
        from ema.kinds.rotary.calibration import Calibrator  # the network's (module docstring)

        config = request.config
        actuator = as_kind(request.actuator, RotaryActuator)
        calibrator = Calibrator(config, copies=request.copies, seed=config.seed, actuator=actuator)
        calibrator.fit(
            [as_window(w, RotaryWindow) for w in windows],
            request.truth,
            on_stage=request.on_stage,
            checkpoint=request.checkpoint,
        )
        return Calibrated(calibrator.report_, None, residual_plot(calibrator))

    def cost(self, window: Window, config: PipelineConfig) -> Cost:
        if not window.high_rate:
            return Cost(simulated_s=0.0, window_s=0.0)
        return Cost(simulated_s=config.total_simulations * window.duration_s, window_s=window.duration_s)

    def calibration_cost(self, windows: Sequence[Window], config: PipelineConfig) -> Cost:
        seconds = sum(w.duration_s for w in windows)
        return Cost(simulated_s=config.total_simulations * seconds, window_s=seconds)

    def synthesize(self, actuator: ActuatorDocument, flags: Mapping[str, Any]) -> dict[str, Any]:
        """``ema simulate``'s windows drawn by the simulator at the health ``flags`` ask (``synthesis.Draw``)."""
        from ema.kinds.rotary.synthesis import Draw, synthesize

        return synthesize(Draw(**flags), as_kind(actuator, RotaryActuator))

    @property
    def sensor_gains(self) -> tuple[SensorGain, ...]:
        return (HINGE_GAUGE,)

    def report_lines(self, report: Mapping[str, Any]) -> list[str]:
        """What no named effect explains, effects its windows cannot tell apart, and what it learned."""
        lines = []
        if report.get("unexplained"):
            lines.append(f"unexplained: {report['unexplained']['description']}")
        if report.get("ambiguity"):
            ambiguity = report["ambiguity"]
            lines.append(
                f"ambiguous: {' / '.join(ambiguity['effects'])}; to tell them apart: {ambiguity['tell_apart']}"
            )
        return lines + learned_lines(report.get("learned", []))

    # What its windows lend each other: a flight's sensor zero, the build's J_M (``ema.kinds.rotary.other_windows``)
    borrowing = HistoryReadings

    def lent_by(self, info: WindowInfo) -> Lent:
        from ema.kinds.rotary.other_windows import lent_by

        return lent_by(info)

    def borrowed(self, lent: Borrowed) -> HistoryReadings:
        from ema.kinds.rotary.other_windows import borrowed

        return borrowed(lent)

    def waits_for_the_run(self, info: WindowInfo) -> bool:
        from ema.kinds.rotary.other_windows import waits_for_the_run

        return waits_for_the_run(info)

    def lacking(self, read: WindowInfo, others: Document | None) -> HistoryReadings | None:
        from ema.kinds.rotary.other_windows import wanted

        return wanted(read, others)

    def prognosis_parts(self, infos: Sequence[WindowInfo]) -> tuple[dict[str, Any], list[Note]]:
        """J_M as the windows read it since it last changed, and a note where it changed along them or scatters
        beyond their stds (``ema.kinds.rotary.inertia``)."""
        from ema.kinds.rotary.inertia import combined_inertia, inertia_change_note
        from ema.kinds.rotary.other_windows import inertia_readings

        readings = inertia_readings(infos)
        note = inertia_change_note(readings)
        return {"inertia": combined_inertia(readings)}, [] if note is None else [note]

    def prognosis_lines(self, prognosis: Mapping[str, Any]) -> list[str]:
        inertia = prognosis.get("inertia")
        if not inertia:
            return []
        said = f"J_M {inertia['factor']:.4f} ± {inertia['std']:.2g}x the document's"
        return [f"{said}, as windows that could tell it read it"]

    def warm_up(self) -> None:
        """A tiny pipeline run: simulation kernels, residual, network and the physics solution all exercised once
        (loaded from the cache or compiled), so that the first window a process answers costs what any other does."""
        window = synthetic_window(HealthParams.single(), seed=0, duration_s=0.05)
        self.estimate(window, Request(WARM_UP, THESIS))


def residual_plot(calibrator: Calibrator) -> ResidualPlot:
    """The equation-error residual before and after, against the variable that explains it."""
    from ema.calibration.held_out import score
    from ema.kinds.rotary.selection import problem

    e, report, chosen = calibrator.measured_, calibrator.report_, calibrator.chosen_
    variable = "time_s"
    if chosen:
        variable = chosen[0].family.follows
    elif report.unexplained is not None:
        variable = report.unexplained.variables[0]
    x = e.variables[variable]
    if variable == "motor_angle_rad":
        x = np.mod(x, 2 * np.pi)
    series = []
    for label, model in (("before", []), ("after", chosen)):
        design, target = problem(e, model)
        residual = target - design @ score(design, target, e.folds).beta
        series.append(Series(label, x[::4].tolist(), residual[::4].tolist()))
    return ResidualPlot(
        title=f"calibration: {report.selected_effect or 'no effect named'}",
        x_label=VARIABLE_LABELS.get(variable, variable),
        y_label="equation error of Eq. 5.1 [N·m]",
        series=series,
    )


def _hinge_gauge_read(info: WindowInfo) -> tuple[float, float | None] | None:
    if not isinstance(info, RotaryWindowInfo) or info.hinge_aircraft_ratio is None:
        return None
    return info.hinge_aircraft_ratio, info.hinge_aircraft_ratio_std


HINGE_GAUGE = SensorGain(
    name="hinge_aircraft_ratio",
    signal="hinge_moment_nm",
    sensor="the hinge moment's strain gauge",
    model="the aircraft model",
    remedy="recalibrate the gauge, or the airframe's C_hδ is off (each estimate divides the gauge's gain out where "
    "its window is long enough)",
    read=_hinge_gauge_read,
)
ROTARY = Rotary()
