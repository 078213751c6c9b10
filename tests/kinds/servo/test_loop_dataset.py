"""The servo's dataset carrying a window's misfit: each simulation's inputs gain the misfit whole, shifted and
signed, reproducibly from its seed, and nothing else moves."""

import numpy as np

from ema.kinds.servo.closed_loop import ServoRuns
from ema.kinds.servo.loop_dataset import ServoData, carrying


def _data(simulations: int, bins: int) -> ServoData:
    runs = ServoRuns(position_m=np.zeros((simulations, 3)), drive_force_n=np.zeros((simulations, 3)))
    inputs = np.arange(simulations * bins, dtype=float).reshape(simulations, bins)
    return ServoData(("fdj_n",), np.zeros(1), np.ones(1), np.zeros((simulations, 1)), runs, inputs, np.zeros(bins))


def test_every_simulation_carries_the_misfit_whole_at_its_own_shift_and_sign():
    data, misfit = _data(40, 6), np.array([3.0, -1.0, 0.5, 0.0, 2.0, -4.0])
    carried = carrying(data, misfit, seed=11)
    added = carried.inputs - data.inputs
    rolls = {shift: np.roll(misfit, shift) for shift in range(len(misfit))}
    for row in added:
        assert any(np.array_equal(row, sign * rolled) for rolled in rolls.values() for sign in (1.0, -1.0))
    assert len({tuple(row) for row in added}) > 4  # shifts and signs drawn, not one copy for all
    assert np.array_equal(carrying(data, misfit, seed=11).inputs, carried.inputs)
    assert np.array_equal(carried.window_inputs, data.window_inputs) and np.array_equal(carried.truth, data.truth)
