"""A geared servo learned from runs our simulator did not draw: the foreign servo's recorder logs (its loop at 1 kHz,
its motor's inductance, a Karnopp friction), at several loads, gains and set points."""

import itertools

import pytest

from ema import kinds
from ema.cli.logs import read_one
from ema.estimate.config import PipelineConfig
from ema.model.actuator import read_actuator
from ema.model.logmap import read_logmap
from tests.foreign.geared import Load, Servo, recorder_log

TRUTH = Servo(fdj=0.12, eta_o=0.8, eta_a=0.7, delay_s=0.03)
LOADS = [Load(mass, arm, kp) for mass, arm, kp in itertools.product((0.5, 1.1), (0.1, 0.15), (4.0, 12.0))]
SHAPES = ("steps", "sines", "rise")


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    folder = tmp_path_factory.mktemp("foreign-runs")
    log_map = read_logmap("examples/sts3215/log-map.json")
    windows = []
    for i, (load, shape) in enumerate(itertools.product(LOADS, SHAPES)):
        path = recorder_log(folder / f"run{i:02d}.json", TRUTH, load, kind=shape, seed=i,
                            off_after_s=4.0 if shape == "rise" else None)  # fmt: skip
        windows.append(read_one(path, log_map))
    document = read_actuator("examples/sts3215/actuator.json")
    request = kinds.CalibrationRequest(PipelineConfig(), document)
    return kinds.calibrate(windows, request), windows


def test_the_efficiency_and_the_delay_are_named_and_the_error_falls(calibrated):
    result, _ = calibrated
    report = result.report
    assert report.selected_effects[0] == "efficiency" and "command_delay" in report.selected_effects
    errors = report.position_error_rad
    assert errors["held_out_after"] < 0.8 * errors["held_out_before"]


def test_the_learned_health_holds_the_foreign_servos(calibrated):
    result, _ = calibrated
    nominal, stds = result.completed.nominal, result.completed.geared.stds
    for name, truth in (("fdj_nm", TRUTH.fdj), ("eta_o", TRUTH.eta_o), ("eta_a", TRUTH.eta_a)):
        assert abs(getattr(nominal, name) - truth) <= 2 * stds[name], name
    assert result.completed.geared.command_delay_s == pytest.approx(TRUTH.delay_s, abs=0.01)


def test_every_load_reads_the_one_servo(calibrated):
    result, _ = calibrated
    for load in result.report.by_load:
        assert abs(load.z["fdj_nm"]) <= 2, load


def test_a_run_read_with_the_completed_document_holds_its_truth(calibrated):
    result, windows = calibrated
    estimate = kinds.estimate(windows[4], PipelineConfig(), actuator=result.completed)
    fdj = estimate.estimates.FDJ
    assert abs(fdj.value - TRUTH.fdj) <= 2 * fdj.std
    assert estimate.check.mean_abs_error["position_rad"] < 0.05
    assert {"resampled", "glitches_repaired", "position_quantized"} <= {note.code for note in estimate.notes}
