"""Round trips on actuators unlike the thesis's, drawn by tests/foreign with their own constants: in flight, on
the ground without load (a pre-flight sweep) and on a bench under a ramp load; and windows read with the wrong
document."""

import pytest

from ema.estimate.config import PipelineConfig
from ema.kinds.rotary.pipeline import estimate_window
from ema.model.actuator import THESIS, actuator_from_dict
from ema.model.checks import InputError
from ema.model.window import window_from_dict
from tests.foreign.actuators import DRIVES, NOMINAL, document
from tests.foreign.windows import Ground, draw

SMALL = PipelineConfig(n_simulations=32, check_simulations=12)
CONDITIONS = {  # what the window shows: a family, where it was logged
    "flight": ("thesis", None),
    "cruise": ("cruise", None),
    "sweep": ("sweep", Ground()),
    "bench": ("sweep", Ground(load_nm=-150.0, ramp_nmps=600.0)),
}


def _answer(name: str, condition: str, seed: int):
    family, where = CONDITIONS[condition]
    drawn = draw(seed, family, drive=DRIVES[name], nominal=NOMINAL[name], flight=where)
    actuator = actuator_from_dict(document(name))
    return drawn, estimate_window(window_from_dict(drawn.document), SMALL, actuator=actuator)


@pytest.mark.parametrize("name", ["heavier", "smaller"])
@pytest.mark.parametrize("condition", ["flight", "cruise", "bench"])
@pytest.mark.parametrize("seed", [11, 12])
def test_an_actuator_unlike_the_thesiss_is_read_with_its_own_document(name, condition, seed):
    drawn, result = _answer(name, condition, seed)
    fdj, eta_o = result.estimates.FDJ, result.estimates.eta_O
    assert abs(fdj.value / drawn.truth["FDJ"] - 1.0) < 0.03 and abs(fdj.value - drawn.truth["FDJ"]) < 3 * fdj.std
    assert eta_o is not None and abs(eta_o.value - drawn.truth["eta_O"]) < max(0.015, 3 * eta_o.std)
    assert result.estimates.eta_A.value == pytest.approx(drawn.truth["eta_A"], abs=0.03)  # Eq. 3.4 at its gear
    assert result.actuator.name == f"foreign {name} actuator" and not result.actuator.default
    codes = {note.code for note in result.notes}
    assert ("on_ground" if condition == "bench" else "aircraft_check_skipped") in codes  # no airframe given


@pytest.mark.parametrize("name", ["heavier", "smaller"])
def test_a_sweep_without_load_reads_fdj_and_says_why_eta_o_is_none(name):
    drawn, result = _answer(name, "sweep", 13)
    assert result.estimates.eta_O is None and result.estimates.eta_A is None
    assert {"on_ground", "no_load"} <= {note.code for note in result.notes}
    assert result.window.sliding_fraction > 0.3
    assert abs(result.estimates.FDJ.value / drawn.truth["FDJ"] - 1.0) < 0.03


@pytest.mark.parametrize(("drawn_as", "read_as"), [("heavier", "thesis"), ("smaller", "heavier")])
def test_another_actuators_document_is_refused_naming_its_gear_ratio(drawn_as, read_as):
    drawn = draw(14, "thesis", drive=DRIVES[drawn_as], nominal=NOMINAL[drawn_as])
    actuator = THESIS if read_as == "thesis" else actuator_from_dict(document(read_as))
    with pytest.raises(InputError) as refused:
        estimate_window(window_from_dict(drawn.document), SMALL, actuator=actuator)
    assert refused.value.field == "actuator.drive.gear_ratio"
    shown = float(refused.value.message.split("gear ratio of ")[1].split()[0])  # what the window shows
    assert shown == pytest.approx(DRIVES[drawn_as].gear_ratio, rel=0.01)


def test_a_document_whose_k_t_is_another_drives_says_so_or_is_not_reproduced():
    drawn = draw(15, "thesis", drive=DRIVES["heavier"], nominal=NOMINAL["heavier"])
    wrong = document("heavier")
    wrong["drive"]["torque_constant_nm_per_a"] = 0.0752  # the thesis's motor, not this one's
    result = estimate_window(window_from_dict(drawn.document), SMALL, actuator=actuator_from_dict(wrong))
    current = [note for note in result.notes if note.code == "current_units"]
    assert not result.check.reproduced and current and "k_T of 0.12" in current[0].text
