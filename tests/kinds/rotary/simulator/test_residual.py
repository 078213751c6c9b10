import numpy as np
import pytest

from ema.kinds.rotary.simulator.batch import simulate_batch
from ema.kinds.rotary.simulator.commands import random_command_knots
from ema.kinds.rotary.simulator.loads import GroundLoad
from ema.kinds.rotary.simulator.residual import (
    above_throughout,
    derivative_weights,
    kernel_samples,
    residual_torque_nm,
    smooth_derivative,
    smoothed,
    smoothing_weights,
)
from ema.kinds.rotary.simulator.sensor_noise import add_sensor_noise
from ema.model.actuator import THESIS
from ema.model.checks import InputError
from ema.model.noise import SensorNoise
from ema.model.params import HealthParams

RATE = 10_000.0


def test_derivative_is_exact_for_a_parabola_inside_and_for_a_line_everywhere():
    t = np.arange(400) / RATE
    parabola = smooth_derivative(3.0 + 2.0 * t + 50.0 * t**2, RATE)
    np.testing.assert_allclose(parabola[10:-10], (2.0 + 100.0 * t)[10:-10], rtol=1e-9)
    np.testing.assert_allclose(parabola, 2.0 + 100.0 * t, atol=0.05)  # ends: curvature leaks into the reflection
    np.testing.assert_allclose(smooth_derivative(1.0 - 7.0 * t, RATE), -7.0, rtol=1e-9)


def test_smoothing_keeps_a_line_and_a_constant():
    t = np.arange(300) / RATE
    np.testing.assert_allclose(smoothed(1.5 + 4.0 * t, RATE)[30:-30], 1.5 + 4.0 * t[30:-30], atol=1e-12)


def test_the_compiled_filters_equal_a_plain_correlation_of_the_reflected_rows():
    values = np.random.default_rng(2).normal(size=(3, 200))
    half = kernel_samples(RATE) // 2
    head, tail = values[:, half:0:-1], values[:, -2 : -half - 2 : -1]
    for got, weights, pad in (
        (smoothed(values, RATE), smoothing_weights(half), (head, tail)),
        (
            smooth_derivative(values, RATE),
            derivative_weights(half, RATE),
            (2 * values[:, :1] - head, 2 * values[:, -1:] - tail),
        ),
    ):
        padded = np.concatenate([pad[0], values, pad[1]], axis=1)
        want = np.stack([np.correlate(row, weights, "valid") for row in padded])
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-9)


def test_residual_torque_reconstructs_the_true_loss_on_clean_data():
    knots = random_command_knots(3000, RATE, np.random.default_rng(11))[0]
    result = simulate_batch(knots, HealthParams.single(), GroundLoad(-60.0, 100.0), drive=THESIS.params)
    signals = result.simulation(0)
    residual = residual_torque_nm(
        signals["current_a"], signals["motor_speed_radps"], signals["hinge_moment_nm"], RATE, drive=THESIS.params
    )
    truth = smoothed(result.loss_torque_nm[0], RATE)  # the same kernel: T_R is the true loss seen through it
    moving = np.abs(signals["motor_speed_radps"]) > 20
    error = residual[moving] - truth[moving]
    assert np.sqrt(np.mean(error**2)) < 0.01  # N·m, against FDJ ≈ 0.05 and a total of ≈ 0.1


def test_filter_cuts_speed_noise_below_fdj():
    rng = np.random.default_rng(1)
    knots = random_command_knots(5000, RATE, rng)[0]
    clean = simulate_batch(knots, HealthParams.single(), drive=THESIS.params).simulation(0)
    noisy = add_sensor_noise(clean, SensorNoise(), rng)

    def reconstruct(signals):
        return residual_torque_nm(
            signals["current_a"], signals["motor_speed_radps"], signals["hinge_moment_nm"], RATE, drive=THESIS.params
        )

    difference = reconstruct(noisy) - reconstruct(clean)
    assert difference.std() < 0.01  # a plain 10 kHz difference would give ≈ 0.09 N·m


def test_batch_and_single_reconstruction_agree():
    rng = np.random.default_rng(2)
    current, speed, hinge = rng.normal(size=(3, 4, 500))
    batch = residual_torque_nm(current, speed, hinge, RATE, drive=THESIS.params)
    np.testing.assert_allclose(batch[2], residual_torque_nm(current[2], speed[2], hinge[2], RATE, drive=THESIS.params))


def test_the_one_pass_reconstruction_equals_its_steps_on_a_batch_split_over_threads(threads):
    threads(2)
    rng = np.random.default_rng(5)
    current, speed, hinge = 8.0 * rng.normal(size=(3, 40, 700))  # some currents past the torque's saturation
    a = THESIS.params
    motor = np.clip(a.torque_constant_nm_per_a * current, -a.max_motor_torque_nm, a.max_motor_torque_nm)
    plain = smoothed(motor + hinge / a.gear_ratio, RATE) - a.inertia_kgm2 * smooth_derivative(speed, RATE)
    np.testing.assert_array_equal(residual_torque_nm(current, speed, hinge, RATE, drive=a), plain)
    # one signal of a batch against one window of the others
    np.testing.assert_array_equal(
        residual_torque_nm(current, speed[0], hinge[0], RATE, drive=a)[3],
        residual_torque_nm(current[3], speed[0], hinge[0], RATE, drive=a),
    )


def test_bad_inputs_are_named():
    with pytest.raises(InputError, match="motor_speed_radps"):
        residual_torque_nm(np.zeros(100), np.full(100, np.nan), np.zeros(100), RATE, drive=THESIS.params)
    with pytest.raises(InputError, match="shapes differ"):
        residual_torque_nm(np.zeros(100), np.zeros(99), np.zeros(100), RATE, drive=THESIS.params)
    with pytest.raises(InputError, match="need more than"):
        residual_torque_nm(np.zeros(10), np.zeros(10), np.zeros(10), RATE, drive=THESIS.params)


def test_sliding_mask_leaves_out_the_edges_where_the_kernel_is_padded():
    # The padded end of the derivative leans on the last few samples: its noise grows ~4x there,
    # and the errors of those samples move together (one window's 9 edge samples held 35 mN·m).
    t = np.arange(400) / RATE
    speed = 200.0 + 2e4 * t
    noisy = speed + np.random.default_rng(3).normal(0.0, 0.5, (2000, t.size))
    current = np.full_like(noisy, 5.0)
    hinge = np.full_like(noisy, -40.0)
    spread = residual_torque_nm(current, noisy, hinge, RATE, drive=THESIS.params).std(axis=0)
    kept = above_throughout(speed, 30.0, kernel_samples(RATE))
    assert not kept[: kernel_samples(RATE) // 2].any() and not kept[-(kernel_samples(RATE) // 2) :].any()
    assert spread[kept].max() < 1.15 * np.median(spread)
    assert spread[~kept].max() > 3 * np.median(spread)


def test_above_throughout_equals_its_definition():
    rng = np.random.default_rng(1)
    for shape, width in [((300,), 21), ((4, 300), 7), ((4, 300), 1), ((5,), 21)]:
        values = rng.normal(1.0, 1.0, shape)
        half = width // 2
        want = np.zeros(shape, dtype=bool)
        for i in range(half, shape[-1] - half):
            want[..., i] = np.all(values[..., i - half : i + half + 1] > 0.2, axis=-1)
        np.testing.assert_array_equal(above_throughout(values, 0.2, width), want)
