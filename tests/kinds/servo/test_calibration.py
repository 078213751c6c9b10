"""A servo's calibration: what the document lacks learned with stds and units, an effect named only where the
windows hold one (the closed-form foreign servo, several seeds), and the EMPS log's own misfit traced."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ema.estimate.config import PipelineConfig
from ema.kinds import CalibrationRequest, calibrate, estimate
from ema.model.actuator import actuator_from_dict, read_actuator
from ema.model.checks import InputError
from ema.model.logmap import read_logmap, read_mapped
from ema.model.window import window_from_dict
from tests.foreign import servo as foreign

EMPS = Path(__file__).resolve().parents[3] / "examples" / "emps"
FOREIGN = actuator_from_dict(foreign.DOCUMENT)
TURNING = actuator_from_dict(
    {**foreign.DOCUMENT, "servo": {**foreign.DOCUMENT["servo"], "travel_per_turn_m": foreign.Load().travel_per_turn_m}}
)  # the same servo whose document gives the load's travel per turn of the motor


def _calibrated(windows, document):
    return calibrate(windows, CalibrationRequest(PipelineConfig(), document))


@pytest.mark.parametrize("seed", range(3))
def test_a_clean_servo_names_nothing(seed):
    report = _calibrated([window_from_dict(foreign.draw(seed))], TURNING if seed % 2 else FOREIGN).report
    assert report.selected_effects == []
    assert report.model_error_pct_after == report.model_error_pct_before


@pytest.mark.parametrize("seed", range(3))
def test_a_viscous_friction_that_differs_with_direction_is_named_and_learned(seed):
    load = foreign.Load(viscous_up_ns_per_m=160.0, viscous_down_ns_per_m=240.0)
    calibrated = _calibrated([window_from_dict(foreign.draw(seed, load))], FOREIGN)
    report = calibrated.report
    assert report.selected_effects[:1] == ["viscous_down"]
    learned = {entry.name: entry for entry in report.learned}
    for name, truth in (("viscous_up", 160.0), ("viscous_down", 240.0), ("mass", 90.0), ("FDJ", 20.0)):
        assert abs(learned[name].value - truth) <= max(3 * learned[name].std, 0.01 * truth), name
    assert learned["FDJ"].unit == "N" and learned["viscous_down"].unit == "N·s/m" and "viscous" not in learned
    assert report.model_error_pct_after["drive_force_n"] < 0.2 * report.model_error_pct_before["drive_force_n"]
    servo, simulated = calibrated.completed.servo, {entry.name: entry.value for entry in report.as_simulated}
    assert servo.viscous_down_ns_per_m == pytest.approx(simulated["viscous_down"])
    for name, entry in learned.items():  # the foreign simulator's truth: the simulator's frame is near the fit's
        assert abs(simulated[name] - entry.value) <= max(3 * entry.std, 0.01 * abs(entry.value)), name


@pytest.mark.parametrize("seed", range(2))
def test_a_force_once_per_turn_is_named_where_the_document_gives_its_period(seed):
    """The foreign servo with a force of 1 N once per 2.5 mm of travel (its own integration): named, as the simulator
    takes it within 3 % of the truth, and another run of the machine (another set point, a command of its own
    added) read with the completed document holds it within 2 std. Without the period it is not looked for."""
    load = foreign.Load(turn_n=(0.8, -0.6))
    window = window_from_dict(foreign.draw(seed, load))
    assert "turn_ripple" not in {c.effect for c in _calibrated([window], FOREIGN).report.candidates}
    calibrated = _calibrated([window], TURNING)
    assert calibrated.report.selected_effects == ["turn_ripple"]
    simulated = {entry.name: entry.value for entry in calibrated.report.as_simulated}
    truth = {"turn_ripple_sin_n": load.turn_n[0], "turn_ripple_cos_n": load.turn_n[1]}
    for name, value in truth.items():
        assert simulated[name] == pytest.approx(value, abs=0.03), name
    other = window_from_dict(foreign.draw(seed + 10, load, excited=True))
    read = estimate(other, actuator=calibrated.completed).estimates
    for name, entry in {"fdj_n": read.FDJ, **read.constants}.items():
        value = truth.get(name, getattr(load, name, None))
        if value is not None:
            assert abs(entry.value - value) <= 2 * entry.std, (name, entry.value, value, entry.std)


@pytest.mark.parametrize("seed", range(4))
def test_a_foreign_servos_completed_document_reads_its_nominal_on_the_window_that_taught_it(seed):
    """Windows of the closed-form foreign servo (its own simulator, not ours), with and without a viscous friction
    that differs with direction: calibrated, then estimated with the completed document, every constant reads
    within 2 std of the nominal the document keeps (its constants as our simulator takes them)."""
    load = foreign.Load(viscous_up_ns_per_m=160.0, viscous_down_ns_per_m=240.0) if seed % 2 else foreign.Load()
    window = window_from_dict(foreign.draw(seed, load))
    completed = _calibrated([window], FOREIGN).completed
    read = estimate(window, actuator=completed).estimates
    for name, entry in {"FDJ": read.FDJ, **read.constants}.items():
        assert abs(entry.value - entry.nominal) <= 2 * entry.std, (name, entry.value, entry.nominal, entry.std)


@pytest.fixture(scope="module")
def emps():
    window = window_from_dict(read_mapped(EMPS / "DATA_EMPS.mat", read_logmap(EMPS / "log-map.json")))
    return window, _calibrated([window], read_actuator(EMPS / "actuator.json"))


def test_the_emps_logs_misfit_is_traced_to_a_direction_dependent_viscous_friction(emps):
    _, calibrated = emps
    report = calibrated.report
    assert report.selected_effects[0] == "viscous_down"
    before, after = report.model_error_pct_before, report.model_error_pct_after
    assert after["drive_force_n"] <= 3.2 < before["drive_force_n"]  # the benchmark's symmetric model: 4.08 %
    assert after["drive_force_n_closed_loop"] < before["drive_force_n_closed_loop"]
    learned = {entry.name: entry for entry in report.learned}
    assert learned["mass"].value == pytest.approx(95.1089, rel=0.02) and learned["mass"].unit == "kg"
    assert learned["FDJ"].value == pytest.approx(20.3935, rel=0.03)
    assert learned["viscous_up"].value < learned["viscous_down"].value
    assert not [c for c in report.candidates if c.effect == "stribeck" and c.plausible]  # a negative excess


def test_the_emps_logs_force_once_per_turn_is_named_with_its_size(emps):
    """EMPS's document gives the motor's turn (2.5 mm of travel): the log holds a force of about 1 N repeating with
    it, named after the viscous friction by direction (benchmarks.turn_ripple: the same in every quarter)."""
    report = emps[1].report
    assert report.selected_effects == ["viscous_down", "turn_ripple"]
    learned = {entry.name: entry for entry in report.learned}
    amplitude = float(np.hypot(learned["turn_ripple_sin_n"].value, learned["turn_ripple_cos_n"].value))
    assert 0.8 < amplitude < 1.2 and learned["turn_ripple_sin_n"].unit == "N"
    assert emps[1].completed.servo.effects["turn_ripple"] == pytest.approx(2.5e-3)


def test_every_candidate_is_scored_against_the_noise_only_copies(emps):
    """A candidate's score is the z every kind reports: its held-out drop against what it gains on the noise-only
    copies. A term with a free constant gains on any log: the Stribeck term's first-step drop over 5 % on EMPS is
    what it gains on the copies too, no evidence; the effects named stand far beyond."""
    from ema.calibration.limits import NAME_Z

    report = emps[1].report
    first = {c.effect: c for c in reversed(report.candidates)}  # each effect's first-step candidate
    assert first["stribeck"].held_out_drop >= 0.05 and abs(first["stribeck"].score) < NAME_Z
    named = [max(c.score for c in report.candidates if c.effect == name) for name in report.selected_effects]
    assert named and min(named) >= NAME_Z  # at the step that named it


def test_the_completed_document_reads_the_log_closer(emps):
    window, calibrated = emps
    before = estimate(window, actuator=read_actuator(EMPS / "actuator.json"))
    after = estimate(window, actuator=calibrated.completed)
    assert after.check.equation_error_ratio < before.check.equation_error_ratio
    assert after.check.output_error_pct["drive_force_n"] < before.check.output_error_pct["drive_force_n"]
    assert after.estimates.FDJ.nominal == pytest.approx(calibrated.completed.nominal.fdj_n)
    read = {"FDJ": after.estimates.FDJ, **after.estimates.constants}
    phased = {name: read.pop(name) for name in ("turn_ripple_sin_n", "turn_ripple_cos_n")}  # no nominal: a phase
    for name, entry in read.items():  # the log that taught the document reads its nominal, within its std
        assert abs(entry.value - entry.nominal) <= 2 * entry.std, (name, entry.value, entry.nominal, entry.std)
    size = calibrated.completed.servo.effect_constants["turn_ripple_amplitude_n"]
    sine, cosine = (phased[name] for name in ("turn_ripple_sin_n", "turn_ripple_cos_n"))
    assert abs(np.hypot(sine.value, cosine.value) - size) <= 2 * max(sine.std, cosine.std)
    again = _calibrated([window], calibrated.completed).report
    assert again.model_error_pct_document["drive_force_n"] <= before.check.output_error_pct["drive_force_n"]
    along = {e.name: e.value for e in again.learned if e.name.startswith("position_")}  # the simulator lacks it
    assert along and along == {e.name: e.value for e in again.as_simulated if e.name in along}


def test_unlogged_pulses_do_not_hide_or_fake_an_effect():
    for load, named in ((foreign.Load(), []), (foreign.Load(viscous_down_ns_per_m=240.0), ["viscous_down"])):
        report = _calibrated([window_from_dict(foreign.draw(1, load, pushed=True))], FOREIGN).report
        assert report.selected_effects == named
        assert {e.name: e.value for e in report.learned}["FDJ"] == pytest.approx(load.fdj_n, rel=0.01)


def test_the_budget_counts_every_closed_loop_a_calibration_runs(monkeypatch):
    """The service refuses a calibration by its simulation work (``calibration_cost``): it counts each closed loop
    the calibration runs, no fewer."""
    from ema.kinds import calibration_cost
    from ema.kinds.servo.closed_loop import SUBSTEPS

    runs = []

    def counted(set_point, lanes, *args, **kwargs):
        runs.append(len(set_point) * lanes.shape[0])
        return simulate(set_point, lanes, *args, **kwargs)

    from ema.kinds.servo import log_reading as prepared_servo  # every closed loop of a prepared window runs there

    simulate = prepared_servo.simulate_servo
    monkeypatch.setattr(prepared_servo, "simulate_servo", counted)
    load = foreign.Load(viscous_up_ns_per_m=160.0, viscous_down_ns_per_m=240.0)
    windows = [window_from_dict(foreign.draw(seed, load)) for seed in range(2)]
    _calibrated(windows, FOREIGN)
    assert runs and calibration_cost(windows, PipelineConfig()).simulated_s == pytest.approx(
        sum(runs) * SUBSTEPS * 1e-6
    )


def test_a_constant_the_twins_give_no_finite_read_of_keeps_the_solved_value(monkeypatch):
    """The simulator's constants are the stacked solution's moved by its bias on the twins; where a twin's solution
    reads no finite number (a closed loop that could not follow), the solved value stands rather than a NaN in the
    document."""
    from types import SimpleNamespace

    import ema.kinds.servo.stacked_solve as stacked_solve

    reads = {"fdj_n": float("nan"), "mass_kg": 94.0, "position_friction_p1_n": 0.0}
    monkeypatch.setattr(stacked_solve, "_simulated", lambda p, *rest: p)
    monkeypatch.setattr(stacked_solve, "problem", lambda prepared, model: None)
    monkeypatch.setattr(stacked_solve, "solved", lambda p: SimpleNamespace(values=reads))
    values = {"fdj_n": 20.0, "mass_kg": 95.0, "position_friction_p1_n": 1.0}
    assert stacked_solve.simulator_frame([None], values, {}) == {
        "fdj_n": 20.0,
        "mass_kg": 96.0,
        "position_friction_p1_n": 1.0,
    }


def test_a_log_its_documents_controller_does_not_give_is_refused_naming_the_window():
    """Every step of a servo's calibration simulates the document's controller: a log run under another (here the
    speed read without its filter) would have the controllers' difference traced to the load."""
    document = actuator_from_dict({**foreign.DOCUMENT, "servo": {**foreign.DOCUMENT["servo"], "speed_filter": [1.0]}})
    with pytest.raises(InputError) as error:
        _calibrated([window_from_dict(foreign.draw(0, seconds=3.0))], document)
    assert error.value.field == "window servo-0" and "controller" in error.value.message


def test_the_turns_force_transfers_to_a_log_whose_zero_is_at_another_angle(emps):
    """The held-out run's turn force lies 100° from the estimation run's (the load's zero at another motor angle):
    the document keeps the force's size, each log reads its phase, so the effect helps a log shifted by a part of
    the turn as much as the log that taught it (a fixed phase would make it worse than none)."""
    from ema.kinds.servo.fold_errors import document_check
    from ema.kinds.servo.log_reading import prepare_servo

    window, calibrated = emps
    document = calibrated.completed
    assert set(document.servo.effect_constants) == {"turn_ripple_amplitude_n"}
    bare = document.model_copy(
        update={"servo": document.servo.model_copy(update={"effects": {}, "effect_constants": {}})}
    )
    for shift_m in (0.0, 0.8e-3):  # about a third of the 2.5 mm turn
        s = {**window.signals}
        s["position_m"], s["set_point_m"] = s["position_m"] + shift_m, s["set_point_m"] + shift_m
        shifted = replace(window, signals=s)
        with_force = document_check([prepare_servo(shifted, document)], document)
        without = document_check([prepare_servo(shifted, bare)], bare)
        assert with_force["drive_force_n"] < without["drive_force_n"] - 0.1
