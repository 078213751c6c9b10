"""Twins: effects that leave the same trace in the residual torque, told apart by simulation.

A torque constant g and a current-sensor gain s both leave a term in k_T·I in the residual torque;
only the first also changes the back-EMF (k_e = k_T), hence how much voltage is left to drive current
near top speed, hence how the motor speed and current evolve. An inertia off the document's leaves a
term in dω/dt, which k_T·I mostly is, and moves how fast the speed follows the current. A current
sensor and a hinge-moment sensor off zero both leave a constant in T_R; only the first is felt by the
loop, which regulates the logged current. Each twin is added to the simulator in turn, the window
simulated at the estimates solved again with it (each reading at its own FDJ and η_O), and the one whose
speed and current stay closer to the measured ones (in units of their noise) is named; the other is
reported as indistinguishable when the difference is small. ``runners_up`` is what the simulation sets
against an effect: its twins, always, and the named families that read the windows about as well.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ema.calibration.limits import NAME_Z
from ema.kinds.rotary.physics.scenario import CLEAR_MARGIN, following_error, inside, scenario_from_window
from ema.kinds.rotary.selection import NAME_MARGIN, Evidence
from ema.kinds.rotary.simulator.effects import EffectSet
from ema.model.actuator import RotaryActuator
from ema.model.noise import SensorNoise
from ema.model.window import RotaryWindow

# Look-alikes, each with the others of its group. An inertia ΔJ leaves ΔJ·dω/dt, which a gain of k_T·I
# (mostly the load and J_M·dω/dt) nearly matches; only its simulation moves the speed otherwise. A current
# sensor off zero and a hinge-moment sensor off zero both leave a constant in T_R, sgn(ω)·c in t; only the
# first is felt by the loop (it regulates the logged current), and only the second moves the load columns.
GROUPS = (("torque_constant", "current_sensor_gain", "inertia"), ("hinge_moment_bias", "current_sensor_offset"))
TWINS = {name: tuple(other for other in group if other != name) for group in GROUPS for name in group}


def output_error(
    windows: Sequence[RotaryWindow],
    estimates: Mapping[str, float],
    option: Evidence | None,
    noise: Sequence[SensorNoise],
    actuator: RotaryActuator,
    beside: Sequence[Evidence] = (),
) -> float:
    """Mean over windows of RMS(speed)/σ_speed + RMS(current)/σ_current, simulated at ``estimates`` with
    ``option``'s effect added (None: no more than ``beside``, the effects already chosen)."""
    effects = simulated_effects([*beside, *([option] if option is not None else [])])
    if effects is None:
        return float("inf")  # a gain outside what the simulator admits: not this reading
    health = inside(estimates["FDJ"], estimates["eta_O"], actuator.health.fdj)
    errors = [
        following_error(scenario_from_window(w, actuator.params, actuator.hinge, effects), w, health, level)
        for w, level in zip(windows, noise, strict=True)
    ]
    return float(np.mean(errors))


def simulated_effects(options: Sequence[Evidence]) -> EffectSet | None:
    """The simulator's terms for ``options`` together (one friction table: the first); None where one of them is
    outside what the simulator admits."""
    terms = [option.family.term(option.beta, option.grid) for option in options]
    return None if any(term is None for term in terms) else EffectSet.combined(t for t in terms if t is not None)


def tell_apart(
    windows: Sequence[RotaryWindow],
    readings: Mapping[str, Mapping[str, float]],
    options: Sequence[Evidence],
    noise: Sequence[SensorNoise],
    actuator: RotaryActuator,
    beside: Sequence[Evidence] = (),
) -> tuple[Evidence, dict[str, float], bool]:
    """The reading whose simulation follows the windows best, each simulated at its own estimates
    (``readings``, by effect name) beside the effects already chosen, each one's output error, and whether the
    call is clear."""
    errors = {
        o.family.name: output_error(windows, readings[o.family.name], o, noise, actuator, beside) for o in options
    }
    ranked = sorted(options, key=lambda o: errors[o.family.name])
    best, runner = errors[ranked[0].family.name], errors[ranked[1].family.name]
    return ranked[0], errors, runner > (1 + CLEAR_MARGIN) * best


def runners_up(pick: Evidence, found: Sequence[Evidence], alike: Sequence[str], *, wide: bool) -> list[Evidence]:
    """What the simulation sets against ``pick``: its twins, and the named families that explain held-out
    samples about as well (within ``NAME_MARGIN``), but for one set aside as the same trace with more shapes
    (``alike``: the simpler is the reading). ``wide`` (``pick``'s reading moves the estimates beyond their
    stds): also those that explain the measured samples about as well, though held-out folds cannot tell (an
    inertia lives in the few samples that accelerate, and a fold without them cannot read it)."""
    twins = set(TWINS.get(pick.family.name, ()))

    def rival(e: Evidence) -> bool:
        if e.family.name in twins:
            return True  # the same trace in the equations by construction: only the simulation tells them apart
        if e.family.name in alike or (
            e.family.follows == pick.family.follows and len(e.family.grid) > len(pick.family.grid)
        ):
            return False
        held_out = e.z >= NAME_Z and e.improvement >= (1 - NAME_MARGIN) * pick.improvement
        in_sample = wide and e.rms_reduction >= (1 - NAME_MARGIN) * pick.rms_reduction
        return held_out or in_sample

    return [e for e in found if e.family.named and e.family.name != pick.family.name and rival(e)]
