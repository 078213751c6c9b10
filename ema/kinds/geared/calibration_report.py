"""A geared servo's calibration as its report and its completed document (``ema.kinds.geared.calibration`` learns).

The completed document holds every constant in SI at the output shaft, each with its std, the named effects, the
nominal health (FDJ, η_O, η_A) and what a healthy run's answer scatters by: every run is answered again with the
completed document, as ``ema estimate`` answers it (its physics reading blended with its network's), and the scatter
of those answers about the nominal beyond their own stds is the document's repeatability (``between_runs_std``);
each load's median against the nominal says whether a load's share was misplaced (FDJ would then rise with the
mass).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from ema.calibration.documents import GearedCalibration, Learned, LoadReading
from ema.estimate.config import PipelineConfig
from ema.estimate.stats import between_runs_std
from ema.kinds.geared.calibration import LearnedModel as Model
from ema.kinds.geared.calibration import learned_model
from ema.kinds.geared.effects import CONSTANTS
from ema.kinds.geared.log_reading import HEALTH, log_constants
from ema.kinds.geared.stacked_fit import LoggedRun, RunSet
from ema.model.actuator import GearedActuator, Nominal
from ema.model.window import GearedWindow

UNITS = {"torque_constant_nm_per_a": "N·m/A", "resistance_ohm": "Ω", "inertia_kg_m2": "kg·m²",
         "error_gain_per_rad": "1/rad", "duty_limit": "1", "viscous_nm_s_per_rad": "N·m·s/rad",
         "command_delay_s": "s", "min_duty": "1", "static_friction_ratio": "1", "fdj_nm": "N·m", "eta_o": "1",
         "eta_a": "1"}  # fmt: skip
REPORTED = {"fdj_nm": "FDJ", "eta_o": "eta_O", "eta_a": "eta_A"}  # the health's names in a report


def motor_constants(values: dict[str, float], stds: dict[str, float]) -> dict[str, tuple[float, float]]:
    """k_t and R with their stds from what a solve reads, b = k_t/R and k_e = k_t²/R: k_t = k_e/b, R = k_t/b
    (relative stds in quadrature)."""
    b, k_e = values["torque_per_volt"], values["back_emf"]
    rb, re = stds.get("torque_per_volt", 0.0) / b, stds.get("back_emf", 0.0) / max(k_e, 1e-300)
    k_t = k_e / b
    return {
        "torque_constant_nm_per_a": (k_t, k_t * float(np.hypot(rb, re))),
        "resistance_ohm": (k_t / b, k_t / b * float(np.hypot(2 * rb, re))),
    }


def section_constants(model: Model) -> dict[str, tuple[float, float]]:
    """Every learned constant of the section, in its field's name: (value, std)."""
    values, stds = model.solved.values, model.stds
    learned = motor_constants(values, stds)
    for name in ("inertia_kg_m2", "error_gain_per_rad", "duty_limit", "viscous_nm_s_per_rad", "command_delay_s",
                 "min_duty", "static_friction_ratio"):  # fmt: skip
        learned[name] = (values[name], stds.get(name, 0.0))
    return learned


def health_values(model: Model) -> dict[str, tuple[float, float]]:
    """FDJ, η_O and η_A of the solve, with their stds (η_O = 1/(1 + k_opp), η_A = 1 − k_aid)."""
    values, stds = model.solved.values, model.stds
    eta_o = 1.0 / (1.0 + values["k_opp"])
    return {
        "fdj_nm": (values["fdj_nm"], stds["fdj_nm"]),
        "eta_o": (eta_o, eta_o * eta_o * stds.get("k_opp", 0.0)),
        "eta_a": (1.0 - values["k_aid"], stds.get("k_aid", 0.0)),
    }


def completed_document(actuator: GearedActuator, model: Model) -> GearedActuator:
    """The document with what the runs taught: the section's constants and stds, the effects, the nominal."""
    learned, health = section_constants(model), health_values(model)
    efficiency = "efficiency" in model.final.effects
    section = actuator.geared.completed(
        **{name: value for name, (value, _) in learned.items()},
        effects={name: 1.0 for name in model.final.effects},
        stds={name: std for name, (_, std) in {**learned, **health}.items()},
        position_error_rad=model.final.held.score,
    )
    fdj = health["fdj_nm"][0]
    nominal = Nominal(
        fdj_nm=fdj,
        eta_o=health["eta_o"][0] if efficiency else None,
        eta_a=health["eta_a"][0] if efficiency else None,
    )
    return actuator.model_copy(update={"geared": section, "nominal": nominal})


def read_runs(
    windows: Sequence[GearedWindow], document: GearedActuator, config: PipelineConfig
) -> dict[str, np.ndarray]:
    """(R,) each run's FDJ, η_O and η_A as ``ema estimate`` answers it with ``document``, and (R,) their stds before
    any repeatability (``<name>_std``: the document read with none): what a run's answer scatters by is measured on the
    answers themselves, their physics reading blended with the network's, not on the physics reading alone."""
    from ema.estimate.documents import ActuatorRead
    from ema.kinds.geared.stages import estimate_geared  # the network's

    bare = document.model_copy(update={"geared": document.geared.completed(repeatability={})})
    read_with = ActuatorRead(name=document.name, version=None, default=False)
    read: dict[str, list[float]] = defaultdict(list)
    for window in windows:
        estimates = estimate_geared(window, config, actuator=bare, read_with=read_with).estimates
        for name in HEALTH:
            entry = getattr(estimates, REPORTED[name])
            read[name].append(entry.value)
            read[f"{name}_std"].append(entry.std)
    return {name: np.array(values) for name, values in read.items()}


