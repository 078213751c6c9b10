"""The real rig (Ruiz-Carcel and Starr 2018; Cranfield CORD 5097649): its logs read as recorded, its drive
learned from healthy runs at two loads, and its states told apart, on runs the calibration did not see."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ema.calibration.limits import NAME_Z
from ema.kinds import estimate
from ema.kinds.linear.calibration_report import calibrate_linear
from ema.kinds.linear.drive_calibration import read_run
from ema.model.actuator import read_actuator
from ema.model.checks import InputError
from ema.model.logmap import read_logmap, read_mapped
from ema.model.window import window_from_dict

RIG = Path(__file__).resolve().parents[3] / "examples" / "ballscrew-rig"
MAP = read_logmap(RIG / "log-map.json")
DOCUMENT = read_actuator(RIG / "actuator.json")


def runs(state: str, load: int, numbers: range) -> list:
    """The set's runs in the data set's order (``numbers`` into them: its run numbers start where the set's do)."""
    paths = sorted((RIG / "runs").glob(f"{state}_load{load}_run*.csv"))
    return [window_from_dict(read_mapped(paths[n], MAP)) for n in numbers]


@pytest.fixture(scope="module")
def learned():
    """The drive learned on half the healthy runs at each load; the other half is for the tests."""
    report, completed, _ = calibrate_linear(runs("normal", 20, range(5)) + runs("normal", 40, range(5)), DOCUMENT)
    return report, completed


def test_the_rigs_columns_become_a_linear_window():
    window = runs("normal", 20, range(1))[0]
    assert window.kind == "linear" and window.sample_rate_hz == pytest.approx(25.0)
    raw = np.genfromtxt(RIG / "runs" / "normal_load20_run001.csv", delimiter=",", names=True, dtype=None, encoding=None)
    assert np.allclose(window.signals["position_mm"], raw["set_point"] - raw["position_error"])
    assert window.signals["load_n"][0] == pytest.approx(20 * 9.80665)


def test_a_file_that_does_not_match_the_map_is_refused_naming_the_column(tmp_path):
    text = (RIG / "runs" / "normal_load20_run001.csv").read_text().replace("position_error", "err")
    (tmp_path / "run.csv").write_text(text)
    with pytest.raises(InputError, match=r"'position_error'.*error\.column"):
        read_mapped(tmp_path / "run.csv", MAP)


def test_healthy_runs_at_two_loads_teach_the_drive(learned):
    report, completed = learned
    drive = report.drive
    assert drive is not None and drive.fdj_nm is not None and drive.eta_o is not None
    assert 0.5 < drive.current_per_nm_a < 1.0 and 0.25 < drive.current_at_zero_torque_a < 0.45
    assert report.residual_rms_after["current_a"] < 0.1 * report.residual_rms_before["current_a"]
    assert any("one number" in line for line in drive.not_separable)  # I0 and c·FDJ: said, not guessed
    assert completed is not None and completed.nominal is not None and completed.screw.current_per_nm_a is not None


def test_runs_at_one_load_leave_fdj_and_eta_o_one_number():
    report, completed, _ = calibrate_linear(runs("normal", 20, range(5)), DOCUMENT)
    assert report.drive is not None and report.drive.fdj_nm is None and report.drive.eta_o is None
    assert completed is not None and completed.nominal is None
    assert any("one load size" in line for line in report.drive.not_separable)


def _fdj(windows, document) -> np.ndarray:
    results = [estimate(w, actuator=document) for w in windows]
    assert all(r.estimates.eta_O is None and r.stages["simulate"].startswith("skipped") for r in results)
    return np.array([(r.estimates.FDJ.value, r.estimates.FDJ.std) for r in results])


def test_states_are_told_apart_on_runs_the_calibration_did_not_see(learned):
    _, document = learned
    held_out = range(5, 10)
    normal20, normal40 = _fdj(runs("normal", 20, held_out), document), _fdj(runs("normal", 40, held_out), document)
    dry20 = _fdj(runs("lackLubrication1", 20, range(10)), document)
    med = {name: float(np.median(v[:, 0])) for name, v in [("n20", normal20), ("n40", normal40), ("dry", dry20)]}
    std = float(np.median(np.concatenate([normal20[:, 1], normal40[:, 1], dry20[:, 1]])))
    assert abs(med["n20"] - med["n40"]) < 2 * std  # the healthy state's FDJ whatever the load
    assert med["dry"] - med["n20"] > 2 * std  # a lack of lubrication is a friction rise, beyond 2 std
    for values in (normal20, normal40, dry20):  # each run's ±2 std holds its set's median
        assert np.mean(np.abs(values[:, 0] - np.median(values[:, 0])) <= 2 * values[:, 1]) >= 0.9


def test_faulted_runs_against_the_baseline_say_what_changed(learned):
    _, document = learned
    report, completed, _ = calibrate_linear(runs("lackLubrication1", 20, range(10)), document)
    assert completed is None and report.changes[0].parameter == "FDJ" and report.changes[0].z > 2
    change = report.changes[0]
    assert change.departed and "rose" in change.said and "friction gained" in change.said


def test_healthy_runs_logged_apart_name_nothing_along_the_stroke(learned):
    """Healthy runs the calibration did not see, at either load: their FDJ within one run's scatter, and no
    local defect (their mean current along the stroke stays within one run's noise of the healthy profile)."""
    _, document = learned
    for load in (20, 40):
        report, _, _ = calibrate_linear(runs("normal", load, range(5, 10)), document)
        assert report.selected_effects == [] and report.candidates[0].score < NAME_Z
        assert abs(report.changes[0].z) < 2 and not report.changes[0].departed


def test_a_document_without_the_healthy_spread_does_not_compare_the_stroke(learned):
    """A document learned before the spread was kept: the runs' own scatter alone would take the profile of
    another load for a defect, so the stroke is not compared, and the report says why."""
    _, document = learned
    older = document.model_copy(update={"screw": document.screw.model_copy(update={"stroke_profile_std_a": None})})
    report, _, _ = calibrate_linear(runs("normal", 40, range(5, 10)), older)
    assert report.selected_effects == [] and "not compared" in report.selection_steps[0].reason


def test_a_local_rise_of_the_current_along_the_stroke_is_named(learned):
    """A spall's form, added to held-out healthy runs: 0.3 A more current wherever the nut passes 60-75 mm."""
    _, document = learned
    spalled = []
    for window in runs("normal", 20, range(5, 10)):
        signals = dict(window.signals)
        over = (signals["position_mm"] > 60.0) & (signals["position_mm"] < 75.0)
        signals["current_a"] = signals["current_a"] + 0.3 * over * (np.abs(np.gradient(signals["position_mm"])) > 0.5)
        spalled.append(replace(window, signals=signals))
    report, _, _ = calibrate_linear(spalled, document)
    assert report.selected_effects == ["position_friction"] and report.candidates[0].score >= NAME_Z


def test_a_run_that_never_rests_is_refused_for_learning_naming_it():
    window = runs("normal", 20, range(1))[0]
    moving = slice(0, 120)  # the first stroke only
    cut = window.__class__(
        {k: v[moving] for k, v in window.signals.items()}, window.sample_rate_hz, None, window.actuator_id, "cut"
    )
    with pytest.raises(InputError, match="window cut"):
        read_run(cut, DOCUMENT)


def _signed(windows: list, signal: str) -> list:
    """``windows`` with ``signal`` logged with the other sign (a log map's sign left out)."""
    return [replace(w, signals={**w.signals, signal: -w.signals[signal]}) for w in windows]


@pytest.mark.parametrize(("signal", "named"), [("current_a", "signals.current_a"), ("load_n", "signals.load_n")])
def test_healthy_runs_logged_with_a_sign_reversed_teach_nothing(signal, named):
    """A stepper's current is a magnitude: at rest below zero, or falling as the opposing load grows, it is a sign."""
    healthy = runs("normal", 20, range(3)) + runs("normal", 40, range(3))
    with pytest.raises(InputError) as refused:
        calibrate_linear(_signed(healthy, signal), DOCUMENT)
    assert refused.value.field == named and "the other sign" in refused.value.message


def test_a_run_whose_current_is_logged_with_the_other_sign_is_refused_not_read_as_negative_friction(learned):
    _, completed = learned
    with pytest.raises(InputError) as refused:
        estimate(_signed(runs("normal", 20, range(5, 6)), "current_a")[0], actuator=completed)
    assert refused.value.field == "signals.current_a" and "FDJ -" in refused.value.message


def test_a_run_read_with_its_time_in_the_wrong_unit_says_how_long_it_then_lasts(learned):
    """The rig's time read as ms makes a 13 s run last 0.013 s at 25 kHz: the refusal says so, not only the rate."""
    from ema.model.logmap import logmap_from_dict

    in_ms = logmap_from_dict(MAP.model_dump(by_alias=True) | {"time": {"column": "time", "unit": "ms"}})
    path = sorted((RIG / "runs").glob("normal_load20_run*.csv"))[5]
    with pytest.raises(InputError) as refused:
        estimate(window_from_dict(read_mapped(path, in_ms)), actuator=learned[1])
    assert "the window spans 0.013 s at 25000 Hz" in refused.value.message


def test_a_repeatability_std_tells_what_runs_of_one_state_scatter_by(learned):
    """Held-out healthy runs: each within ±2 repeatability std of its set's median about 95 % of the time, that std
    well under the whole std (which carries the document's own η_O and c, shared by every run)."""
    _, document = learned
    inside, ratios = [], []
    for load in (20, 40):
        fdj = [estimate(w, actuator=document).estimates.FDJ for w in runs("normal", load, range(5, 10))]
        values, repeatable = np.array([e.value for e in fdj]), np.array([e.repeatability_std for e in fdj])
        inside += list(np.abs(values - np.median(values)) <= 2 * repeatable)
        ratios += [e.repeatability_std / e.std for e in fdj]
    assert np.mean(inside) >= 0.8 and max(ratios) < 0.9


@pytest.mark.parametrize(("state", "load"), [("lackLubrication2", 40), ("backlash2", 20), ("spalling8", 40)])
def test_a_seeded_fault_departs_either_way(learned, state, load):
    _, document = learned
    report, _, _ = calibrate_linear(runs(state, load, range(10)), document)
    fdj = report.changes[0]
    assert fdj.departed and fdj.load_n == pytest.approx(load * 9.80665, rel=0.01)
    assert ("fell" in fdj.said) == (state == "spalling8")  # a spalled screw loses its preload: friction falls


def test_a_fall_of_friction_in_one_window_is_noted(learned):
    _, document = learned
    result = estimate(runs("spalling8", 40, range(1))[0], actuator=document)
    note = next(n for n in result.notes if n.code == "fdj_departed")
    assert "friction lost" in note.text and result.estimates.FDJ.value < document.health.fdj


def test_a_load_the_healthy_runs_never_had_is_said_and_shows_no_fault(learned):
    """At −40 kgf the load's sign is one the calibration never saw: the nominal is extrapolated, and the report says
    how large a change it cannot show (the lab sees the opposing stroke's current unmoved there by any fault)."""
    _, document = learned
    healthy, _, _ = calibrate_linear(runs("normal", -40, range(10)), document)
    assert not healthy.changes[0].departed and "not shown here" in healthy.changes[0].said
    assert "not compared at -392 N" in healthy.selection_steps[0].reason
    result = estimate(runs("normal", -40, range(1))[0], actuator=document)
    assert [n for n in result.notes if n.code == "load_extrapolated"]
