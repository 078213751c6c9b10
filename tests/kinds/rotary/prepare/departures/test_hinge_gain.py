"""The hinge moment's gain, read per window on foreign windows (tests/foreign logs the moment times a
gain, noise and all, as a strain gauge calibrated off would)."""

import numpy as np
import pytest

from ema.kinds.rotary.prepare.conditioning import conditioning_done, conditioning_notes, prepare
from ema.kinds.rotary.prepare.departures.hinge_gain import eta_o_from_product, read_hinge_gain
from ema.model.actuator import THESIS
from ema.model.params import eta_a_from_eta_o
from ema.model.window import window_from_dict
from tests.foreign.windows import Effects, draw, with_hinge_gain, worn

FAMILIES = ("thesis", "cruise", "gust", "doublet", "steps")
SEEDS = range(4500, 4510)


def test_eta_o_from_the_product_inverts_eq_3_4():
    eta_o = np.linspace(0.3, 0.99, 50)
    np.testing.assert_allclose(eta_o_from_product(eta_o * eta_a_from_eta_o(eta_o, 500.0), 500.0), eta_o, rtol=1e-10)


@pytest.mark.parametrize("gain", [0.74, 0.9, 1.1])
def test_a_hinge_moment_logged_off_gain_is_read_within_its_std(gain):
    drawn = [
        read_hinge_gain(window_from_dict(with_hinge_gain(draw(s, FAMILIES[s % 5]), gain).document), drive=THESIS.params)
        for s in SEEDS
    ]
    read = [r for r in drawn if r.gain != 1.0]  # one steps window at 1.1x does not stand out beside an offset
    assert len(read) >= 9 and all(r.gain == pytest.approx(gain, rel=0.015) for r in read), [r.gain for r in drawn]
    assert sum(abs(r.gain - gain) <= 2 * max(r.gain_std, 1e-3) for r in read) >= len(read) - 1


def test_a_true_hinge_moment_is_left_as_logged():
    windows = [draw(s, FAMILIES[s % 5]) for s in SEEDS] + [worn(s, family=FAMILIES[s % 5]) for s in SEEDS]
    assert [read_hinge_gain(window_from_dict(w.document), drive=THESIS.params).gain for w in windows] == [1.0] * len(
        windows
    )


def test_the_pipeline_reads_the_gain_and_answers_as_with_the_true_moment():
    drawn = draw(4511, "doublet")
    off = prepare(window_from_dict(with_hinge_gain(drawn, 0.8).document), actuator=THESIS)
    assert conditioning_done(off)["hinge_gain"] == pytest.approx(0.8, rel=0.01)
    said = {"hinge_gain", "hinge_vs_aircraft"}  # its loads, or the aircraft
    assert said & {note.code for note in conditioning_notes(off)}
    true = prepare(window_from_dict(drawn.document), actuator=THESIS)
    assert off.departures.answer["eta_O"] == pytest.approx(true.departures.answer["eta_O"], abs=0.005)
    assert off.departures.answer["FDJ"] == pytest.approx(true.departures.answer["FDJ"], rel=0.01)


def test_the_gain_leads_the_drive_constants_only_where_it_explains_the_window_better():
    def lead(drawn) -> bool:
        return read_hinge_gain(window_from_dict(drawn.document), leading=True, drive=THESIS.params).gain != 1.0

    assert all(lead(with_hinge_gain(draw(s, FAMILIES[s % 5]), 0.8)) for s in SEEDS)
    drive_off = [Effects(torque_constant_gain=0.95), Effects(current_sensor_gain=1.03), Effects(inertia_factor=1.08)]
    assert not any(lead(draw(s, FAMILIES[s % 5], effects=drive_off[s % 3])) for s in SEEDS)
