"""Sensors that stopped updating: found only where they cannot be a working sensor, bridged or cut out, and
the window read from what is left, on windows of the independent implementation (``tests.foreign``)."""

import copy

import numpy as np
import pytest

from benchmarks.foreign_groups import group_seed, groups
from ema.estimate.report import share_of_range
from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.friction import solve_window
from ema.kinds.rotary.prepare.conditioning import Prepared, conditioning_done, conditioning_notes, prepare, widened
from ema.kinds.rotary.prepare.stale import MIN_STALE_SAMPLES, equal_runs, stale_runs
from ema.model.actuator import THESIS
from ema.model.checks import InputError
from ema.model.window import window_from_dict
from tests.foreign.faults import FAULTS, Fault, frozen, stretch, with_fault
from tests.foreign.windows import draw

FAMILIES = ("thesis", "cruise", "gust", "doublet", "steps")


def _physics(document: dict) -> tuple[dict[str, float], dict[str, float], Prepared]:
    """Eq. 5.1's answer to the window as prepared, its stds widened by what conditioning left open."""
    prepared = prepare(window_from_dict(document), actuator=THESIS)
    w = prepared.window
    solved = solve_window(as_read(w.signals, w.sample_rate_hz), w.sample_rate_hz, prepared.drive_as_read)
    stds = widened({"FDJ": float(solved.fdj_std_nm[0]), "eta_O": float(solved.eta_o_std[0])}, prepared)
    return {"FDJ": float(solved.fdj_nm[0]), "eta_O": float(solved.eta_o[0])}, stds, prepared


def _fault(seed: int) -> Fault:
    """A sensor of the three Eq. 5.1 reads, in turn, holding its last value or at 0 in turn, over 5–25 %."""
    return Fault(("current_a", "motor_speed_radps", "hinge_moment_nm")[seed % 3], (None, 0.0)[seed % 2])


@pytest.mark.parametrize("group", ["gust", "low log rate (1-2 kHz)", "held position", "sensors behind filters"])
def test_no_working_sensor_of_a_foreign_window_is_taken_for_a_stale_one(group):
    make = groups()[group]
    for seed in range(5200, 5206):
        assert stale_runs(window_from_dict(make(seed).document), drive=THESIS.params) == ()


def test_a_frozen_or_dropped_out_sensor_is_cut_out_and_the_rest_read_within_its_std():
    """Left in, a speed frozen over a fifth of a window put FDJ 0.3–7 ranges off, said weak."""
    covered, errors = 0, []
    for k, seed in enumerate(range(5300, 5312)):
        drawn, fault = draw(seed, FAMILIES[k % 5]), _fault(seed)
        name, n = fault.signal, len(drawn.document["signals"]["current_a"])
        start, stop = stretch(drawn.document, fault, seed)
        answer, std, prepared = _physics(with_fault(drawn.document, fault, seed))
        span = conditioning_done(prepared)["read_span"]
        assert span in ([0, start], [stop, n]), f"{name} frozen over [{start}, {stop}), read {span}"
        assert prepared.stale.samples[name] >= stop - start - 1
        assert any(n.code == "stale_sensor" and n.parameter == name for n in conditioning_notes(prepared))
        covered += all(abs(answer[p] - drawn.truth[p]) <= 2 * std[p] for p in answer)
        errors.extend(abs(share_of_range(p, answer[p] - drawn.truth[p], ranges=THESIS.ranges)) for p in answer)
    assert covered >= 11 and max(errors) < 0.1, f"{covered} of 12 covered, worst {max(errors):.3f} of range"


def test_a_sensor_quantized_coarser_than_its_noise_is_not_taken_for_a_frozen_one():
    """A current in 0.5 A steps (10x its noise) sits on one level through a steady slew."""
    drawn = draw(5400, "cruise")
    document = copy.deepcopy(drawn.document)
    document["signals"]["current_a"] = [round(i / 0.5) * 0.5 for i in document["signals"]["current_a"]]
    window = window_from_dict(document)
    assert np.max(np.diff(np.flatnonzero(np.diff(window.signals["current_a"]) != 0))) > 20  # long flat runs
    assert stale_runs(window, drive=THESIS.params) == ()


def test_a_speed_reading_exactly_zero_at_rest_is_no_frozen_sensor():
    """An encoder's speed reads 0 with the shaft at rest: between the steps of a foreign steps window."""
    drawn, clean = draw(5500, "steps"), draw(5500, "steps", noise_level=0.0)
    document = copy.deepcopy(drawn.document)
    at_rest = np.abs(clean.document["signals"]["motor_speed_radps"]) < 1.0
    speed = np.where(at_rest, 0.0, document["signals"]["motor_speed_radps"])
    document["signals"]["motor_speed_radps"] = speed.tolist()
    window = window_from_dict(document)
    longest = max(len(run) for run in np.split(speed, np.flatnonzero(np.diff(speed != 0)) + 1) if run[0] == 0)
    assert longest > 100 * MIN_STALE_SAMPLES  # rests long enough to be taken for one
    assert stale_runs(window, drive=THESIS.params) == ()


def test_a_window_with_too_little_sliding_left_is_refused_naming_the_sensor():
    drawn = draw(5600, "doublet")
    n = len(drawn.document["signals"]["current_a"])
    with pytest.raises(InputError, match="repeats 0 exactly") as refused:
        prepare(window_from_dict(frozen(drawn.document, "current_a", n // 20, n - n // 20, 0.0)), actuator=THESIS)
    assert refused.value.field == "signals.current_a"


def test_a_dropout_shorter_than_the_kernel_is_bridged_and_the_window_read_whole():
    """A current dropping to zero for 1.8 ms at slew moved FDJ by a median 4 of its stds (up to 84); 5 samples
    at 0 are no glitch for the glitch repair (3 at most) and barely improbable as repeats: they jump."""
    shifts, dropout = [], FAULTS["current at 0 for 0.5-2 ms at slew"]
    for k, seed in enumerate(range(5800, 5810)):
        drawn = draw(seed, FAMILIES[k % 5])
        start, _ = stretch(drawn.document, dropout, seed)
        clean, _, _ = _physics(drawn.document)
        for length in (5, 18):
            bridged, std, prepared = _physics(frozen(drawn.document, "current_a", start, start + length, 0.0))
            assert prepared.stale.samples == {"current_a": length} and prepared.stale.span is None
            shifts.append(abs(bridged["FDJ"] - clean["FDJ"]) / std["FDJ"])
    assert np.median(shifts) < 0.3 and max(shifts) < 1.5, f"FDJ moved by {np.round(shifts, 2)} of its std"


def test_a_chance_run_of_a_quantized_position_is_no_stale_run():
    """A foreign cruise window's position, quantized at a quarter of its noise (neighbours equal 7 % of the time),
    repeats one value over 8 samples as the shaft slides: 1 in ~6000 such signals, taken for a frozen sensor at a
    chance of 1e-3 (3 of 1623 clean benchmark windows were)."""
    window = window_from_dict(groups()["cruise"](group_seed("cruise", 0)).document)
    starts, stops = equal_runs(window.signals["position_deg"])
    assert (stops - starts).max() == 8
    assert stale_runs(window, drive=THESIS.params) == ()
