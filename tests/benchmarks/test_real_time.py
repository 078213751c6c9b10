"""The real-time benchmark's report: shares of the idle p95 and of both yardstick readings."""

import numpy as np

from benchmarks.real_time import FAMILIES, LOADED_LIMIT, documents, report


def test_each_row_is_its_p95_over_the_idle_one_and_over_each_yardstick() -> None:
    idle = list(np.linspace(0.1, 0.2, 21))  # p95 0.195
    loaded = [2 * x for x in idle]
    text = report({"idle": idle, "2 busy processes": loaded}, {"one thread": 1.95, "every thread": 0.975}, 21)
    rows = [line for line in text.splitlines() if line.startswith(("| idle", "| 2 busy"))]
    assert rows[0] == "| idle | 0.150 | 0.195 | 1.00 | 0.100 | 0.200 |"
    assert rows[1] == "| 2 busy processes | 0.300 | 0.390 | 2.00 | 0.200 | 0.400 |"
    assert f"≤ {LOADED_LIMIT:g}x the idle p95" in text


def test_windows_are_foreign_and_take_the_families_in_turn() -> None:
    drawn = documents(len(FAMILIES) + 1, seed=7)
    assert [d["actuator_id"] for d in drawn] == [f"foreign/{f}" for f in (*FAMILIES, FAMILIES[0])]
    assert len({d["window_id"] for d in drawn}) == len(drawn)
