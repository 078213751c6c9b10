"""Round trips of the calibration loop on windows drawn by tests/foreign, with effects in its own forms."""

import numpy as np
import pytest

from ema.calibration.documents import CalibrationReport
from ema.calibration.truth import with_truth_errors
from ema.estimate.config import PipelineConfig
from ema.kinds.rotary.calibration import Calibrator
from ema.model.actuator import THESIS
from ema.model.checks import InputError
from ema.model.window import window_from_dict
from tests.foreign.effects import CASES
from tests.foreign.physics import Flight
from tests.foreign.windows import Effects, draw, filter_widths

SMALL = PipelineConfig(n_simulations=32, check_simulations=16, n_timesteps=100, hidden_units=20)
STOPS_FLIGHT = Flight(airspeed_mps=100.0, altitude_m=5000.0)  # a low q̄: the motor holds the stop against it


def reported(drawn, calibrator: Calibrator | None = None) -> CalibrationReport:
    """The report as ``ema calibrate`` gives it: the calibrator's, with its errors against the drawn truth."""
    calibrator = calibrator or Calibrator(SMALL, copies=16, actuator=THESIS)
    return with_truth_errors(calibrator.fit([window_from_dict(drawn.document)], drawn.truth).report_, drawn.truth)


def calibrate(case: str, seed: int, scale: float = 1.0) -> tuple[CalibrationReport, dict]:
    effects = CASES[case](np.random.default_rng(seed), scale)
    drawn = draw(seed, "thesis", effects=effects)
    report = reported(drawn)
    return report, drawn.truth


def combined_error(report: CalibrationReport, when: str) -> float:
    """|FDJ| + |η_O| relative error, as the issue counts it."""
    errors = getattr(report, f"error_pct_{when}")
    return (errors["FDJ"] + errors["eta_O"]) / 100


@pytest.mark.parametrize("seed", [901, pytest.param(902, marks=pytest.mark.slow)])
def test_clean_windows_select_nothing(seed):
    report, _ = calibrate("clean", seed)
    assert report.selected_effect is None and report.unexplained is None
    assert report.estimates_after == report.estimates_before
    assert report.noise_floor.equation_error_ratio < 1.3


def test_a_drive_whose_loop_departs_from_the_spec_is_no_effect():
    # Bus 8 % high, G_P 1.5 % low, 30 µs of lag and a loop dithering on a noisy speed reading: the
    # torque balance the calibration reads is untouched, so nothing may be named or described.
    loop = Effects(
        supply_voltage_factor=1.08,
        position_gain_factor=0.985,
        loop_delay_s=3e-5,
        loop_noise_radps=0.4,
        loop_noise_seed=5,
    )
    drawn = draw(903, "doublet", effects=loop)
    report = reported(drawn)
    assert report.selected_effect is None and report.unexplained is None
    assert report.estimates_after == report.estimates_before


@pytest.mark.parametrize(("seed", "family"), [(907, "cruise"), pytest.param(905, "doublet", marks=pytest.mark.slow)])
def test_sensors_behind_filters_are_no_effect(seed, family):
    # Correlated sensor noise (moving averages of 2–40 samples) is noise: drawn white into the noise
    # floor's copies, it was described as an unexplained effect on 5 of 6 such windows.
    drawn = draw(seed, family, filter_samples=filter_widths(seed))
    report = reported(drawn)
    assert report.selected_effect is None and report.unexplained is None


@pytest.mark.parametrize(
    ("case", "seed"),
    [
        ("viscous", 911),
        ("hinge_moment_bias", 914),
        ("backlash", 916),
        pytest.param("torque_constant", 912, marks=pytest.mark.slow),
        pytest.param("cogging", 917, marks=pytest.mark.slow),
    ],
)
def test_the_undeclared_effect_is_named_and_the_estimates_recover(case, seed):
    report, _ = calibrate(case, seed)
    assert report.selected_effect == case, report.selection_steps[0].reason
    before, after = combined_error(report, "before"), combined_error(report, "after")
    assert after <= max(0.5 * before, 0.01)
    assert report.held_out.adopted or case == "backlash"  # the dead band does not move FDJ or η_O


