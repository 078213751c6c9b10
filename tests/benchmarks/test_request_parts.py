"""The request's parts: each step is found where its stage calls it, its wrapper comes off, the table adds up."""

import pytest

from benchmarks.request_parts import PARTS, STAGES, Clock, instrumented, measure, report, resolve


def test_every_step_is_a_function_of_its_module_and_comes_off_after():
    keys = {key for _, key, _ in PARTS}
    before = {key: getattr(*resolve(key)) for key in keys}
    assert all(callable(function) for function in before.values())
    assert {stage for stage, _, _ in PARTS} == set(STAGES)
    with instrumented(Clock()):
        assert all(getattr(*resolve(key)) is not before[key] for key in keys)
    assert all(getattr(*resolve(key)) is before[key] for key in keys)


def test_a_step_counts_only_while_its_stage_runs():
    clock = Clock()
    double = clock.timed("m:f", {"simulate"}, lambda x: 2 * x)
    clock.next_stage("preparing")
    assert double(3) == 6 and not clock.seconds
    clock.next_stage("fitting")
    clock.next_stage("simulating")
    assert double(4) == 8 and set(clock.seconds) == {("simulate", "m:f")}


def test_each_stage_is_its_steps_and_its_rest():
    stages = dict.fromkeys(STAGES, 0.010)  # 70 ms a request
    parts = {("prepare", key): 0.002 for stage, key, _ in PARTS if stage == "prepare"}  # 7 steps: 14 > 10 ms
    text = report(parts, stages, 5)
    rows = text.splitlines()
    assert "| **prepare** | | **10.0** | **14%** |" in rows
    assert "| | rest | -4.0 | -6% |" in rows  # a rest below zero says the steps overlap: visible, not hidden
    assert "| | the network trained | 0.0 | 0% |" in rows
    assert "| **request** | | **70.0** | 100% |" in rows


@pytest.mark.slow
def test_every_step_is_reached_on_foreign_windows():
    parts, stages = measure(4, seed=390_000)
    reached = {key for key, seconds in parts.items() if seconds > 0}
    maybe = {
        ("check", "ema.kinds.rotary.simulator.batch:run_groups"),
        ("check", "ema.kinds.rotary.reproduction:as_read"),
    }  # reused lane
    assert {(stage, key) for stage, key, _ in PARTS} - maybe <= reached
    for stage in STAGES:
        listed = sum(seconds for (s, _), seconds in parts.items() if s == stage)
        assert listed <= stages[stage] * 1.001, stage
