"""The batch simulator end to end: closed-form answers, invariants, equivalences, bad input."""

import numpy as np
import pytest

from ema.kinds.rotary.simulator import kernels
from ema.kinds.rotary.simulator.batch import (
    LANE_MULTIPLE,
    MAX_LANES,
    MIN_VECTOR_LANES,
    InitialState,
    default_lanes,
    interval_steps,
    kernel_constants,
    simulate_batch,
)
from ema.kinds.rotary.simulator.commands import random_command_knots
from ema.kinds.rotary.simulator.effects import EffectSet
from ema.kinds.rotary.simulator.loads import GroundLoad, LoggedLoad, load_model
from ema.kinds.rotary.simulator.reference import simulate_numpy
from ema.kinds.rotary.simulator.residual import residual_torque_nm
from ema.model import runtime
from ema.model.actuator import THESIS
from ema.model.aircraft import FlightCondition
from ema.model.checks import InputError
from ema.model.params import DEFAULT_RANGES, DriveConstants, HealthParams, eta_a_from_eta_o
from tests.kinds.rotary.simulator.conftest import ramp_knots

RATE = 10_000.0


def test_stuck_below_the_break_away_load_and_slips_above_it(nominal):
    # Command = position = 0: the controller asks for nothing, so only the load drives the shaft.
    # Stuck, the load aids the drive, so it breaks away when η_A·|T_ext| > FSJ.
    threshold_nm = 0.10 / float(eta_a_from_eta_o(0.85, 500.0)) * 500.0
    below = simulate_batch(np.zeros(301), nominal, GroundLoad(0.8 * threshold_nm), drive=THESIS.params)
    above = simulate_batch(np.zeros(301), nominal, GroundLoad(1.25 * threshold_nm), drive=THESIS.params)
    assert np.all(below.signals["motor_speed_radps"] == 0.0)
    assert np.all(below.signals["position_deg"] == 0.0)
    assert np.abs(above.signals["motor_speed_radps"]).max() > 1.0


@pytest.mark.parametrize(("load_nm", "kind"), [(-100.0, "opposing"), (100.0, "aiding")])
def test_steady_sliding_loss_is_fdj_plus_load_part_plus_viscous(load_nm, kind):
    health = HealthParams.single(fdj_nm=0.045, eta_o=0.8)
    result = simulate_batch(ramp_knots(0.0, 10.0, 3000), health, GroundLoad(load_nm), drive=THESIS.params)
    steady = slice(1000, 3000)
    speed = result.signals["motor_speed_radps"][0, steady]
    assert speed.mean() == pytest.approx(np.radians(10.0) * 500, rel=0.01)
    t_ext = abs(load_nm) / 500
    k_load = 1 / 0.8 - 1 if kind == "opposing" else 1 - float(eta_a_from_eta_o(0.8, 500.0))
    expected = 0.045 + k_load * t_ext + DriveConstants().viscous_nms * speed
    np.testing.assert_allclose(result.loss_torque_nm[0, steady], expected, rtol=1e-3)
    # Eq. 5.3 from the recorded signals alone gives the same torque.
    residual = residual_torque_nm(
        result.signals["current_a"],
        result.signals["motor_speed_radps"],
        result.signals["hinge_moment_nm"],
        RATE,
        drive=THESIS.params,
    )[0, steady]
    assert residual.mean() == pytest.approx(expected.mean(), rel=0.02)


def test_elevator_follows_a_slow_command(nominal):
    t = np.arange(5001) / RATE
    command = 5.0 * np.sin(2 * np.pi * 1.0 * t)
    result = simulate_batch(command, nominal, FlightCondition(), drive=THESIS.params)
    error = result.signals["position_deg"][0, 200:] - result.signals["command_deg"][0, 200:]
    assert np.abs(error).max() < 0.5  # P-loop lag + half the 0.29° dead band
    assert np.abs(result.signals["command_deg"][0] - 0.5 * (command[1:] + command[:-1])).max() < 1e-3


def test_end_stops_hold(nominal):
    result = simulate_batch(
        np.full(2001, 35.0), nominal, FlightCondition(), InitialState(position_deg=28.0), drive=THESIS.params
    )
    position = result.signals["position_deg"][0]
    assert position.max() <= 30.0
    assert position[-500:].min() > 29.5
    assert np.all(result.signals["motor_speed_radps"][0, -500:] == 0.0)


