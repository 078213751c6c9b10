"""Where a warm request's time goes: each stage of the pipeline by its steps, on hidden windows.

The windows are the real-time benchmark's (``tests.foreign``: its own simulator, noise and five command
families), estimated in-process one after another, warm, idle. Each step is timed by wrapping the
function the stage calls (``PARTS``: the stage, where the stage looks the function up, and what it
does), counted only while its stage runs (a step called from two stages is two parts); what a
stage spends outside its listed steps is its *rest*. A wrapper adds two clock reads to a call. Steps
on the simulator's threads (the kernel, the row loops) are wall time on every thread of the budget.

    python -m benchmarks.request_parts [--windows 40] [--docs]
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import importlib
import time
from collections import defaultdict
from collections.abc import Callable, Iterator
from typing import Any

from benchmarks.real_time import documents
from benchmarks.service_overhead import quiet_collector
from ema.cli.benchmark_docs import write_section
from ema.estimate import thread_budget
from ema.estimate.config import PipelineConfig
from ema.kinds.rotary.pipeline import estimate_window
from ema.model.actuator import THESIS
from ema.model.window import WindowDocument

SECTION = "A warm request, step by step"
STAGES = ("prepare", "physics", "simulate", "learn", "assess", "check", "report")  # the pipeline's, in order
SIMULATIONS = PipelineConfig().total_simulations
PARTS = (  # (stage, "module:function" as the stage calls it, what the step does)
    ("prepare", "ema.kinds.rotary.prepare.conditioning:without_stale", "cut to the stretch the sensors kept updating"),
    ("prepare", "ema.kinds.rotary.prepare.conditioning:repaired", "glitches repaired"),
    ("prepare", "ema.kinds.rotary.prepare.conditioning:check_consistency", "the signals checked against each other"),
    ("prepare", "ema.kinds.rotary.prepare.conditioning:aligned", "the sensors put on one clock"),
    (
        "prepare",
        "ema.kinds.rotary.prepare.conditioning:check_against_aircraft",
        "the hinge moment against the airframe",
    ),
    ("prepare", "ema.kinds.rotary.prepare.conditioning:read_departures", "departures from the actuator document"),
    ("prepare", "ema.kinds.rotary.prepare.conditioning:step_lag", "the hinge moment's step lag"),
    ("physics", "ema.kinds.rotary.pipeline:solve_window", "Eq. 5.1 on the window"),
    (
        "simulate",
        "ema.kinds.rotary.simulator.batch:run_groups",
        f"the kernel: {SIMULATIONS} simulations and the clean lane",
    ),
    ("simulate", "ema.kinds.rotary.dataset:excess_noise", "the window's noise, read against the clean lane"),
    ("simulate", "ema.kinds.rotary.dataset:add_seeded_noise", "that noise added to the simulations"),
    ("simulate", "ema.kinds.rotary.dataset:as_read", "the simulations read as the window is"),
    ("simulate", "ema.kinds.rotary.dataset:residual_torque_nm", "T_R of the simulations and the window"),
    ("simulate", "ema.kinds.rotary.dataset:sliding_features", "the network's inputs"),
    ("learn", "ema.kinds.rotary.pipeline:learned", "the network trained"),
    ("assess", "ema.kinds.rotary.pipeline:solve_friction", "Eq. 5.1 on the held-out simulations"),
    ("assess", "ema.kinds.rotary.network:NetworkEstimator.predict_unit", "the network on them and the window"),
    ("assess", "ema.kinds.rotary.pipeline:assess", "the estimators weighed and blended"),
    ("check", "ema.kinds.rotary.simulator.batch:run_groups", "the window simulated at the answer (where not reused)"),
    ("check", "ema.kinds.rotary.reproduction:as_read", "that simulation read as the window is"),
    ("check", "ema.kinds.rotary.reproduction:residual_torque_nm", "T_R of both"),
    ("report", "ema.kinds.rotary.pipeline:read_static_friction", "FSJ read where the window shows one"),
)


class Clock:
    """The stage now running (from the pipeline's announcements, which come in ``STAGES`` order) and the
    seconds each (stage, function) has taken."""

    def __init__(self) -> None:
        self.index = -1
        self.seconds: dict[tuple[str, str], float] = defaultdict(float)

    def next_stage(self, _: str) -> None:
        self.index = (self.index + 1) % len(STAGES)

    def timed(self, key: str, stages: set[str], function: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(function)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            stage = STAGES[self.index]
            if stage not in stages:
                return function(*args, **kwargs)
            started = time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                self.seconds[stage, key] += time.perf_counter() - started

        return wrapper


def resolve(key: str) -> tuple[Any, str]:
    """(the module or class that holds it, its name) of a ``PARTS`` key, "module:function" or
    "module:Class.method"."""
    module_name, path = key.split(":")
    owner: Any = importlib.import_module(module_name)
    *classes, name = path.split(".")
    for cls in classes:
        owner = getattr(owner, cls)
    return owner, name


@contextlib.contextmanager
def instrumented(clock: Clock) -> Iterator[None]:
    """Every function of ``PARTS`` wrapped where its stage looks it up, restored on exit."""
    stages: dict[str, set[str]] = defaultdict(set)
    for stage, key, _ in PARTS:
        stages[key].add(stage)
    originals = []
    for key, where in stages.items():
        owner, name = resolve(key)
        originals.append((owner, name, getattr(owner, name)))
        setattr(owner, name, clock.timed(key, where, getattr(owner, name)))
    try:
        yield
    finally:
        for owner, name, original in originals:
            setattr(owner, name, original)


def measure(count: int, seed: int) -> tuple[dict[tuple[str, str], float], dict[str, float]]:
    """Mean seconds per request of each (stage, step) and of each stage, over ``count`` warm windows."""
    thread_budget.configure()
    windows = [WindowDocument.model_validate(d).to_window() for d in documents(count, seed)]
    for window in windows[:3]:
        estimate_window(window, actuator=THESIS)
    quiet_collector()  # the collector's full passes over the loaded modules are not the request's
    clock, stages = Clock(), defaultdict[str, float](float)
    with instrumented(clock):
        for window in windows:
            clock.index = -1
            timings = estimate_window(window, actuator=THESIS, on_stage=clock.next_stage).timings_s
            for stage in STAGES:
                stages[stage] += getattr(timings, stage) / count
    return {k: v / count for k, v in clock.seconds.items()}, dict(stages)


def report(parts: dict[tuple[str, str], float], stages: dict[str, float], count: int) -> str:
    total = sum(stages.values())
    lines = [
        f"{count} hidden 0.5 s windows at 10 kHz (`tests.foreign`, the real-time benchmark's), estimated",
        "in-process one after another, warm, idle, default sizes; mean ms per request. *Rest*: what the",
        "stage spends outside its listed steps (assembling, small reads, notes).",
        "",
        "| stage | step | ms | share of the request |",
        "|---|---|---:|---:|",
    ]
    for stage in STAGES:
        listed = [(label, parts.get((stage, key), 0.0)) for s, key, label in PARTS if s == stage]
        rest = stages[stage] - sum(seconds for _, seconds in listed)
        lines.append(f"| **{stage}** | | **{1e3 * stages[stage]:.1f}** | **{stages[stage] / total:.0%}** |")
        for label, seconds in [*listed, ("rest", rest)]:
            if len(listed) > 1 or label != "rest":
                lines.append(f"| | {label} | {1e3 * seconds:.1f} | {seconds / total:.0%} |")
    lines += [
        f"| **request** | | **{1e3 * total:.1f}** | 100% |",
        "",
        "The service adds parsing, validation and storage (*Service overhead*); beside busy processes every",
        "part takes its share of the cores (*Real time on a warm service*).",
    ]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", type=int, default=40)
    parser.add_argument("--seed", type=int, default=390_000)
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/benchmarks.md")
    args = parser.parse_args()
    parts, stages = measure(args.windows, args.seed)
    body = report(parts, stages, args.windows)
    print(body)
    if args.docs:
        write_section(SECTION, f"python -m benchmarks.request_parts --windows {args.windows} --docs", body)


if __name__ == "__main__":
    main()
