"""Which estimator the answer believes: bias shrinkage, the network's margin, the std's floor."""

import numpy as np
import pytest

from ema.estimate.assess.weighing import NETWORK_MARGIN, Candidates, assess, bias_corrected

K = 24  # the pipeline's held-out simulations


def candidates(rng: np.random.Generator, physics_error: float, network_error: float, bias: float = 0.0) -> Candidates:
    """K held-out simulations with physics errors N(bias, physics_error²) and network errors that share
    60 % of the physics fit's noise (both read the same residual torque) to a total std ``network_error``,
    and a window whose two answers agree as the simulations' do."""
    truth = {name: rng.uniform(0.4, 0.6, K) for name in ("FDJ", "eta_O")}
    shared = {name: rng.standard_normal(K) for name in truth}
    physics = {name: t + bias + physics_error * shared[name] for name, t in truth.items()}
    own = max(network_error**2 - (0.6 * physics_error) ** 2, 0.0) ** 0.5
    network = {name: t + 0.6 * physics_error * shared[name] + own * rng.standard_normal(K) for name, t in truth.items()}
    return Candidates(
        physics={"FDJ": 0.5 + bias, "eta_O": 0.5 + bias},
        physics_std={"FDJ": 1e-6, "eta_O": 1e-6},
        network={"FDJ": 0.5, "eta_O": 0.5},
        network_unit=np.array([0.5, 0.5]),
        check_truth=truth,
        check_physics=physics,
        check_network=network,
    )


def test_a_bias_the_simulations_resolve_is_subtracted_whole():
    rng = np.random.default_rng(0)
    errors = 0.05 + 0.01 * rng.standard_normal(K)  # the mean is 25 standard errors from zero
    bias, corrected = bias_corrected(errors, np.zeros(K))
    assert bias == pytest.approx(errors.mean(), rel=0.01)
    assert abs(np.mean(corrected)) < 0.01


def test_a_bias_within_the_noise_of_k_draws_is_mostly_dropped():
    # Pure noise: the plain mean is a ~1-standard-error draw. Within one it is dropped (~68 % of
    # draws), beyond it shrunk by s²/b: about 0.6 of its RMS is left (√0.35, by the normal integrals).
    applied, plain = [], []
    for seed in range(400):
        errors = np.random.default_rng(seed).standard_normal(K)
        applied.append(bias_corrected(errors, np.zeros(K))[0])
        plain.append(errors.mean())
    assert np.mean(np.array(applied) == 0.0) > 0.6
    assert np.sqrt(np.mean(np.square(applied))) < 0.7 * np.sqrt(np.mean(np.square(plain)))


def test_the_shrinkage_is_positive_part_james_stein():
    errors = np.array([0.3, -0.1, 0.5, 0.2, 0.1, 0.4])
    b, s2 = errors.mean(), errors.var(ddof=1) / len(errors)
    assert bias_corrected(errors, np.zeros(6))[0] == pytest.approx(b * max(0.0, 1 - s2 / b**2))


@pytest.mark.parametrize("seed", range(5))
def test_a_network_that_barely_helps_on_the_simulations_stays_out(seed):
    result = assess(candidates(np.random.default_rng(seed), physics_error=0.01, network_error=0.011), 1.0, 1.1)
    for name in ("FDJ", "eta_O"):
        assert result.methods[name].weight_network == 0.0
        assert result.values[name] == pytest.approx(0.5 - result.methods[name].physics_bias)
        assert result.methods[name].network_note.code == "network_not_better"
    assert not any(note.code == "physics_only" for note in result.notes)  # routine: not the answer's news


@pytest.mark.parametrize("seed", range(5))
def test_a_network_much_better_on_the_simulations_joins_the_answer(seed):
    result = assess(candidates(np.random.default_rng(seed), physics_error=0.01, network_error=0.003), 1.0, 1.1)
    for name in ("FDJ", "eta_O"):
        assert result.methods[name].weight_network > 0.5
        assert result.methods[name].rms_error_blend < NETWORK_MARGIN * result.methods[name].rms_error_physics


def test_the_std_is_never_below_the_windows_jackknife_and_widens_with_the_equation_error():
    c = candidates(np.random.default_rng(1), physics_error=1e-4, network_error=1e-4)
    c = Candidates(**{**c.__dict__, "physics_std": {"FDJ": 0.02, "eta_O": 0.03}})
    assert assess(c, 1.0, 1.1).stds == pytest.approx({"FDJ": 0.02, "eta_O": 0.03})
    assert assess(c, 2.5, 1.1).stds == pytest.approx({"FDJ": 0.05, "eta_O": 0.075})


def test_the_student_quantile_is_scipys_within_one_percent():
    from scipy import stats

    from ema.estimate.assess.weighing import student_99

    for dof in (4, 7, 15, 23, 60, 200):
        assert student_99(dof) == pytest.approx(stats.t.ppf(0.99, dof), rel=1e-2)


def test_a_clean_window_passes_the_misfit_limit_at_the_stated_rate():
    """K simulations' RMS errors and the window's, all one log-normal null (spreads as the pipeline sees them,
    0.03-0.05): the window passes ``misfit_limit`` 1 % of the time."""
    from ema.estimate.assess.weighing import MISFIT_FALSE_ALARM, misfit_limit

    rng = np.random.default_rng(7)
    trials, passed = 20_000, 0
    for _ in range(trials):
        spread, k = rng.uniform(0.03, 0.05), int(rng.integers(16, 25))
        draws = np.exp(spread * rng.standard_normal(k + 1))
        passed += draws[-1] / np.median(draws[:-1]) > misfit_limit(draws[:-1])
    rate = passed / trials
    assert abs(rate - MISFIT_FALSE_ALARM) < 3 * np.sqrt(MISFIT_FALSE_ALARM / trials) + 0.002, rate


def test_the_misfit_note_is_said_past_the_limit_only():
    c = candidates(np.random.default_rng(2), physics_error=1e-3, network_error=1e-3)
    assert "model_misfit" not in [n.code for n in assess(c, 1.08, 1.1).notes]
    assert "model_misfit" in [n.code for n in assess(c, 1.12, 1.1).notes]