def test_batch_equals_single_simulations_and_lanes_do_not_change_results():
    rng = np.random.default_rng(7)
    health = HealthParams.uniform(5, DEFAULT_RANGES, rng)
    knots = random_command_knots(400, RATE, rng)[0]
    batch = simulate_batch(knots, health, drive=THESIS.params)
    plain = simulate_batch(knots, health, lanes=1, drive=THESIS.params)  # one lane: the scalar path
    for name in batch.signals:
        np.testing.assert_array_equal(batch.signals[name], plain.signals[name])
    for i in (0, 3):
        single = simulate_batch(
            knots, HealthParams.single(health.fsj_nm[i], health.fdj_nm[i], health.eta_o[i]), drive=THESIS.params
        )
        for name in batch.signals:
            np.testing.assert_array_equal(batch.signals[name][i], single.signals[name][0])


def test_one_command_per_simulation_case_2():
    rng = np.random.default_rng(8)
    health = HealthParams.uniform(3, DEFAULT_RANGES, rng)
    knots = random_command_knots(300, RATE, rng, n_commands=3)
    batch = simulate_batch(knots, health, drive=THESIS.params)
    for i in range(3):
        single = simulate_batch(
            knots[i], HealthParams.single(health.fsj_nm[i], health.fdj_nm[i], health.eta_o[i]), drive=THESIS.params
        )
        np.testing.assert_array_equal(batch.signals["position_deg"][i], single.signals["position_deg"][0])


SENSOR_FAULTS = EffectSet(
    {
        "current_sensor_offset": {"offset_a": 0.3},
        "current_sensor_gain": {"gain": 1.05},
        "hinge_moment_bias": {"bias_nm": 5.0},
    }
)


@pytest.mark.parametrize("effects", [EffectSet(), SENSOR_FAULTS], ids=["base", "sensor faults"])
def test_kernel_matches_the_plain_numpy_model(effects):
    rng = np.random.default_rng(9)
    health = HealthParams.uniform(4, DEFAULT_RANGES, rng)
    knots = random_command_knots(30, RATE, rng)[0]
    initial = InitialState(position_deg=0.3, motor_speed_radps=50.0, current_a=2.0)
    fast = simulate_batch(knots, health, initial=initial, effects=effects, drive=THESIS.params)
    c = kernel_constants(DriveConstants(), effects)
    eta_a = health.eta_a(500.0)
    per_sim = np.stack([health.fdj_nm, health.fsj_nm, 1 - eta_a, 1 / health.eta_o - 1])
    start = np.repeat(np.array([[np.radians(0.3)], [50.0], [2.0]]), 4, axis=1)
    steps = np.full(30, 100)
    slow = simulate_numpy(c, load_model(FlightCondition(), 1e-4), per_sim, np.radians(knots)[None], start, steps)
    np.testing.assert_allclose(np.radians(fast.signals["position_deg"]), slow[0], atol=1e-12)
    np.testing.assert_allclose(fast.signals["motor_speed_radps"], slow[1], atol=1e-9)
    np.testing.assert_allclose(fast.signals["current_a"], slow[2], atol=1e-9)
    np.testing.assert_allclose(fast.signals["hinge_moment_nm"], slow[3], atol=1e-9)
    np.testing.assert_allclose(fast.loss_torque_nm, slow[5], atol=1e-9)


