"""The thesis's aim on windows our code did not draw: an actuator's history -> trend and remaining life.

Each actuator wears in flight hours (linearly, faster and faster, or not at all), and its windows
come from ``tests.foreign`` as a fleet logs them (``PROSE``); every window goes through
``estimate_window`` and the history through ``prognose``, as the service does. Per actuator: how
its windows' answers fared, the trend's level at the last window against the truth there, and the
true remaining life against the 90 % interval.

    python -m benchmarks.foreign_history [--actuators 16] [--speeding 8] [--healthy 32] [--windows 30] [--docs]
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.tails import BOUND
from benchmarks.wearing_fleet import KINDS_OF_WEAR, Thresholds, Wear, flights, logged_window, wear
from ema.cli.benchmark_docs import write_section
from ema.estimate import thread_budget
from ema.estimate.documents.window_facts import RotaryWindowInfo
from ema.estimate.report import share_of_range
from ema.kinds import readings_of_results
from ema.kinds.rotary.other_windows import as_readings
from ema.kinds.rotary.pipeline import estimate_window
from ema.model.actuator import THESIS
from ema.model.checks import InputError
from ema.model.window import window_from_dict
from ema.prognosis.documents import Prognosis, Stored
from ema.prognosis.prognose import prognose

PROGNOSIS_MD = Path(__file__).resolve().parent.parent / "docs" / "prognosis.md"
PROSE = """A window that holds little (0.1 s, a 1–2 kHz log, a cold grease it cannot read) is answered
weak, and the remedy `docs/results.md` names is the actuator's history, each window weighed by its std.
This checks that remedy end to end. Sixteen actuators wear linearly in flight hours: FDJ from
0.045–0.055 N·m towards its threshold (1.5x nominal), η_O from 0.85–0.95 towards 0.70, each crossing
1.5–4 times the logged span of 1000 flight hours after the first window. Its windows, at flight hours
drawn uniformly over the span, come from `tests/foreign` (the independent implementation) as a fleet
logs them: the five families, half 0.5 s at 10 kHz, a fifth 0.1 s gusts, a fifth 1–2 kHz logs, a
tenth 2 s cruise; in three of ten a grease 1.2–2x as viscous as the document's (a cold flight), unlogged.
Eight more wear as the square of the hours (wear that speeds up: a line through their windows
crosses the threshold ~3x too late, surely), and thirty-two do not wear at all (a monitor that claims
a degradation or a change there raises a false alarm). Eight more wear linearly with a rotor 1.03–1.1x as heavy as
the document's J_M, unlogged: a window whose motor saturates as it accelerates cannot tell that from a
weaker motor, and is read with the J_M earlier windows of the actuator read (thesis-like windows can;
each read alone, `--actuators 0 --speeding 0 --healthy 0 --zeroed 0 --alone`, 143 of their 240 FDJ answers were
past 10 % of the range, all said weak, the level up to 12 % of range off, and 4 of 8 FDJ lives
missed: 3 with no degradation detected, 1 outside its interval). Eight more wear linearly and log
three windows a flight, 0.3 h apart, their current sensor 0.04–0.2 A off zero, drawn anew each flight
(`flight_id`): a window moving one way cannot read that, and is read with the zero an earlier window
of its flight read.
Every window goes through `estimate_window` with what the actuator's earlier windows read
(`ema.kinds.rotary.other_windows`), and the history through `prognose`, as the service does
(`benchmarks/foreign_history.py`). Per actuator: its windows' FDJ
answers said weak, past 10 % of the range, and past it without saying so; the trend's level at the
last window against the truth there (error in % of the range and in the trend's stds); the true
remaining life against the predicted one and its 90 % interval (✗: outside; for a healthy
actuator, a degradation claimed)."""


def history(
    actuator: int, truth: Wear, n_windows: int, thresholds: Thresholds, alone: bool = False
) -> tuple[Prognosis, dict[str, Any]]:
    """The actuator's prognosis from its estimated windows, and how its windows' answers fared (a window
    refused is left out of the history, as the service stores none); ``alone``: each window read without
    what earlier ones read."""
    hours, flight_ids, offsets = flights(actuator, truth, n_windows)
    stored: list[Any] = []
    refused: list[Any] = []
    weak, over, unsaid, undecided, decided, zeroed = 0, 0, 0, 0, 0, 0
    for j, (h, flight_id) in enumerate(zip(hours, flight_ids, strict=True)):
        drawn = logged_window(actuator, j, float(h), truth, thresholds, float(offsets[j]))
        if flight_id is not None:
            drawn.document["flight_id"] = flight_id
        known = (
            None if alone else as_readings(readings_of_results(THESIS, [s.window for s in stored], flight_id))
        )  # as the service reads it
        try:
            result = estimate_window(window_from_dict(drawn.document), history=known, actuator=THESIS)
        except InputError as exc:
            rate = drawn.document["sample_rate_hz"]
            refused.append(f"{actuator}/{drawn.document['window_id']} ({drawn.family}, {rate:g} Hz): {exc}")
            continue
        fdj = result.estimates.FDJ
        past = abs(share_of_range("FDJ", fdj.value - drawn.truth["FDJ"], ranges=THESIS.ranges)) > BOUND
        weak, over, unsaid = weak + fdj.weakly_determined, over + past, unsaid + (past and not fdj.weakly_determined)
        read = result.window
        assert isinstance(read, RotaryWindowInfo)  # a rotary window at 10 kHz: its prepare stage ran
        undecided, decided = undecided + read.inertia_undecided, decided + bool(read.inertia_from)
        zeroed += read.sensor_zero_from is not None
        stored.append(Stored(**result.model_dump(), id=j, stored_at="2026-01-01T00:00:00+00:00"))
    fared = {
        "weak": weak,
        "over": over,
        "unsaid": unsaid,
        "refused": refused,
        "undecided": undecided,
        "decided": decided,
        "zeroed": zeroed,
    }
    return prognose(f"foreign/history-{actuator}", stored, THESIS), fared


def scored(prognosis: Prognosis, wear_: Wear, thresholds: Thresholds) -> dict[str, dict[str, Any]]:
    """Per parameter: the level's error in its stds and share of range, and the true life against the RUL."""
    out = {}
    for name, crossing in (("FDJ", wear_.fdj_crossing_h), ("eta_O", wear_.eta_o_crossing_h)):
        trend, life = prognosis.trends[name], prognosis.remaining_life[name]
        last = max(point.time for point in trend.points)
        true_level = getattr(wear_.health(last, thresholds), {"FDJ": "fdj_nm", "eta_O": "eta_o"}[name])
        true_life = crossing - last  # inf: a healthy actuator's
        low, high = life.rul_low, np.inf if life.rul_high is None else life.rul_high
        level, level_std = trend.now()
        out[name] = {
            "level_z": (level - true_level) / level_std,
            "level_of_range": share_of_range(name, level - true_level, ranges=THESIS.ranges),
            "true_life": true_life,
            "status": life.status,
            "rul": life.rul,
            "interval": (life.rul_low, life.rul_high),
            "held": (life.status != "crossing predicted")
            if math.isinf(true_life)
            else (life.status == "crossing predicted" and low is not None and low <= true_life <= high),
        }
    return out


def _life(score: dict[str, Any]) -> str:
    """The true life against the predicted one, in flight hours."""
    if math.isinf(score["true_life"]):
        return f"none: {score['status']}{'' if score['held'] else ' ✗'}"
    if score["status"] != "crossing predicted":
        return f"{score['true_life']:.0f} h: {score['status']}"
    low, high = score["interval"]
    upper = "open" if high is None else f"{high:.0f}"
    return f"{score['true_life']:.0f} h: {score['rul']:.0f} [{low:.0f}–{upper}]{'' if score['held'] else ' ✗'}"


def table(rows: list[dict[str, Any]]) -> str:
    lines = [
        "| actuator | windows answered: FDJ weak / past 10 % of range / past it, not said weak "
        "| FDJ level error: % of range (stds) | FDJ life: true: RUL [90 %] "
        "| η_O level error: % of range (stds) | η_O life: true: RUL [90 %] |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for row in rows:
        f, e = row["scores"]["FDJ"], row["scores"]["eta_O"]
        lines.append(
            f"| {row['actuator']} | {row['n'] - len(row['refused'])}: {row['weak']} / {row['over']} / {row['unsaid']} "
            f"| {100 * f['level_of_range']:+.1f} ({f['level_z']:+.1f}) | {_life(f)} "
            f"| {100 * e['level_of_range']:+.1f} ({e['level_z']:+.1f}) | {_life(e)} |"
        )
    return "\n".join(lines)


def summary(rows: list[dict[str, Any]]) -> str:
    """The table in one paragraph: the windows, the levels, and the lives by kind of wear."""
    parts = []
    for name, label in (("FDJ", "FDJ"), ("eta_O", "η_O")):
        level = sum(abs(r["scores"][name]["level_z"]) <= 2 for r in rows)
        worst = max(abs(r["scores"][name]["level_of_range"]) for r in rows)
        lives = []
        for kind in KINDS_OF_WEAR:
            chosen = [r["scores"][name]["held"] for r in rows if r["kind"] == kind]
            what = "no degradation claimed" if kind == "healthy" else "the true life inside the 90 % interval"
            lives.append(f"{kind}: {what} in {sum(chosen)} of {len(chosen)}")
        parts.append(
            f"{label}: level within ±2 std in {level} of {len(rows)} (worst {100 * worst:.1f} % of range); "
            + "; ".join(lives)
        )
    windows = sum(r["n"] for r in rows)
    over, unsaid = sum(r["over"] for r in rows), sum(r["unsaid"] for r in rows)
    heavier = [r for r in rows if r["kind"] == "linear, heavier rotor"]
    parts.append(
        f"Heavier rotors: of their {sum(r['n'] for r in heavier)} windows, "
        f"{sum(r['decided'] + r['undecided'] for r in heavier)} could not tell J_M from k_T alone; the "
        f"actuator's J_M read by earlier windows decided {sum(r['decided'] for r in heavier)}"
    )
    zeroed = [r for r in rows if r["kind"] == "linear, zero off by flight"]
    carried = sum(r["zeroed"] for r in zeroed)
    parts.append(
        f"Zero off by flight: of their {sum(r['n'] for r in zeroed)} windows, {carried} were read with "
        "the zero an earlier window of their flight read"
    )
    healthy = [r for r in rows if r["kind"] == "healthy"]
    wearing = [r for r in rows if r["kind"] != "healthy"]
    parts.append(
        "A trend moving away from its watched level (moving_away, 3 std): noted on "
        f"{sum(r['away'] for r in healthy)} of the healthy actuators' {sum(r['trends'] for r in healthy)} trends "
        f"({sum(r['away'] > 0 for r in healthy)} of {len(healthy)} actuators), and on "
        f"{sum(r['away'] for r in wearing)} of the wearing ones' {sum(r['trends'] for r in wearing)}"
    )
    refused = [f for r in rows for f in r["refused"]]
    head = (
        f"{windows} windows, {len(refused)} refused, {over} answered FDJ past 10 % of range ({unsaid} not said weak). "
    )
    tail = "".join(f"\n\nRefused: {f}" for f in refused)
    return head + ". ".join(parts) + "." + tail


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--actuators", type=int, default=16, help="histories of actuators wearing linearly")
    parser.add_argument("--speeding", type=int, default=8, help="histories of actuators whose wear speeds up")
    parser.add_argument("--healthy", type=int, default=32, help="histories of healthy actuators (no wear)")
    parser.add_argument("--heavier", type=int, default=8, help="histories of linearly wearing heavier rotors")
    parser.add_argument("--zeroed", type=int, default=8, help="histories whose current sensor's zero changes by flight")
    parser.add_argument("--windows", type=int, default=30, help="windows per history")
    parser.add_argument("--alone", action="store_true", help="each window without what earlier ones read")
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/prognosis.md")
    args = parser.parse_args()
    thread_budget.configure()
    started, thresholds, rows = time.perf_counter(), Thresholds.of(THESIS), []
    sizes = (args.actuators, args.speeding, args.healthy, args.heavier, args.zeroed)
    counts = dict(zip(KINDS_OF_WEAR, sizes, strict=True))
    for offset, kind in zip((0, 200, 100, 300, 400), KINDS_OF_WEAR, strict=True):
        for actuator in range(offset, offset + counts[kind]):
            truth = wear(actuator, kind)
            prognosis, fared = history(actuator, truth, args.windows, thresholds, args.alone)
            rows.append(
                {
                    "actuator": f"{actuator} ({kind})",
                    "kind": kind,
                    "n": args.windows,
                    **fared,
                    "scores": scored(prognosis, truth, thresholds),
                    "away": sum(n.code == "moving_away" for n in prognosis.notes),
                    "trends": len(prognosis.trends),
                }
            )
            print(table(rows[-1:]).splitlines()[-1], flush=True)
    body = "\n".join([PROSE, f"Total {time.perf_counter() - started:.0f} s.", "", table(rows), "", summary(rows)])
    print(body)
    if args.docs and not args.alone:
        command = (
            f"python -m benchmarks.foreign_history --actuators {args.actuators} --speeding {args.speeding} "
            f"--healthy {args.healthy} --heavier {args.heavier} --zeroed {args.zeroed} --windows {args.windows} "
            "--docs"
        )
        write_section("On windows our code did not draw", command, body, PROGNOSIS_MD)


if __name__ == "__main__":
    main()