@pytest.mark.parametrize(("scale", "seed"), [(1.0, 5701), pytest.param(5.0, 5700, marks=pytest.mark.slow)])
def test_the_dead_band_width_is_read_where_the_motor_drives_the_elevator(scale, seed):
    report, _ = calibrate("backlash", seed, scale)
    drawn_extra_rad = 5e-3 * (CASES["backlash"](np.random.default_rng(seed), scale).backlash_factor - 1.0)
    read = next(c for c in report.candidates if c.effect == "backlash").parameters["extra_rad"]
    assert report.selected_effect == "backlash"
    assert read == pytest.approx(drawn_extra_rad, rel=0.1)


@pytest.mark.slow
@pytest.mark.parametrize(("case", "scale", "seed"), [("torque_constant", 5.0, 5201), ("hinge_moment_bias", 20.0, 5500)])
def test_a_model_that_cannot_follow_the_window_is_no_worn_dead_band(case, scale, seed):
    # The copies replicate the base model, which moves the motor unlike the window: their spread
    # understates the reading's, and the dead band must stand out of the widened one.
    report, _ = calibrate(case, seed, scale)
    assert "backlash" not in report.selected_effects


def test_a_current_scale_names_one_twin_and_reports_the_others():
    report, _ = calibrate("current_sensor_gain", 913)
    assert report.selected_effect in ("current_sensor_gain", "torque_constant")
    step = report.selection_steps[0]
    errors = step.tie_break_output_error
    assert errors is not None and set(errors) - {"none"} == {"current_sensor_gain", "torque_constant", "inertia"}
    # where the reading moves the estimates, the model without it is simulated too, and follows worse
    assert errors.get("none", float("inf")) > errors[report.selected_effect]
    assert combined_error(report, "after") <= 0.5 * combined_error(report, "before")


@pytest.mark.parametrize("seed", [6101, pytest.param(6103, marks=pytest.mark.slow)])
def test_an_inertia_off_the_specs_is_told_from_a_gain_of_the_motor_torque_by_simulation(seed):
    """Its trace in the residual torque is nearly a gain's (k_T·I is mostly J_M·dω/dt and the load): on the
    study's windows, before the simulation had it as a twin, 3 of 5 were named current_sensor_gain."""
    report, _ = calibrate("inertia", seed)
    assert report.selected_effect == "inertia"
    assert combined_error(report, "after") <= max(0.5 * combined_error(report, "before"), 0.01)


@pytest.mark.slow
def test_a_spall_is_found_where_it_is():
    report, _ = calibrate("position_friction", 925)
    assert report.selected_effect == "position_friction"
    assert combined_error(report, "after") <= max(0.5 * combined_error(report, "before"), 0.01)


def test_friction_drifting_in_time_is_described_never_named_and_adopted():
    report, truth = calibrate("drift", 919)
    assert report.selected_effect is None
    assert report.unexplained is not None and report.unexplained.variables[0] == "time_s"
    assert report.unexplained.simulator_term is not None and report.unexplained.simulator_term["variable"] == "time"
    added = report.unexplained.estimates_if_added
    assert added is not None, report.unexplained.estimates_withheld
    assert abs(added["FDJ"] / truth["FDJ"] - 1) < 0.5 * report.error_pct_before["FDJ"] / 100
    # adopted as a named effect would be: in the estimates after, and in what the simulator adds
    assert report.unexplained.adopted and report.held_out.adopted
    assert report.estimates_after == pytest.approx(added)
    assert report.effects["table"]["variable"] == "time"


@pytest.mark.parametrize(
    "seed", [3801, 3802, pytest.param(3803, marks=pytest.mark.slow), pytest.param(3805, marks=pytest.mark.slow)]
)
def test_a_current_sensor_off_zero_is_named_as_such_and_the_estimates_recover(seed):
    """A current offset and a hinge-moment bias both leave a constant in T_R; with no family of its own the
    offset was named a hinge-moment bias, and one such window's estimates got worse (0.29 -> 0.72)."""
    report, _ = calibrate("current_sensor_offset", seed)
    assert report.selected_effect == "current_sensor_offset", report.selection_steps[0].reason
    assert combined_error(report, "after") <= max(0.5 * combined_error(report, "before"), 0.01)


@pytest.mark.parametrize("seed", [3803, pytest.param(3804, marks=pytest.mark.slow)])
def test_a_hinge_moment_bias_is_not_taken_for_a_current_offset_on_a_narrow_simulated_call(seed):
    """Their simulations follow the window about equally (within 1 %): the held-out equations' choice stands."""
    report, _ = calibrate("hinge_moment_bias", seed)
    assert report.selected_effect == "hinge_moment_bias"
    assert combined_error(report, "after") <= max(0.5 * combined_error(report, "before"), 0.01)


