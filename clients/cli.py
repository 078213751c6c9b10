"""The ``ema`` command line. Exit status: 0 success, 2 bad input (naming the field or file), 1 internal error."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sim.aircraft import FlightCondition
from sim.checks import InputError
from sim.effects import EffectSet
from sim.noise import NO_NOISE, SensorNoise
from sim.params import HealthParams, eta_a_from_eta_o
from sim.residual import residual_torque_nm
from sim.synthetic import synthetic_window
from sim.window import Window, write_window

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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="ema", description="Onboard health monitor for an elevator EMA.")
    commands = parser.add_subparsers(dest="command", required=True)
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
