"""A geared servo's window made ready to simulate: its document and log checked, its log's faults repaired or said.

- The loop's gain kp, the load's mass and its arm are the log's own constants (a recorder's header, named by its
  log map); the servo's own constants are its document's, learned by ``ema calibrate``.
- **The supply.** A PWM drive switches its supply; a sample that reads far off the supply's median (a recorder's
  glitch: 0 V, or twice the supply) is read as its neighbours, and said.
- **The motor off.** Where the log says the torque is off the shaft turns free: simulated with no motor torque.
- **The position's step.** An encoder reads in steps (the document's, else the smallest the log shows): the
  simulations the network learns from are read through the same step.
- **The time stamps.** A log resampled from uneven time stamps says so (``Window.resampled``).
- **The command delay.** The set point reaches the loop the document's delay late (a lane's parameter: the
  simulator reads the logged set point that late).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import ema.estimate.documents as doc
from ema.kinds.geared.loop import GRAVITY, LANE_PARAMETERS, Run
from ema.model.actuator import GearedActuator
from ema.model.checks import InputError
from ema.model.geared import GEARED_CONSTANTS, Geared
from ema.model.params import HealthRanges
from ema.model.window import GearedWindow

SUPPLY_BAND = 0.25  # a supply sample more than this share off the log's median is a glitch of its reading
HEALTH = ("fdj_nm", "eta_o", "eta_a")  # what a window reads: the thesis's health, at the output shaft


@dataclass(frozen=True)
class GearedPrepared:
    window: GearedWindow
    geared: Geared
    run: Run  # what the simulator takes: the supply repaired
    resolution_rad: float  # the position's step
    nominal: dict[str, float]  # HEALTH, the document's
    failure_levels: dict[str, float]  # FDJ's upper level, η_O's lower one (the document's thresholds)
    ranges: HealthRanges  # the healthy ranges around the nominal (what "weakly determined" is judged against)
    notes: list[doc.Note]

    @property
    def position_rad(self) -> np.ndarray:
        return self.window.signals["position_rad"]

    def lane(self, health: dict[str, float]) -> np.ndarray:
        """The simulator's parameters (``LANE_PARAMETERS``) at the document's constants and ``health`` (FDJ,
        η_O, η_A, and any constant of the section given by name)."""
        return lane_of(self.geared, health)


def lane_of(geared: Geared, health: dict[str, float]) -> np.ndarray:
    """A lane (``LANE_PARAMETERS``) from the section and the health (``fdj_nm``, ``eta_o``, ``eta_a``); a section
    constant in ``health`` (a calibration's trial value) overrides the section's."""
    value = {**geared.model_dump(), **health}
    k_t, resistance = value["torque_constant_nm_per_a"], value["resistance_ohm"]
    lane = {
        "torque_per_volt": k_t / resistance,
        "back_emf": k_t * k_t / resistance,
        "inertia_kg_m2": value["inertia_kg_m2"],
        "error_gain_per_rad": value["error_gain_per_rad"],
        "duty_limit": value["duty_limit"],
        "min_duty": value["min_duty"],
        "fdj_nm": value["fdj_nm"],
        "viscous_nm_s_per_rad": value["viscous_nm_s_per_rad"],
        "k_opp": 1.0 / value["eta_o"] - 1.0,
        "k_aid": 1.0 - value["eta_a"],
        "static_friction_ratio": value["static_friction_ratio"],
        "command_delay_s": value["command_delay_s"],
    }
    return np.array([lane[name] for name in LANE_PARAMETERS])


def log_constants(window: GearedWindow) -> dict[str, float]:
    """The loop's gain and the load, as the log recorded them; InputError naming the first it lacks."""
    missing = [name for name in GEARED_CONSTANTS if name not in window.constants]
    if missing:
        raise InputError(
            f"constants.{missing[0]}",
            f"a geared servo's window gives its loop's gain and its load ({', '.join(GEARED_CONSTANTS)}): its log "
            "map names the file's constants that hold them",
        )
    constants = {name: float(window.constants[name]) for name in GEARED_CONSTANTS}
    for name in GEARED_CONSTANTS:
        if constants[name] < 0 or (name != "load_mass_kg" and constants[name] == 0):
            raise InputError(f"constants.{name}", f"is {constants[name]:g}: a gain and an arm are positive, a mass ≥ 0")
    return constants


def completed_section(actuator: GearedActuator) -> Geared:
    """The section, refused naming the first constant a simulation needs that it lacks (calibrate first)."""
    geared = actuator.geared
    if (missing := geared.missing()) or actuator.nominal is None:
        field = f"actuator.geared.{missing[0]}" if missing else "actuator.nominal"
        raise InputError(
            field,
            "is not known yet: run ema calibrate on this servo's runs and read with the document it writes "
            "(--out-actuator)",
        )
    return geared


def load_run(window: GearedWindow, geared: Geared, supply_v: np.ndarray) -> Run:
    """What the simulator takes of ``window`` (``Run``): its load's gravity moment and inertia from the log's mass
    and arm and the document's arm."""
    constants = log_constants(window)
    mass, arm, per_m = constants["load_mass_kg"], constants["arm_length_m"], geared.arm_kg_per_m
    s, step = window.signals, 1.0 / window.sample_rate_hz
    switch = s.get("motor_on_flag")  # a log that records no switch: the motor on throughout
    on = np.ones(window.n_samples, dtype=bool) if switch is None else switch > 0.5
    return Run(
        set_point_rad=s["set_point_rad"],
        motor_on=on,
        supply_v=supply_v,
        position_gain=constants["position_gain"],
        step_s=step,
        load_moment_nm=GRAVITY * (mass * arm + per_m * arm * arm / 2.0),
        load_inertia_kg_m2=mass * arm * arm + per_m * arm**3 / 3.0,
        first_position_rad=float(s["position_rad"][0]),
    )


def repaired_supply(supply_v: np.ndarray) -> tuple[np.ndarray, doc.Note | None]:
    """The supply with its glitches (``SUPPLY_BAND`` off its median) read as their neighbours, and a note."""
    median = float(np.median(supply_v))
    if median <= 0:
        raise InputError("signals.supply_v", f"its median is {median:g} V: a drive's supply is positive")
    bad = np.abs(supply_v - median) > SUPPLY_BAND * median
    if not bad.any():
        return supply_v, None
    if bad.mean() > 0.5:
        raise InputError(
            "signals.supply_v", f"{bad.mean():.0%} of its samples lie over {SUPPLY_BAND:.0%} off its median"
        )
    good = np.flatnonzero(~bad)
    repaired = supply_v.copy()
    repaired[bad] = np.interp(np.flatnonzero(bad), good, supply_v[good])
    note = doc.Note(
        code="glitches_repaired",
        parameter="supply_v",
        text=f"{int(bad.sum())} sample(s) of the supply read {supply_v[bad].min():.3g} to {supply_v[bad].max():.3g} V "
        f"against its {median:.3g} V median (a glitch of its reading): read as their neighbours",
    )
    return repaired, note


def position_step(position_rad: np.ndarray, geared: Geared) -> float:
    """The position's step: the document's, else the smallest move the log shows (a resampled log's moves are
    blurred by the interpolation: give the encoder's step in the document)."""
    if geared.position_resolution_rad is not None:
        return geared.position_resolution_rad
    moves = np.abs(np.diff(position_rad))
    moves = moves[moves > 1e-12]
    return float(np.min(moves)) if len(moves) else 0.0


def _notes(window: GearedWindow, run: Run, resolution: float) -> list[doc.Note]:
    notes = []
    if window.resampled is not None:
        steps = window.resampled
        notes.append(
            doc.Note(
                code="resampled",
                text=f"the log's {steps.logged_samples} time stamps stepped {1e3 * steps.min_step_s:.1f} to "
                f"{1e3 * steps.max_step_s:.1f} ms apart: resampled to {window.sample_rate_hz:g} Hz",
            )
        )
    off = ~run.motor_on
    if off.any():
        notes.append(
            doc.Note(
                code="motor_off",
                text=f"{off.sum() * run.step_s:.2f} s with the motor's torque off: the shaft turns free there, "
                "simulated with no motor torque",
            )
        )
    if resolution > 0:
        notes.append(
            doc.Note(
                code="position_quantized",
                parameter="position_rad",
                text=f"the position reads in steps of {1e3 * resolution:.3g} mrad: the simulations the network learns "
                "from read through the same step",
            )
        )
    return notes


def prepare_geared(window: GearedWindow, actuator: GearedActuator) -> GearedPrepared:
    """The window ready to simulate (module docstring); InputError where its log or its document lacks a constant."""
    geared = completed_section(actuator)
    supply, glitches = repaired_supply(window.signals["supply_v"])
    run = load_run(window, geared, supply)
    resolution = position_step(window.signals["position_rad"], geared)
    notes = ([glitches] if glitches else []) + _notes(window, run, resolution)
    levels = {"fdj_nm": actuator.threshold("FDJ")[0], "eta_o": actuator.threshold("eta_O")[0]}
    return GearedPrepared(window, geared, run, resolution, nominal_health(actuator), levels, actuator.ranges, notes)


def nominal_health(actuator: GearedActuator) -> dict[str, float]:
    """The document's nominal FDJ, η_O and η_A (η_A by Eq. 3.4 where the document reads none on its own)."""
    nominal = actuator.health
    eta_o = nominal.efficiency
    eta_a = nominal.eta_a if nominal.eta_a is not None else float(actuator.eta_a(eta_o))
    return {"fdj_nm": nominal.fdj, "eta_o": eta_o, "eta_a": eta_a}
