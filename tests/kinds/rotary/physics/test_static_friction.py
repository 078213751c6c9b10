"""FSJ at quasi-static break-aways: hand-drawn traces, noisy ground ramps, and foreign flight windows."""

import numpy as np
import pytest

from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.static_friction import read_static_friction
from ema.kinds.rotary.prepare.conditioning import prepare
from ema.kinds.rotary.simulator.batch import simulate_batch
from ema.kinds.rotary.simulator.loads import GroundLoad
from ema.kinds.rotary.simulator.sensor_noise import add_sensor_noise
from ema.model.actuator import THESIS
from ema.model.noise import SensorNoise
from ema.model.params import DriveConstants, HealthParams
from ema.model.window import window_from_dict
from tests.foreign.windows import Effects, draw

RATE = 10_000.0
KT = DriveConstants().torque_constant_nm_per_a


def trace(rest_speed_radps: float, rest_current_a: np.ndarray, after_current_a: float, seed: int) -> dict:
    """A hand-drawn window, no simulator: a rest (speed ``rest_speed_radps``, the given current), then
    the shaft accelerates to 60 rad/s in 5 ms at ``after_current_a``; no hinge load, sensor noise added."""
    rng = np.random.default_rng(seed)
    n_rest, n_move = len(rest_current_a), 300
    speed = np.concatenate([np.full(n_rest, rest_speed_radps), np.minimum(np.arange(1, n_move + 1) * 1.2, 60.0)])
    current = np.concatenate([rest_current_a, np.full(n_move, after_current_a)])
    n = n_rest + n_move
    return {
        "motor_speed_radps": speed + 0.5 * rng.standard_normal(n),
        "current_a": current + 0.05 * rng.standard_normal(n),
        "hinge_moment_nm": 2.0 * rng.standard_normal(n),
        "position_deg": 5.0 + 0.01 * rng.standard_normal(n),
    }


def _foreign_reading(seed: int, family: str, rate: float, effects: Effects | None = None):
    window = draw(seed, family, sample_rate_hz=rate, effects=effects or Effects())
    w = prepare(window_from_dict(window.document), actuator=THESIS).window
    found = read_static_friction(
        as_read(w.signals, w.sample_rate_hz),
        w.sample_rate_hz,
        window.truth["FDJ"],
        window.truth["eta_O"],
        THESIS.params,
    )
    return found, window.truth["FSJ"]


@pytest.mark.parametrize("seed", range(4))
def test_a_drive_that_creeps_up_to_the_break_away_reads_its_level(seed):
    level_a = 1.4  # FSJ = k_T · 1.4 A ≈ 0.105 N·m (no load)
    window = trace(0.0, np.linspace(0.4, level_a, 400), 0.7, seed)
    found = read_static_friction(window, RATE, 0.05, 0.85, drive=THESIS.params)
    assert found.value_nm is not None and found.std_nm is not None
    assert abs(found.value_nm - KT * level_a) < 2 * found.std_nm


@pytest.mark.parametrize("seed", range(4))
def test_a_hold_then_a_jump_in_drive_is_not_a_break_away(seed):
    # Held still at a drive below the static level, then stepped: the hold only bounds FSJ from below.
    window = trace(0.0, np.full(400, 0.8), 15.0, seed)
    found = read_static_friction(window, RATE, 0.05, 0.85, drive=THESIS.params)
    assert found.value_nm is None and found.reason.code == "fsj_no_break_away"


@pytest.mark.parametrize("seed", range(4))
def test_a_shaft_creeping_under_dynamic_friction_is_not_stuck(seed):
    # 0.3 rad/s passes for rest in a 0.5 rad/s-noisy log; its drive rises, but it never stuck.
    window = trace(0.3, np.linspace(0.4, 1.4, 400), 0.7, seed)
    assert read_static_friction(window, RATE, 0.05, 0.85, drive=THESIS.params).value_nm is None