def repeatable(document: GearedActuator, read: dict[str, np.ndarray]) -> GearedActuator:
    """The document with its repeatability (``between_runs_std`` of the runs' answers about the nominal: an answer is
    judged against it, so the runs' offset from it counts, as a set point the model reads off does in service) and
    its nominal health's stds widened by it: what a healthy run's answer scatters by about the nominal."""
    section, nominal = document.geared, health_nominal(document)
    repeatability, stds = {}, dict(section.stds)
    for name in HEALTH:
        values, own = read[name], read[f"{name}_std"]
        centre = nominal.get(name, float(np.median(values)) if len(values) else 0.0)
        repeatability[name] = between_runs_std(values, own, centre)
        stds[name] = float(np.hypot(stds.get(name, 0.0), repeatability[name]))
    return document.model_copy(update={"geared": section.completed(repeatability=repeatability, stds=stds)})


def by_load(
    windows: Sequence[GearedWindow], read: dict[str, np.ndarray], document: GearedActuator
) -> list[LoadReading]:
    """Each load's (mass × arm) runs: their median health against the nominal, in the nominal's stds."""
    groups: dict[tuple[float, float], list[int]] = defaultdict(list)
    for i, window in enumerate(windows):
        constants = log_constants(window)
        groups[(constants["load_mass_kg"], constants["arm_length_m"])].append(i)
    nominal, stds = health_nominal(document), document.geared.stds
    loads = []
    for (mass, arm), members in sorted(groups.items()):
        median = {name: float(np.median(read[name][members])) for name in HEALTH if name in nominal}
        z = {name: (median[name] - nominal[name]) / max(stds.get(name, 0.0), 1e-300) for name in median}
        loads.append(LoadReading(load=f"{mass:g} kg at {arm:g} m", runs=len(members), median=median, z=z))
    return loads


def health_nominal(document: GearedActuator) -> dict[str, float]:
    nominal = document.health
    values = {"fdj_nm": nominal.fdj, "eta_o": nominal.eta_o, "eta_a": nominal.eta_a}
    return {name: value for name, value in values.items() if value is not None}


def report(
    model: Model, runs: list[LoggedRun], document: GearedActuator, loads: list[LoadReading]
) -> GearedCalibration:
    """The ``ema-calibration/1`` report of a geared servo's calibration."""
    run_set = RunSet.of(runs)
    before, after = model.base.start, model.solved.values
    rms = {
        when: float(np.sqrt(np.mean((run_set.logged - run_set.simulated(v)) ** 2)))
        for when, v in (("before", before), ("after", after))
    }
    norm = float(np.linalg.norm(run_set.logged))
    pct = {when: 100.0 * rms[when] * np.sqrt(len(run_set.logged)) / norm for when in rms}
    health = health_values(model)
    learned = [
        Learned(name=name, value=v, std=s, unit=UNITS[name]) for name, (v, s) in section_constants(model).items()
    ]
    learned += [
        Learned(name=REPORTED[name], value=v, std=document.geared.stds.get(name, s), unit=UNITS[name])
        for name, (v, s) in health.items()
        if name == "fdj_nm" or "efficiency" in model.final.effects
    ]
    return GearedCalibration(
        n_windows=len(runs),
        noise_floor=model.noise_floor,
        residual_rms_before={"position_rad": rms["before"]},
        residual_rms_after={"position_rad": rms["after"]},
        candidates=model.candidates,
        selected_effect=model.final.effects[0] if model.final.effects else None,
        selected_effects=list(model.final.effects),
        selected_parameters={name: after[name] for name in CONSTANTS if name not in ("torque_per_volt", "back_emf")},
        effects={name: 1.0 for name in model.final.effects},
        selection_steps=model.steps,
        held_out=model.held,
        estimates_before={"FDJ": before["fdj_nm"]},
        estimates_after={REPORTED[name]: v for name, (v, _) in health.items()},
        stds_after={REPORTED[name]: document.geared.stds.get(name, s) for name, (_, s) in health.items()},
        learned=learned,
        model_error_pct_before={"position_rad": pct["before"]},
        model_error_pct_after={"position_rad": pct["after"]},
        position_error_rad={
            "before": float(np.mean(run_set.errors(before))),
            "after": float(np.mean(run_set.errors(after))),
            "held_out_before": model.base.held.score,
            "held_out_after": model.final.held.score,
        },
        by_load=loads,
        timings_s={},
    )


def calibrate_geared(
    windows: Sequence[GearedWindow],
    actuator: GearedActuator,
    config: PipelineConfig,
    on_stage: Callable[[str], None],
) -> tuple[GearedCalibration, GearedActuator]:
    """The report and the completed document of a geared servo's runs (module docstring)."""
    model, runs = learned_model(windows, actuator.geared, on_stage)
    document = completed_document(actuator, model)
    on_stage(f"answering each of the {len(windows)} runs with the completed document")
    read = read_runs(windows, document, config)
    document = repeatable(document, read)
    return report(model, runs, document, by_load(windows, read, document)), document


def report_lines(report: Mapping[str, Any]) -> list[str]:
    """The runs' mean position error before and after (in sample and held out), and each load's runs read with the
    completed document: their median health and its z against the nominal's std."""
    errors = report.get("position_error_rad", {})
    lines = []
    if errors:
        lines.append(
            f"position error: {errors['before']:.4f} -> {errors['after']:.4f} rad on average "
            f"(held out: {errors['held_out_before']:.4f} -> {errors['held_out_after']:.4f} rad)"
        )
    for load in report.get("by_load", []):
        said = ", ".join(f"{name} {value:.4g} (z {load['z'][name]:+.1f})" for name, value in load["median"].items())
        lines.append(f"{load['load']}: {load['runs']} run(s), median {said}")
    return lines
