"""The ema-estimate/1 document's verdicts: what "weakly determined" covers."""

from ema.estimate.assess.weighing import Assessed
from ema.estimate.report import weakly_determined
from ema.kinds.rotary.physics.static_friction import StaticFriction
from ema.kinds.rotary.report import _estimates
from ema.model.actuator import THESIS

NO_FSJ = StaticFriction(None, None, 0, "no rest in the window")


def test_weak_is_two_stds_past_a_tenth_of_the_range():
    assert not weakly_determined("eta_O", 0.0149, ranges=THESIS.ranges) and weakly_determined(
        "eta_O", 0.0151, ranges=THESIS.ranges
    )  # range 0.30
    assert not weakly_determined("FDJ", 0.00099, ranges=THESIS.ranges) and weakly_determined(
        "FDJ", 0.00101, ranges=THESIS.ranges
    )  # range 0.02 N·m


def test_an_eta_o_at_a_bound_of_the_search_is_weak_and_so_is_the_fdj_read_with_it():
    """A 0.1 s foreign window with its current logged 0.71x read η_O 0.999 ± 0.009 at the bound (truth 0.70)."""
    answer = Assessed({"FDJ": 0.057, "eta_O": 0.999}, {"FDJ": 0.0002, "eta_O": 0.0085}, {}, 1.0, [])
    free = _estimates(answer, NO_FSJ, eta_o_bound=False, actuator=THESIS, loaded=True)
    bound = _estimates(answer, NO_FSJ, eta_o_bound=True, actuator=THESIS, loaded=True)
    assert not any(e.weakly_determined for e in (free.FDJ, free.eta_O, free.eta_A))
    assert all(e.weakly_determined for e in (bound.FDJ, bound.eta_O, bound.eta_A))
    assert bound.eta_O.std == free.eta_O.std  # a bound, said so: its std is the fit's, not widened to mean more