def test_any_log_rate_is_exact_intervals_of_whole_steps(nominal):
    # A 3 kHz log holds intervals of 333 or 334 steps; each recorded value is the mean of the
    # 1 µs values inside it, so it equals the step-weighted mean of a log taken every step.
    assert list(interval_steps(3, 3_000.0, drive=THESIS.params)) == [333, 334, 333]
    c = kernel_constants(DriveConstants(), EffectSet())
    load = load_model(FlightCondition(), 1 / 3_000.0)
    per_sim = np.tile(np.array([[0.05], [0.1], [1 - float(eta_a_from_eta_o(0.85, 500.0))], [1 / 0.85 - 1]]), (1, 8))
    initial = np.zeros((3, 8))
    every_step = np.empty((6, 8, 1000))
    knots = np.radians(np.linspace(0.0, 3.0, 1001))[None]
    frozen = load._replace(ad=np.eye(4), bd=np.zeros(4))  # the aircraft held still: only the logging differs
    kernels.run_group(c, (np.zeros(2), frozen, per_sim, knots, np.ones(1000, np.int64), initial), 0, 8, every_step)
    logged = np.empty((6, 8, 3))
    three = knots[:, [0, 333, 667, 1000]]
    steps = interval_steps(3, 3_000.0, drive=THESIS.params)
    kernels.run_group(c, (np.zeros(2), frozen, per_sim, three, steps, initial), 0, 8, logged)
    for k, (lo, hi) in enumerate([(0, 333), (333, 667), (667, 1000)]):
        for row in (kernels.SPEED, kernels.CURRENT):
            np.testing.assert_allclose(logged[row, 0, k], every_step[row, 0, lo:hi].mean(), rtol=1e-9)


def test_a_command_past_the_end_stops_acts_as_one_just_beyond_them(nominal):
    # Beyond ω_max/G_P ≈ 0.37° past the stops the speed reference is saturated: 45° and 31° are one command.
    far = simulate_batch(
        np.full(1001, 45.0), nominal, FlightCondition(), InitialState(position_deg=25.0), drive=THESIS.params
    )
    near = simulate_batch(
        np.full(1001, 31.0), nominal, FlightCondition(), InitialState(position_deg=25.0), drive=THESIS.params
    )
    np.testing.assert_array_equal(far.signals["position_deg"], near.signals["position_deg"])


def test_a_logged_load_reproduces_the_aircraft_that_logged_it(nominal):
    knots = random_command_knots(3000, RATE, np.random.default_rng(12))[0]
    flown = simulate_batch(knots, nominal, FlightCondition(120.0, 2000.0), drive=THESIS.params)
    logged = LoggedLoad(
        FlightCondition(120.0, 2000.0), flown.signals["hinge_moment_nm"][0], flown.signals["position_deg"][0]
    )
    replayed = simulate_batch(knots, nominal, logged, drive=THESIS.params)
    # The slow part is held per interval from the log, the δ term applied every step as in flight.
    assert np.abs(replayed.signals["hinge_moment_nm"] - flown.signals["hinge_moment_nm"]).max() < 0.5
    assert np.abs(replayed.signals["position_deg"] - flown.signals["position_deg"]).max() < 0.01
    np.testing.assert_allclose(replayed.loss_torque_nm.mean(), flown.loss_torque_nm.mean(), rtol=1e-3)


def test_thread_budget_does_not_change_results(nominal):
    from ema.model import runtime

    health = HealthParams.uniform(40, DEFAULT_RANGES, np.random.default_rng(2))
    knots = random_command_knots(200, RATE, np.random.default_rng(3))[0]
    before = runtime.threads()
    try:
        runtime.set_threads(1)
        one = simulate_batch(knots, health, lanes=8, drive=THESIS.params)
        runtime.set_threads(2)
        two = simulate_batch(knots, health, lanes=8, drive=THESIS.params)
    finally:
        runtime.set_threads(before)
    np.testing.assert_array_equal(one.signals["current_a"], two.signals["current_a"])


def test_a_kept_recording_buffer_gives_the_fresh_results_and_is_reused():
    knots = random_command_knots(200, RATE, np.random.default_rng(3))[0]
    first, second = (HealthParams.uniform(30, DEFAULT_RANGES, np.random.default_rng(seed)) for seed in (4, 5))
    kept = simulate_batch(knots, first, drive=THESIS.params, reuse_output=True).signals["current_a"].copy()
    np.testing.assert_array_equal(kept, simulate_batch(knots, first, drive=THESIS.params).signals["current_a"])
    a = simulate_batch(knots, first, drive=THESIS.params, reuse_output=True).signals["current_a"]
    b = simulate_batch(knots, second, drive=THESIS.params, reuse_output=True).signals["current_a"]
    assert np.shares_memory(a, b)  # the documented contract: the next such call overwrites the last


