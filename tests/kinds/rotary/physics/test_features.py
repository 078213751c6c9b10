import numpy as np
import pytest

from ema.kinds.rotary.physics.features import as_read, bin_means, features
from ema.kinds.rotary.physics.friction import solve_friction
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.checks import InputError
from ema.model.params import HealthParams
from tests.foreign.windows import draw, noisy


def test_bin_means_cover_every_sample():
    values = np.arange(10.0)
    np.testing.assert_allclose(bin_means(values, 5), [0.5, 2.5, 4.5, 6.5, 8.5])
    uneven = bin_means(values, 3)  # bins of 3, 4, 3 samples
    assert len(uneven) == 3
    assert uneven.sum() == pytest.approx((0 + 1 + 2) / 3 + (3 + 4 + 5 + 6) / 4 + (7 + 8 + 9) / 3)
    with pytest.raises(InputError, match="n_timesteps"):
        bin_means(values, 11)


def test_the_same_features_for_a_batch_row_and_a_single_window():
    windows = [synthetic_window(HealthParams.single(fdj_nm=f), seed=2, duration_s=0.05) for f in (0.045, 0.055)]
    batch = {name: np.stack([w.signals[name] for w in windows]) for name in windows[0].signals}
    together = features(batch, 10_000.0, 100, THESIS.params, "input_map")
    assert together.shape == (2, 300)
    for i, window in enumerate(windows):
        single = features(window.signals, 10_000.0, 100, THESIS.params, "input_map")
        np.testing.assert_array_equal(single[0], together[i])


def test_unknown_input_set_is_named():
    window = synthetic_window(HealthParams.single(), seed=2, duration_s=0.05)
    with pytest.raises(InputError) as error:
        features(window.signals, 10_000.0, 100, THESIS.params, "torque")
    assert error.value.field == "inputs"


def test_reading_the_hinge_along_the_deflection_lowers_the_fit_error_on_foreign_windows():
    """Round trip on the independent implementation: 0.1 s gust windows, 40 of its own noise draws each.
    The gain depends on how much of the error the hinge noise makes: never a loss, 30 % on one."""
    squares = {"logged": [], "read": []}
    for seed in (13017, 13026):
        clean = draw(seed, "gust", duration_s=0.1, noise_level=0.0)
        signals = {name: np.asarray(v) for name, v in clean.document["signals"].items()}
        batch = [noisy(dict(signals), np.random.default_rng(k), 1.0) for k in range(40)]
        stacked = {name: np.stack([b[name] for b in batch]) for name in signals}
        for label, read in (("logged", stacked), ("read", as_read(stacked, 10_000.0))):
            solution = solve_friction(read, 10_000.0, drive=THESIS.params)
            # η_O in FDJ units of range (0.30 against 0.02 N·m)
            error = np.hypot(solution.fdj_nm - clean.truth["FDJ"], (solution.eta_o - clean.truth["eta_O"]) / 15)
            squares[label].append(np.mean(error**2))
    ratios = np.sqrt(np.array(squares["read"]) / np.array(squares["logged"]))
    assert np.all(ratios < 1.0), ratios
    assert np.sqrt(sum(squares["read"]) / sum(squares["logged"])) < 0.85
