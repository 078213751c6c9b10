"""The ``ema`` command line. Exit status: 0 success, 2 bad input (naming the field or file), 1 internal error."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from clients.bench import command_bench
from clients.replay import ServiceError, command_replay, print_replay
from clients.report import BENCHMARKS_MD
from sim.aircraft import FlightCondition
from sim.checks import InputError
from sim.effects import EffectSet
from sim.noise import NO_NOISE, SensorNoise
from sim.params import HealthParams, eta_a_from_eta_o
from sim.residual import residual_torque_nm
from sim.synthetic import synthetic_window
from sim.window import Window, read_window, write_window
from training.pipeline import PipelineConfig, estimate_window

EXIT_OK, EXIT_INTERNAL, EXIT_BAD_INPUT = 0, 1, 2


def parse_effect(text: str) -> tuple[str, dict[str, float]]:
    """``name:key=value,key=value`` (or just ``name`` for its neutral values) -> (name, parameters)."""
    name, _, assignments = text.partition(":")
    parameters: dict[str, float] = {}
    for assignment in filter(None, assignments.split(",")):
        key, sep, value = assignment.partition("=")
        if not sep:
            raise InputError("--effect", f"expected key=value in {assignment!r}")
        try:
            parameters[key.strip()] = float(value)
        except ValueError:
            raise InputError(f"--effect {name}.{key}", f"{value!r} is not a number") from None
    return name.strip(), parameters


def window_summary(window: Window) -> dict[str, Any]:
    """Ranges of the signals and of the reconstructed residual torque, for a human or a script."""
    signals = window.signals
    residual = residual_torque_nm(
        signals["current_a"], signals["motor_speed_radps"], signals["hinge_moment_nm"], window.sample_rate_hz
    )
    ranges = {name: [float(values.min()), float(values.max())] for name, values in signals.items()}
    ranges["residual_torque_nm"] = [float(residual.min()), float(residual.max())]
    moving = np.abs(signals["motor_speed_radps"]) > 5.0
    return {
        "actuator_id": window.actuator_id,
        "window_id": window.window_id,
        "n_samples": window.n_samples,
        "duration_s": window.duration_s,
        "sample_rate_hz": window.sample_rate_hz,
        "ranges": ranges,
        "moving_fraction": float(moving.mean()),
        "mean_abs_residual_torque_moving_nm": float(np.abs(residual[moving]).mean()) if moving.any() else None,
    }


def command_simulate(args: argparse.Namespace) -> dict[str, Any]:
    health = HealthParams.single(fsj_nm=args.fsj, fdj_nm=args.fdj, eta_o=args.eta_o)
    effects = EffectSet(dict(parse_effect(text) for text in args.effect))
    window = synthetic_window(
        health,
        FlightCondition(args.airspeed, args.altitude),
        seed=args.seed,
        duration_s=args.duration,
        sample_rate_hz=args.rate,
        noise=NO_NOISE if args.clean else SensorNoise(),
        effects=effects,
        actuator_id=args.actuator_id,
    )
    write_window(window, args.out)
    truth = {"FDJ": args.fdj, "eta_O": args.eta_o, "FSJ": args.fsj}
    if args.truth_out:
        Path(args.truth_out).write_text(json.dumps(truth, indent=2))
    return {
        "window": str(args.out),
        "truth": {**truth, "eta_A": float(eta_a_from_eta_o(args.eta_o))},
        "effects": effects.as_dict(),
        "noise": "none" if args.clean else SensorNoise().as_dict(),
        "summary": window_summary(window),
    }


def print_simulate(result: dict[str, Any]) -> None:
    summary = result["summary"]
    rate = summary["sample_rate_hz"]
    print(f"wrote {result['window']}: {summary['n_samples']} samples, {summary['duration_s']:g} s at {rate:g} Hz")
    truth = result["truth"]
    print(f"truth: FDJ {truth['FDJ']:.4f} N·m  η_O {truth['eta_O']:.4f}  η_A {truth['eta_A']:.4f}", end="")
    print(f"  FSJ {truth['FSJ']:.4f} N·m")
    print(f"effects: {result['effects'] or 'none'}   noise: {'none' if result['noise'] == 'none' else 'realistic'}")
    print(f"{'signal':<22}{'min':>12}{'max':>12}")
    for name, (low, high) in summary["ranges"].items():
        print(f"{name:<22}{low:>12.4g}{high:>12.4g}")
    print(f"moving {summary['moving_fraction']:.0%} of the window")


def command_estimate(args: argparse.Namespace) -> dict[str, Any]:
    window = read_window(args.window)
    config = PipelineConfig(
        n_simulations=args.sims,
        n_timesteps=args.timesteps,
        hidden_units=args.hidden,
        members=args.members,
        input_set=args.inputs,
        seed=args.seed,
    )
    return estimate_window(window, config, on_stage=lambda text: print(f"ema estimate: {text}…", file=sys.stderr))


def print_estimate(result: dict[str, Any]) -> None:
    print(f"{result['actuator_id']}  window {result['window_id']}")
    print(f"{'parameter':<10}{'value':>12}{'std':>12}{'nominal':>12}{'drift':>10}")
    for name, entry in result["estimates"].items():
        if name == "FSD" or entry is None:
            continue
        std = "—" if entry["std"] is None else f"{entry['std']:.2g}"
        print(f"{name:<10}{entry['value']:>12.5g}{std:>12}{entry['nominal']:>12.4g}{entry['drift_pct']:>9.2f}%")
    if result["estimates"]["FSJ"] is None:
        print(f"FSJ: not estimated: {result['fsj_note']}")
    timings = result["timings_s"]
    print("time: " + "  ".join(f"{stage} {seconds:.2f} s" for stage, seconds in timings.items()))


def command_serve(args: argparse.Namespace) -> dict[str, Any]:
    import uvicorn

    from service.config import Settings
    from service.main import create_app

    overrides = {"host": args.host, "port": args.port}
    if args.database:
        overrides["database"] = args.database
    settings = Settings(**{k: v for k, v in overrides.items() if v is not None})
    uvicorn.run(create_app(settings), host=settings.host, port=settings.port, log_level="info")
    return {"stopped": True}


def read_truth(path: Path | None) -> dict[str, float] | None:
    """``{"FDJ": 0.05, "eta_O": 0.85, "FSJ": 0.1}`` (FSJ optional); errors name the file."""
    if path is None:
        return None
    try:
        truth = json.loads(Path(path).read_text())
        return {key: float(truth[key]) for key in ("FDJ", "eta_O")}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputError(str(path), f"is not a truth file with FDJ and eta_O ({exc!r})") from None


def command_calibrate(args: argparse.Namespace) -> dict[str, Any]:
    from training.calibration.calibrate import Calibrator
    from training.calibration.figure import residual_figure

    windows = [read_window(path) for path in args.windows]
    config = PipelineConfig(n_simulations=args.sims, n_timesteps=args.timesteps, hidden_units=args.hidden)
    print(f"ema calibrate: {len(windows)} window(s), 3 pipeline runs each…", file=sys.stderr)
    calibrator = Calibrator(config, seed=args.seed).fit(windows, read_truth(args.truth))
    report = calibrator.report_
    selected = report["selected_effect"]
    variable = (report["unexplained_structure"] or {}).get("variable")
    figure = residual_figure(calibrator.residuals_before_, calibrator.residuals_after_, selected, variable, args.figure)
    return {**report, "figure": str(figure)}


def print_calibrate(report: dict[str, Any]) -> None:
    print(f"{'candidate':<22}{'BIC gain':>10}{'RMS cut':>9}  parameters")
    for c in sorted(report["candidates"], key=lambda c: -c["score"]):
        parameters = ", ".join(f"{k}={v:.4g}" for k, v in c["parameters"].items())
        flag = "" if c["plausible"] else "  (implausible)"
        print(f"{c['effect']:<22}{c['score']:>10.1f}{c['rms_reduction']:>8.0%}  {parameters}{flag}")
    print(f"selected: {report['selected_effect']} — {report['selection']['reason']}")
    if report["selected_parameters"]:
        print("  parameters: " + ", ".join(f"{k}={v:.4g}" for k, v in report["selected_parameters"].items()))
    if report["unexplained_structure"]:
        print(f"  unexplained: {report['unexplained_structure']['description']}")
    before, after = report["residual_rms_before"], report["residual_rms_after"]
    print("residual RMS: " + "  ".join(f"{k} {before[k]:.3g} -> {after[k]:.3g}" for k in before))
    for name in ("FDJ", "eta_O"):
        line = f"{name}: {report['estimates_before'][name]:.5g} -> {report['estimates_after'][name]:.5g}"
        if "error_pct_before" in report:
            line += f"   error {report['error_pct_before'][name]:.2f} % -> {report['error_pct_after'][name]:.2f} %"
        print(line)
    print(f"figure: {report['figure']}")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="ema", description="Onboard health monitor for an elevator EMA.")
    commands = parser.add_subparsers(dest="command", required=True)
    estimate = commands.add_parser("estimate", help="estimate FDJ, η_O, η_A (FSJ where it can) of one window")
    estimate.add_argument("window", type=Path, help="an ema-window/1 JSON file")
    estimate.add_argument("--sims", type=int, default=500, help="simulations in the training set (500)")
    estimate.add_argument("--timesteps", type=int, default=1000, help="network input timesteps (1000)")
    estimate.add_argument("--hidden", type=int, default=100, help="hidden neurons (100)")
    estimate.add_argument("--members", type=int, default=1, help="networks in the ensemble (1)")
    estimate.add_argument("--inputs", default="residual_torque", help="residual_torque or input_map")
    estimate.add_argument("--seed", type=int, default=0, help="seed of the dataset and the training")
    estimate.add_argument("--json", action="store_true", help="print one JSON document")
    estimate.set_defaults(run=command_estimate, show=print_estimate)
    serve = commands.add_parser("serve", help="run the HTTP service (settings: EMA_* environment variables)")
    serve.add_argument("--host", default=None, help="bind address (default 127.0.0.1, or EMA_HOST)")
    serve.add_argument("--port", type=int, default=None, help="port (default 8000, or EMA_PORT)")
    serve.add_argument("--database", type=Path, default=None, help="SQLite history file (or EMA_DATABASE)")
    serve.set_defaults(run=command_serve, show=lambda _: None, json=False)

    calibrate = commands.add_parser("calibrate", help="trace model discrepancy to a missing effect, add it")
    calibrate.add_argument("windows", type=Path, nargs="+", help="ema-window/1 JSON files of one actuator")
    calibrate.add_argument("--truth", type=Path, help="JSON with the true FDJ and eta_O (synthetic windows)")
    calibrate.add_argument("--figure", type=Path, default=Path("calibration.png"), help="PNG of the residuals")
    calibrate.add_argument("--sims", type=int, default=500, help="simulations per estimate (500)")
    calibrate.add_argument("--timesteps", type=int, default=1000, help="network input timesteps (1000)")
    calibrate.add_argument("--hidden", type=int, default=100, help="hidden neurons (100)")
    calibrate.add_argument("--seed", type=int, default=0, help="seed of the bootstrap")
    calibrate.add_argument("--json", action="store_true", help="print one JSON document")
    calibrate.set_defaults(run=command_calibrate, show=print_calibrate)

    bench = commands.add_parser("bench", help="latency benchmark of the whole pipeline over a grid of sizes")
    bench.add_argument("--out", type=Path, default=Path("bench-out"), help="folder for bench.json and bench.png")
    bench.add_argument("--repeats", type=int, default=5, help="windows per size (5)")
    bench.add_argument("--quick", action="store_true", help="one small size, no docs update (a smoke run)")
    bench.add_argument("--docs", type=Path, default=BENCHMARKS_MD, help="markdown file to update (docs/benchmarks.md)")
    bench.add_argument("--json", action="store_true", help="print one JSON document")
    bench.set_defaults(run=command_bench, show=lambda result: print(result["table"]))

    replay = commands.add_parser("replay", help="post a recorded log to the service window by window")
    replay.add_argument("log", type=Path, help="a JSON window / list / long recording, a CSV, an NPZ, or a folder")
    replay.add_argument("--url", default="http://127.0.0.1:8000", help="the service (default http://127.0.0.1:8000)")
    replay.add_argument("--out", type=Path, default=Path("estimates.csv"), help="CSV to append answers to")
    replay.add_argument("--window-s", dest="window_s", type=float, default=0.5, help="cut recordings into windows [s]")
    replay.add_argument("--api-key", dest="api_key", default=None, help="X-API-Key, if the service wants one")
    replay.add_argument("--actuator-id", dest="actuator_id", default="unknown", help="for CSV/NPZ without one")
    replay.add_argument("--rate", type=float, default=10_000.0, help="sample rate [Hz] for CSV/NPZ without one")
    replay.add_argument("--airspeed", type=float, default=153.01, help="[m/s] for CSV/NPZ without one")
    replay.add_argument("--altitude", type=float, default=0.0, help="[m] for CSV/NPZ without one")
    replay.add_argument("--json", action="store_true", help="print one JSON document")
    replay.set_defaults(run=command_replay, show=print_replay)

    simulate = commands.add_parser("simulate", help="write a synthetic ema-window/1 file from the model")
    simulate.add_argument("--out", required=True, type=Path, help="window JSON to write")
    simulate.add_argument("--fdj", type=float, default=0.05, help="dynamic friction FDJ [N·m] (default 0.05)")
    simulate.add_argument("--eta-o", dest="eta_o", type=float, default=0.85, help="opposing efficiency η_O (0.85)")
    simulate.add_argument("--fsj", type=float, default=0.10, help="static friction FSJ [N·m] (default 0.10)")
    simulate.add_argument("--airspeed", type=float, default=153.01, help="true airspeed [m/s], 90–215")
    simulate.add_argument("--altitude", type=float, default=0.0, help="altitude [m], 0–10000")
    simulate.add_argument("--seed", type=int, default=0, help="seed of the command and the noise")
    simulate.add_argument("--duration", type=float, default=0.5, help="window length [s] (default 0.5)")
    simulate.add_argument("--rate", type=float, default=10_000.0, help="log rate [Hz] (default 10000)")
    simulate.add_argument("--clean", action="store_true", help="no sensor noise")
    simulate.add_argument(
        "--effect", action="append", default=[], metavar="NAME[:KEY=VALUE,...]",
        help="switch on an effect the base model lacks, e.g. cogging:amplitude_nm=0.02 (repeatable)",
    )  # fmt: skip
    simulate.add_argument("--actuator-id", default="synthetic/elevator", help="actuator_id written to the window")
    simulate.add_argument("--truth-out", type=Path, help="also write the true parameters as JSON")
    simulate.add_argument("--json", action="store_true", help="print one JSON document")
    simulate.set_defaults(run=command_simulate, show=print_simulate)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        result = args.run(args)
    except InputError as exc:
        print(f"ema {args.command}: bad input: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:
        print(f"ema {args.command}: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except ServiceError as exc:
        print(f"ema {args.command}: {exc}", file=sys.stderr)
        return EXIT_INTERNAL
    except Exception as exc:
        print(f"ema {args.command}: internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
        return EXIT_INTERNAL
    if args.json:
        print(json.dumps(result))
    else:
        args.show(result)
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