def test_simulation_is_deterministic(nominal):
    knots = random_command_knots(200, RATE, np.random.default_rng(3))[0]
    a, b = (
        simulate_batch(knots, nominal, drive=THESIS.params),
        simulate_batch(knots, nominal, drive=THESIS.params),
    )
    np.testing.assert_array_equal(a.signals["current_a"], b.signals["current_a"])


def test_aircraft_on_the_log_step_is_indistinguishable_from_a_finer_one(nominal):
    # The aircraft advances once per log interval; halving that interval must not move the outputs.
    knots = random_command_knots(1000, RATE, np.random.default_rng(4))[0]
    coarse = simulate_batch(knots, nominal, sample_rate_hz=RATE, drive=THESIS.params)
    fine_knots = np.interp(np.arange(2001) / 2, np.arange(1001), knots)
    fine = simulate_batch(fine_knots, nominal, sample_rate_hz=2 * RATE, drive=THESIS.params)
    fine_hinge = fine.signals["hinge_moment_nm"][0].reshape(-1, 2).mean(axis=1)
    assert np.abs(fine_hinge - coarse.signals["hinge_moment_nm"][0]).max() < 0.5  # of ~100 N·m
    fine_position = fine.signals["position_deg"][0].reshape(-1, 2).mean(axis=1)
    assert np.abs(fine_position - coarse.signals["position_deg"][0]).max() < 0.02


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"command_knots_deg": np.array([0.0, np.nan, 1.0])}, "command_knots_deg"),
        ({"command_knots_deg": np.zeros((2, 11))}, "command_knots_deg"),
        ({"sample_rate_hz": 200_000.0}, "sample_rate_hz"),
        ({"sample_rate_hz": 10.0}, "sample_rate_hz"),
        ({"initial": InitialState(position_deg=40.0)}, "initial.position_deg"),
        ({"initial": InitialState(motor_speed_radps=float("inf"))}, "initial.motor_speed_radps"),
        ({"health": "nominal"}, "health"),
        ({"effects": {"cogging": {}}}, "effects"),
    ],
)
def test_bad_input_names_the_argument(kwargs, field):
    arguments = {
        "command_knots_deg": np.zeros(11),
        "health": HealthParams.uniform(3, DEFAULT_RANGES, np.random.default_rng(0)),
    }
    arguments.update(kwargs)
    with pytest.raises(InputError) as error:
        simulate_batch(**arguments, drive=THESIS.params)
    assert error.value.field == field


def test_an_interrupted_batch_runs_none_of_its_queued_groups(monkeypatch):
    """Ctrl-C while a batch runs: the groups still queued are cancelled, and ``runtime.shutdown`` lets the
    threads end after the group each runs (Python's exit would otherwise run every queued group first)."""
    import _thread
    import threading
    import time

    from ema.kinds.rotary.simulator import batch
    from ema.model import runtime

    ran = []

    def slow_group(*args):
        time.sleep(0.02)
        ran.append(1)

    monkeypatch.setattr(batch.kernels, "run_group", slow_group)
    runtime.set_threads(2)
    timer = threading.Timer(0.1, _thread.interrupt_main)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        batch.run_groups((), np.empty((1, 400 * 8, 1)), 8)  # 400 groups: 4 s on two threads
    runtime.shutdown()
    settled = len(ran)
    time.sleep(0.2)
    assert settled < 50 and len(ran) <= settled + 2


@pytest.mark.parametrize("threads", [1, 2, 4])
def test_default_lanes_fill_the_threads_with_whole_loop_iterations_and_little_padding(threads):
    before = runtime.threads()
    runtime.set_threads(threads)
    try:
        assert default_lanes(1) == 1 and default_lanes(5) == 5  # scalar anyway: no padding
        for n in range(8, 1200, 7):
            lanes = default_lanes(n)
            groups = -(-n // lanes)
            assert lanes % LANE_MULTIPLE == 0 and MIN_VECTOR_LANES <= lanes <= MAX_LANES
            busiest, fair = -(-groups // threads) * lanes, -(-n // threads)  # lanes on the busiest thread
            assert busiest - fair < MAX_LANES  # within one group of a fair share
            if n >= threads * MAX_LANES:
                assert groups >= threads  # every thread has a group
        if threads == 2:
            assert default_lanes(89) == 48 and default_lanes(500) == 72  # the pipeline's batch, the benchmarks'
    finally:
        runtime.set_threads(before)