@pytest.mark.parametrize("fsj", [0.085, 0.115])
def test_reads_fsj_at_a_quasi_static_break_away(fsj):
    # On ground with a rising load and the command held, the shaft rests until the load breaks it away.
    result = simulate_batch(
        np.zeros(3001), HealthParams.single(fsj, 0.05, 0.85), GroundLoad(-20.0, -600.0), drive=THESIS.params
    )
    found = read_static_friction(result.simulation(0), 10_000.0, 0.05, 0.85, drive=THESIS.params)
    assert found.value_nm == pytest.approx(fsj, rel=0.02)
    assert found.std_nm is not None and found.std_nm > 0


@pytest.mark.parametrize("seed", range(5))
def test_steps_and_doublets_give_no_fsj_rather_than_a_wrong_one(seed):
    # After a pilot's step the drive jumps past the static level in one log interval: nothing to read.
    found, truth = _foreign_reading(100 + seed, ("steps", "doublet")[seed % 2], 10_000.0)
    if found.value_nm is not None:
        assert abs(found.value_nm - truth) < 2 * found.std_nm
    else:
        assert found.reason.code in ("fsj_no_break_away", "fsj_below_fdj")


@pytest.mark.parametrize("fsj", [0.085, 0.115])
def test_noisy_ground_ramps_read_fsj_within_their_std(fsj):
    # On ground with the command held, a load ramp (slow to fast) breaks the shaft away; sensor noise drawn.
    z, answered = [], 0
    for rate_nm_per_s in (-200.0, -600.0, -2000.0):
        clean = simulate_batch(
            np.zeros(3001),
            HealthParams.single(fsj, 0.05, 0.85),
            GroundLoad(-20.0, rate_nm_per_s),
            drive=THESIS.params,
        )
        for seed in range(5):
            noisy = add_sensor_noise(clean.simulation(0), SensorNoise(), np.random.default_rng(seed))
            found = read_static_friction(noisy, RATE, 0.05, 0.85, drive=THESIS.params)
            if found.value_nm is not None and found.std_nm is not None:
                answered += 1
                z.append((found.value_nm - fsj) / found.std_nm)
    assert answered >= 13
    assert np.mean(np.abs(z) <= 2) >= 0.9


@pytest.mark.parametrize(("seed", "rate"), [(329, 10_000.0), (331, 10_000.0), (303, 50_000.0)])
def test_foreign_holds_between_steps_give_no_fsj(seed, rate):
    # These windows hold the elevator against its load between steps; the first reader took the hold's
    # drive for the static level and answered 35-50 % low with a 10 % std.
    found, _ = _foreign_reading(seed, "steps", rate)
    assert found.value_nm is None and found.reason.code == "fsj_no_break_away"


def test_foreign_cruise_readings_hold_their_std():
    # About 1 cruise window in 100 rests at a reversal and creeps free; these four (of seeds 300-452) do.
    readings = [_foreign_reading(seed, "cruise", 10_000.0) for seed in (369, 419, 449, 452)]
    given = [(f.value_nm, f.std_nm, truth) for f, truth in readings if f.value_nm is not None and f.std_nm]
    assert len(given) >= 3
    assert all(abs(value - truth) < 2 * std for value, std, truth in given)


def test_a_drive_that_dithers_widens_its_fsj_std_to_hold_the_truth():
    # A loop that reads a speed with 0.4 rad/s of noise dithers the current by ~0.25 A: the shaft breaks
    # free at a peak hidden inside a log interval. Of seeds 600-899 of cruise, doublet and gust commands,
    # 14 windows give an FSJ; on these six the reader with the sensor-noise std alone answered 2.3-8.8 std low.
    cases = [(638, "cruise"), (664, "cruise"), (735, "cruise"), (790, "cruise"), (733, "doublet"), (857, "gust")]
    readings = [
        _foreign_reading(seed, family, RATE, Effects(loop_noise_radps=0.4, loop_noise_seed=seed))
        for seed, family in cases
    ]
    given = [(f.value_nm, f.std_nm, truth) for f, truth in readings if f.value_nm is not None and f.std_nm]
    assert len(given) == len(cases)
    assert all(abs(value - truth) < 2 * std for value, std, truth in given)
    assert all(std > 0.15 * value for value, std, _ in given)  # wider than the 10 % of a quiet drive
