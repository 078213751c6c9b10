"""Where the model misses part of a servo's log, its stds hold what each effect the log holds evidence for reads:
on the independent closed-form servo, a viscous friction that differs with the direction read with a symmetric
model; the log that holds nothing more keeps its stds."""

import numpy as np
import pytest

from ema.estimate.assess.weighing import Assessed
from ema.kinds import estimate
from ema.kinds.servo.effect_readings import HELD_READINGS, Reading, widened
from ema.kinds.servo.load_effects import LOAD_EFFECTS
from ema.kinds.servo.stacked_solve import Solved
from ema.model.actuator import actuator_from_dict
from ema.model.window import window_from_dict
from tests.foreign import servo as foreign

FOREIGN = actuator_from_dict(foreign.DOCUMENT)
MISSED = foreign.Load(viscous_up_ns_per_m=160.0, viscous_down_ns_per_m=240.0)


def _solved(values: dict[str, float]) -> Solved:
    return Solved(values, dict.fromkeys(values, 0.1), 1.0, np.ones(5), np.zeros(3))


def test_each_std_holds_the_farthest_reading_in_quadrature_with_its_noise():
    base = _solved({"fdj_n": 20.0, "mass_kg": 90.0, "viscous_ns_per_m": 200.0})
    effect = LOAD_EFFECTS[0]
    readings = [
        Reading(effect, 0.0, _solved({"fdj_n": 21.0, "mass_kg": 90.2, "viscous_up_ns_per_m": 150.0}), 0.5, True, True),
        Reading(effect, 0.0, _solved({"fdj_n": 19.6, "mass_kg": 90.0, "viscous_ns_per_m": 203.0}), 0.1, True, True),
    ]
    stds = dict.fromkeys(base.values, 0.3)
    answer = Assessed(values=dict(base.values), stds=stds, methods={}, inflation=1.0, notes=[])
    out, note = widened(answer, base, readings)
    assert out.stds["fdj_n"] == pytest.approx(np.hypot(0.3, 1.0 / HELD_READINGS))
    assert out.stds["mass_kg"] == pytest.approx(np.hypot(0.3, 0.2 / HELD_READINGS))
    assert out.stds["viscous_ns_per_m"] == pytest.approx(np.hypot(0.3, 3.0 / HELD_READINGS))  # the one that has it
    assert out.values == answer.values and note is not None and note.code == "model_form"
    assert widened(answer, base, []) == (answer, None)


@pytest.mark.parametrize("excited", [False, True])
def test_a_missed_effect_costs_the_answer_its_precision_not_its_truth(excited):
    """Seed 3 read FDJ 8.6 stds off the truth with a command of its own added, its std the noise's alone."""
    result = estimate(window_from_dict(foreign.draw(3 + 10 * excited, MISSED, excited=excited)), actuator=FOREIGN)
    fdj = result.estimates.FDJ
    codes = {note.code for note in result.notes}
    assert {"model_misfit", "model_form"} <= codes
    assert abs(fdj.value - MISSED.fdj_n) <= 2.0 * fdj.std


def test_a_log_the_model_explains_keeps_its_stds():
    result = estimate(window_from_dict(foreign.draw(3, foreign.Load(), excited=True)), actuator=FOREIGN)
    assert "model_form" not in {note.code for note in result.notes}
    assert result.estimates.FDJ.std < 0.05
