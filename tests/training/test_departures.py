"""The departures from the spec's model read in turn, on a foreign window where the order matters."""

from sim.window import window_from_dict
from tests.foreign.windows import Effects, worn
from training.baseline import fit_window
from training.conditioning import prepare, widened
from training.preprocess import as_read


def test_where_a_scale_and_an_inertia_cannot_be_told_apart_the_stds_reach_both_ends():
    """A worn gust window, J_M 0.5 % light: read as γ, its viscous coefficient then read 0.63x and FDJ 66 %
    of range off; read as ΔJ, 1.0x and right. The window cannot tell which: the std must reach both."""
    drawn = worn(32057, family="gust", effects=Effects(inertia_factor=0.99465))
    prepared = prepare(window_from_dict(drawn.document))
    assert prepared.drive.alternative is not None
    w = prepared.window
    fitted = fit_window(as_read(w.signals, w.sample_rate_hz), w.sample_rate_hz, prepared.actuator)
    std = widened({"FDJ": float(fitted.fdj_std_nm[0])}, prepared)["FDJ"]
    error = abs(float(fitted.fdj_nm[0]) - drawn.truth["FDJ"])
    assert error > 0.3 * 0.02  # the γ end is far off ...
    assert error < 2 * std  # ... and the std says so,
    assert prepared.drive.spread["FDJ"] > 0.5 * error  # by the gap between the two ends
