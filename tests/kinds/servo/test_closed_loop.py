"""The servo's closed loop: the compiled kernel is its Python twin, a load within its static level stays put,
and the loop follows the closed-form foreign servo (another integration, the same physics)."""

import numpy as np
import pytest

from ema.kinds.servo import closed_loop as servo_sim
from ema.kinds.servo.closed_loop import LANE_PARAMETERS, ServoLoop, simulate_servo
from tests.foreign import servo as foreign

LOOP = ServoLoop(foreign.KP, foreign.KV, foreign.GAIN, foreign.LIMIT, 1.0 / foreign.RATE_HZ, foreign.STEP_M)


def _lane(**values: float) -> np.ndarray:
    healthy = {"mass_kg": 90.0, "fdj_n": 20.0, "viscous_up_ns_per_m": 200.0, "viscous_down_ns_per_m": 200.0}
    lane = dict.fromkeys(LANE_PARAMETERS, 0.0) | healthy | {"offset_n": -3.0} | values
    return np.array([[lane[name] for name in LANE_PARAMETERS]])


def test_the_compiled_kernel_is_its_python_twin():
    reference = foreign.set_point(3, seconds=1.5)
    params = np.vstack(
        [
            _lane(),
            _lane(stribeck_n=4.0, stribeck_speed_mps=0.01, presliding_n=5.0, presliding_travel_m=1e-4),
            _lane(turn_ripple_sin_n=1.5, turn_ripple_cos_n=-0.8, turn_ripple_travel_m=2.5e-3),
        ]
    )
    outputs = []
    for kernel in (servo_sim.run_lanes, servo_sim.run_lanes.py_func):
        q, f = np.empty((3, len(reference))), np.empty((3, len(reference)))
        constants = np.array(
            [
                LOOP.position_gain_per_s,
                LOOP.speed_gain_per_mps,
                LOOP.drive_gain_n_per_unit,
                LOOP.command_limit,
                LOOP.period_s,
                LOOP.resolution_m,
            ]
        )
        kernel(
            reference,
            0.5 * np.sin(np.arange(len(reference)) / 40.0),  # a command added to the controller's
            np.zeros(len(reference)),
            constants,
            np.array(LOOP.taps),
            params,
            np.zeros(3),
            np.array([reference[0], 0.0]),
            0,
            3,
            q,
            f,
        )
        outputs.append((q, f))
    assert np.allclose(outputs[0][0], outputs[1][0], rtol=0, atol=1e-12)
    assert np.allclose(outputs[0][1], outputs[1][1], rtol=0, atol=1e-9)


def test_a_load_held_within_its_static_level_stays_at_rest():
    reference = np.full(500, 0.1)  # the set point 10 µm off the load: a force of 5.4 N, under FDJ's 20 N
    run = simulate_servo(reference + 1e-5, _lane(offset_n=0.0), LOOP, start=(0.1, 0.0))
    assert np.all(run.position_m[0] == run.position_m[0, 0])
    assert np.allclose(run.drive_force_n[0], foreign.GAIN * foreign.KV * foreign.KP * 1e-5, rtol=1e-3)


@pytest.mark.parametrize("seed", [0, 1])
def test_the_closed_loop_follows_the_foreign_servo(seed):
    load = foreign.Load(viscous_down_ns_per_m=260.0)
    reference = foreign.set_point(seed, seconds=6.0)
    position, force = foreign.simulate(reference, load)
    lane = _lane(mass_kg=load.mass_kg, fdj_n=load.fdj_n, viscous_down_ns_per_m=260.0, offset_n=load.offset_n)
    run = simulate_servo(reference, lane, LOOP, start=(reference[0], 0.0))
    assert np.sqrt(np.mean((run.position_m[0] - position) ** 2)) < 2e-6  # 2 µm on a 0.25 m stroke
    assert np.linalg.norm(run.drive_force_n[0] - force) / np.linalg.norm(force) < 0.02


def test_a_force_once_per_turn_follows_the_foreign_servos():
    """The foreign servo holds the turn's force over each 100th of a sample and solves the load between; ours takes it
    at each of ten steps: the same force along the travel, read alike, and without it the loops part."""
    load = foreign.Load(turn_n=(1.5, -0.8))
    reference = foreign.set_point(0, seconds=6.0)
    _, force = foreign.simulate(reference, load)
    ripple = {"turn_ripple_sin_n": 1.5, "turn_ripple_cos_n": -0.8, "turn_ripple_travel_m": load.travel_per_turn_m}
    errors = []
    for lane in (_lane(**ripple), _lane()):
        run = simulate_servo(reference, lane, LOOP, start=(reference[0], 0.0))
        errors.append(np.linalg.norm(run.drive_force_n[0] - force) / np.linalg.norm(force))
    assert errors[0] < 0.005 < 0.015 < errors[1]


def test_a_command_added_to_the_controllers_is_logged_as_the_drive_applies_it():
    """With the load at rest, the logged force is g·sat(the controller's command + the added one): the added command
    passes the limit's saturation like the controller's own."""
    n = 200
    added = np.where(np.arange(n) % 50 < 10, 3.0 * foreign.LIMIT, -0.05)  # pulses past the limit, a small offset
    heavy = _lane(fdj_n=1e6, offset_n=0.0)  # static friction holds the load: position and speed stay 0
    run = simulate_servo(np.zeros(n), heavy, LOOP, added_command=added)
    assert np.all(run.position_m[0] == 0.0)
    assert np.allclose(run.drive_force_n[0], foreign.GAIN * np.clip(added, -foreign.LIMIT, foreign.LIMIT))


def test_an_added_command_of_another_length_is_refused_naming_it():
    from ema.model.checks import InputError

    with pytest.raises(InputError, match="added_command"):
        simulate_servo(np.zeros(100), _lane(), LOOP, added_command=np.zeros(99))
