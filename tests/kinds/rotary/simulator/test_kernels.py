"""One step of the kernel against the closed-form Borello friction: the five stick/slip situations."""

import numpy as np
import pytest

from ema.kinds.rotary.simulator.batch import kernel_constants
from ema.kinds.rotary.simulator.effects import EffectSet
from ema.kinds.rotary.simulator.kernels import advance
from ema.model.params import DriveConstants, eta_a_from_eta_o

ACTUATOR = DriveConstants()
FDJ, FSJ, ETA_O = 0.05, 0.10, 0.85
K_AID = 1.0 - float(eta_a_from_eta_o(ETA_O, 500.0))
K_OPP = 1.0 / ETA_O - 1.0
H_OVER_J = ACTUATOR.step_s / ACTUATOR.inertia_kgm2


def step(speed: float, load_nm: float) -> tuple[float, float, float]:
    """One step with the controller switched off and a load torque ``load_nm`` at the motor shaft.

    Returns (new speed, loss torque, driving torque) where the drive is computed from the current
    the step produced, exactly as the friction model saw it.
    """
    c = kernel_constants(ACTUATOR, EffectSet())._replace(position_gain=0.0, speed_gain_over_kt=0.0)
    levels = (load_nm, 0.0, FDJ, FSJ, K_AID, K_OPP)
    current, new_speed, _, _, loss = advance(c, 0.0, 0.0, levels, (0.0, speed, 0.0, 0.0))
    drive = ACTUATOR.torque_constant_nm_per_a * current + load_nm - ACTUATOR.viscous_nms * speed
    return new_speed, loss, drive


def test_stuck_below_break_away_stays_stuck():
    load = 0.8 * FSJ / (1.0 - K_AID)  # aiding: threshold is FSJ + (1 − η_A)|T_ext|
    new_speed, loss, drive = step(0.0, load)
    assert new_speed == 0.0
    assert loss == pytest.approx(drive)  # friction balances the drive exactly


def test_stuck_above_break_away_slips_with_dynamic_friction():
    load = 0.2
    assert load > FSJ + K_AID * load  # above the static level
    new_speed, loss, drive = step(0.0, load)
    expected_friction = FDJ + K_AID * load
    assert new_speed == pytest.approx(H_OVER_J * (drive - expected_friction))
    assert new_speed > 0.0
    assert loss == pytest.approx(expected_friction)


def test_slipping_keeps_slipping_against_an_opposing_load():
    new_speed, loss, drive = step(100.0, -0.2)
    friction = FDJ + K_OPP * 0.2
    assert new_speed == pytest.approx(100.0 + H_OVER_J * (drive - friction))
    assert loss == pytest.approx(friction + ACTUATOR.viscous_nms * 100.0)


def test_slipping_stops_instead_of_crossing_zero():
    new_speed, _, _ = step(1e-3, -0.2)
    assert new_speed == 0.0


def test_slipping_reverses_through_a_stop():
    stopped, _, _ = step(1e-3, -0.3)
    assert stopped == 0.0
    reversed_speed, loss, _ = step(stopped, -0.3)
    assert reversed_speed < 0.0  # the load now aids the motion it causes
    assert loss == pytest.approx(-(FDJ + K_AID * 0.3))


def test_aiding_and_opposing_use_their_own_efficiency():
    _, loss_aiding, _ = step(50.0, 0.3)
    _, loss_opposing, _ = step(50.0, -0.3)
    viscous = ACTUATOR.viscous_nms * 50.0
    assert loss_aiding - viscous == pytest.approx(FDJ + K_AID * 0.3)
    assert loss_opposing - viscous == pytest.approx(FDJ + K_OPP * 0.3)


def test_irreversible_transmission_never_back_drives():
    eta_o = 0.44  # Case 1C low end: η_A < 0
    k_aid = 1.0 - float(eta_a_from_eta_o(eta_o, 500.0))
    assert k_aid > 1.0
    c = kernel_constants(ACTUATOR, EffectSet())._replace(position_gain=0.0, speed_gain_over_kt=0.0)
    for load in (0.1, 0.5, 1.0):
        _, new_speed, *_ = advance(c, 0.0, 0.0, (load, 0.0, FDJ, FSJ, k_aid, 1 / eta_o - 1), (0.0, 0.0, 0.0, 0.0))
        assert new_speed == 0.0


def test_end_stop_clamps_angle_and_stops_the_shaft():
    c = kernel_constants(ACTUATOR, EffectSet())
    stop = np.radians(30.0)
    levels = (0.0, 0.0, FDJ, FSJ, K_AID, K_OPP)
    _, speed, angle, position, _ = advance(c, 0.0, stop + 0.1, levels, (20.0, 600.0, stop, stop))
    assert angle == stop
    assert speed == 0.0
    assert position <= stop