@pytest.mark.slow
def test_a_term_the_load_mimics_is_offered_without_estimates():
    # After the spall is named, what remains is a ramp over deflection; the hinge moment follows
    # deflection, so FDJ and η_O trade with the ramp (with it: 31 % and 15 % off). Offer the shape,
    # never those estimates.
    report, _ = calibrate("position_friction", 5500)
    assert report.selected_effect == "position_friction"
    assert report.unexplained is not None and report.unexplained.variables == ["position_rad"]
    assert report.unexplained.estimates_if_added is None
    assert "not identified" in (report.unexplained.estimates_withheld or "")


def test_settings_and_windows_are_checked():
    with pytest.raises(InputError, match="windows"):
        Calibrator(actuator=THESIS).fit([])
    with pytest.raises(InputError, match="copies"):
        Calibrator(copies=2, actuator=THESIS).fit([window_from_dict(draw(1, "thesis").document)])


@pytest.mark.slow
def test_a_drift_while_the_elevator_turns_once_is_no_hinge_bias():
    # The window turns once (t = 0.13 s): sgn(ω), the trace a hinge-moment bias leaves, is a step in
    # time, and a linear drift fits it as well. The report may say either variable, never the name.
    report, _ = calibrate("drift", 5902)
    assert report.selected_effect is None, report.selection_steps[0].reason
    assert report.unexplained is not None and "time_s" in report.unexplained.variables


@pytest.mark.slow
def test_a_small_viscous_friction_is_not_won_by_a_slow_stribeck_decay():
    # exp(−ω/320) is nearly a line over the visited speeds: the grid of decay scales must not win
    # the one-column viscous term by a hair when it explains nothing beyond it.
    report, _ = calibrate("viscous", 5103, scale=0.2)
    assert report.selected_effect == "viscous", report.selection_steps[0].reason
    assert report.selection_steps[0].indistinguishable_from == ["stribeck"]  # and the report says it could be
    assert combined_error(report, "after") <= max(0.5 * combined_error(report, "before"), 0.01)


@pytest.mark.slow
def test_a_stribeck_decay_of_another_form_leaves_fdj_in_place():
    # tests/foreign's Stribeck term decays as 1 − tanh(|ω|/ω_s), ten times FDJ at rest: an exponential
    # of the wrong tail leaves friction at speed that the refit puts into FDJ (0.07 → 0.23 with scales
    # an octave apart and δ = 1 only).
    report, _ = calibrate("stribeck", 5803, scale=20.0)
    assert report.selected_effect == "stribeck", report.selection_steps[0].reason
    assert combined_error(report, "after") <= max(0.5 * combined_error(report, "before"), 0.01)


@pytest.mark.parametrize("case", ["current_sensor_offset", "hinge_moment_bias"])
def test_a_sensor_offset_in_a_window_that_reverses_as_a_drift_would_is_told_by_the_load_split(case):
    """Seed 3806 mostly moves one way and then the other: beside free load columns a curve over time explained
    95-97 % of what the offset does, and the offset was only described (named, a drift window alike had been
    called a current offset: ``test_a_drift_while_the_elevator_turns_once_is_no_hinge_bias``). With η_A tied to
    η_O as the estimators tie it, what an offset does to the aiding and opposing load's share is its own, and no
    curve over time draws it: named right, the twin told apart by simulation, the error cut tenfold or more."""
    report, _ = calibrate(case, 3806)
    assert report.selected_effect == case, report.selection_steps[0].reason
    assert combined_error(report, "after") <= 0.1 * combined_error(report, "before")


def test_a_second_effect_is_judged_even_where_the_base_models_stds_are_huge():
    """A current sensor 1.73 A off (5x; beyond the ±1.5 A search): the base model's FDJ std is 3 N·m, and no
    reading counted as a move, so nothing was simulated against the model before it. A viscous term entered
    second and took FDJ from 0.047 to 0.008 (truth 0.05; the error 0.47 -> 0.87). A move is now judged on stds no
    wider than a weakly determined answer's: the viscous term is simulated, follows the window worse, and is
    left out."""
    report, _ = calibrate("current_sensor_offset", 5504, 5.0)
    assert report.selected_effects == ["current_sensor_offset"]
    assert combined_error(report, "after") <= 0.5 * combined_error(report, "before")


@pytest.mark.slow
def test_a_small_stribeck_decay_read_as_a_viscous_term_below_the_documents_is_described_not_named():
    # 8 mN·m decaying over 120-300 rad/s: over the speeds visited a line of negative slope fits it as
    # well, and named viscous it put the decay's level into FDJ (0.003 -> 0.064).
    report, _ = calibrate("stribeck", 5901, scale=0.2)
    assert report.selected_effect is None, report.selection_steps[0].reason
    assert report.unexplained is not None and "viscous or stribeck" in report.unexplained.description
    assert not report.unexplained.adopted and report.estimates_after == report.estimates_before


@pytest.mark.slow
def test_a_large_hinge_moment_bias_is_simulated_against_the_load_the_drive_feels():
    # -104 N·m: simulated, the bias hypothesis used to push the drive against the logged (biased) moment,
    # so a current offset followed the window better and was named (0.39 -> 0.58).
    report, _ = calibrate("hinge_moment_bias", 5402, scale=5.0)
    assert report.selected_effect == "hinge_moment_bias", report.selection_steps[0].reason
    assert combined_error(report, "after") <= max(0.5 * combined_error(report, "before"), 0.01)


@pytest.mark.slow
def test_a_tanh_stribeck_decay_is_followed_by_an_exponent_between_the_classic_ones():
    # 1 − tanh(|ω|/230) lies between exp(−x) and exp(−x^1.5): with only ½, 1 and 2 the refit's tail
    # missed and left ~1 % of FDJ (0.018 -> 0.016, not halved).
    report, _ = calibrate("stribeck", 5901)
    assert report.selected_effect == "stribeck", report.selection_steps[0].reason
    assert combined_error(report, "after") <= max(0.5 * combined_error(report, "before"), 0.01)


def _into_the_stops(seed: int, effects: Effects) -> tuple[CalibrationReport, dict]:
    drawn = draw(seed, "stops", effects=effects, duration_s=1.5, flight=STOPS_FLIGHT)
    report = reported(drawn)
    return report, drawn.truth


@pytest.mark.slow
def test_a_light_rotor_into_the_stops_is_not_read_as_a_stribeck_decay():
    """Seed 3 of ``benchmarks.calibration_stops``: a Stribeck decay explained held-out samples best and its
    simulation beat the base model's, but put FDJ at 2.2x the truth (adopted, 0.069 -> 1.15). Whatever is read
    now, no decay is adopted and the estimates are no worse."""
    drawn = draw(3, "stops", effects=Effects(inertia_factor=0.8), duration_s=1.5, flight=STOPS_FLIGHT)
    report = reported(drawn, Calibrator(seed=3, actuator=THESIS))
    assert combined_error(report, "after") <= combined_error(report, "before") + 1e-4
    assert "stribeck" not in report.selected_effects


MECHANICAL = {"backlash", "position_friction", "stribeck", "viscous", "cogging"}


@pytest.mark.parametrize(
    "effects",
    [Effects(current_sensor_gain=0.94), pytest.param(Effects(inertia_factor=0.8), marks=pytest.mark.slow)],
)
def test_a_window_into_the_stops_is_never_made_worse_nor_a_sensor_fault_made_mechanical(effects):
    """Into the end stops, a current gain and an inertia leave look-alike traces; whatever the loop names, the
    estimates after are no worse than before, and a sensor's gain is not named backlash or friction
    (``benchmarks.calibration_stops`` for the table over seeds)."""
    report, _ = _into_the_stops(0, effects)
    assert combined_error(report, "after") <= combined_error(report, "before") + 1e-4
    if effects.current_sensor_gain != 1.0:
        assert not set(report.selected_effects) & MECHANICAL
    if report.ambiguity is not None:
        assert report.estimates_after == report.estimates_before
        assert all(report.stds_after[t] >= report.stds_before[t] for t in ("FDJ", "eta_O"))


@pytest.mark.slow
def test_a_light_rotor_into_the_stops_is_not_named_a_mechanical_effect():
    """Named a wider dead band in 4/4 seeds until the copies' spread was widened by the base model's mismatch and
    a light rotor was no longer read as a current 0.9 ms early (``ema.kinds.rotary.prepare.alignment``)."""
    report, _ = _into_the_stops(0, Effects(inertia_factor=0.8))
    assert not set(report.selected_effects) & MECHANICAL
