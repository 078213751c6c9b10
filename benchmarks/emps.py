"""A real EMA at 1 kHz through the whole method: the EMPS benchmark (docs/results.md).

A. Janot, M. Gautier and M. Brunot, "Data Set and Reference Models of EMPS", ONERA and LS2N, 2019: a DC motor
turning a ball screw that moves a load, logged at 1 kHz on the load side under a known position controller.
Its estimation run is ``examples/emps/DATA_EMPS.mat``; its validation run is not bundled (``--held-out``).

On the estimation run: ``ema estimate`` as a user runs it (a subprocess, timed end to end, and each stage's
seconds), then ``ema calibrate``: what it learned beside the benchmark's own identification, the effect it
named, the model's error before and after (the benchmark's 100·‖y − ŷ‖/‖y‖, inverse and closed loop), and the
published models' errors on the same file. With ``--held-out F.mat --held-out-map M.json``: that run estimated
with the example document and with the completed one, each against the estimation run read with the same document
(both runs' FDJ against 2 std of their difference, the held-out run's closed-loop check and verdict, whether the
network disagrees with physics there), and each model's error on it with its constants fixed: ema's learned ones
and the published ones of each form. Without it, a stand-in is read the same way: the estimation run with pulses
added to its command and felt by the load (``pulsed_copy``), which shows how the three checks behave on a log whose
command is not only its controller's, not what the held-out run reads; then stand-ins of other excitations
(``SWEEP``: 20 or 80 pulses of 1.5 to 8 V), each read with both documents.

    python -m benchmarks.emps [--held-out F.mat --held-out-map M.json] [--docs]
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from benchmarks.as_user import run_ema
from benchmarks.foreign_accuracy import RESULTS_MD
from ema.calibration.documents import ServoCalibration
from ema.cli.benchmark_docs import typed_command, write_section
from ema.estimate import thread_budget
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import STAGES, Estimate
from ema.estimate.stats import rms
from ema.kinds import CalibrationRequest, calibrate, estimate
from ema.kinds.servo.fold_errors import model_errors_pct
from ema.kinds.servo.inverse import UNITS
from ema.kinds.servo.log_reading import completed, followed_loop, log_loop, prepare_servo
from ema.kinds.servo.stages import physics_of
from ema.model.actuator import ActuatorDocument, ServoActuator, as_kind, read_actuator
from ema.model.logmap import read_logmap, read_mapped
from ema.model.window import ServoWindow, as_window, window_from_dict
from tests.foreign import servo as foreign

ROOT = Path(__file__).resolve().parent.parent
EMPS = ROOT / "examples" / "emps"
CITATION = (
    'A. Janot, M. Gautier and M. Brunot, "Data Set and Reference Models of EMPS", ONERA and LS2N, 2019 (the '
    "nonlinear system identification benchmarks): a Maxon DC motor, a Star ball screw, a load in translation, "
    "logged at 1 kHz on the load side under a PD position controller; the estimation run, `DATA_EMPS.mat`, "
    "read through `examples/emps/`."
)
# The benchmark's own least-squares identification of this run (its report; Script_IDIM_LS*.m)
PUBLISHED = {"mass_kg": 95.1089, "viscous_ns_per_m": 203.5034, "fdj_n": 20.3935, "offset_n": -3.1648}
PUBLISHED_STD = {"mass_kg": 0.1085, "viscous_ns_per_m": 1.1460, "fdj_n": 0.1012, "offset_n": 0.0444}
# Its asymmetric model (Coulomb and viscous per direction, no offset), as the same form ema's offset takes
PUBLISHED_ASYMMETRIC = {
    "mass_kg": 95.1540,
    "viscous_up_ns_per_m": 166.7061,
    "viscous_down_ns_per_m": 240.4236,
    "fdj_n": (20.1440 + 20.6277) / 2,
    "offset_n": (20.1440 - 20.6277) / 2,
}
PUBLISHED_ERROR_PCT = 4.08
NAMES = {"mass_kg": "mass", "viscous_ns_per_m": "viscous", "fdj_n": "FDJ", "offset_n": "offset"}


def read(path: Path, mapping: Path) -> ServoWindow:
    return as_window(window_from_dict(read_mapped(path, read_logmap(mapping))), ServoWindow)


def estimation_run() -> ServoWindow:
    """The benchmark's estimation run, as the bundled log map reads it."""
    return read(EMPS / "DATA_EMPS.mat", EMPS / "log-map.json")


def calibrations(window: ServoWindow, times: int) -> list[ActuatorDocument]:
    """The bundled document, then each document ``ema calibrate`` completes on ``window`` from the one before:
    ``times`` + 1 documents."""
    documents = [read_actuator(EMPS / "actuator.json")]
    for _ in range(times):
        completed = calibrate([window], CalibrationRequest(PipelineConfig(), documents[-1])).completed
        assert completed is not None, "the EMPS log completes its document"
        documents.append(completed)
    return documents


def cli_seconds(path: Path, mapping: Path, actuator: Path) -> tuple[float, dict]:
    """``ema estimate`` as a user types it: its wall time and its answer."""
    return run_ema("estimate", str(path), "--log-map", str(mapping), "--actuator", str(actuator))


def identification_table(learned: dict, base: dict, simulated: dict[str, float]) -> str:
    """The benchmark's constants beside ema's: its symmetric model's, with the effects (the fit's), and those as the
    simulator takes them (``simulated``: what the completed document keeps)."""
    rows = ["| constant | benchmark (LS ± std) | ema, its model | ema, with the effect | as simulated | unit |"]
    rows.append("|---|---:|---:|---:|---:|---|")
    for name, value in PUBLISHED.items():
        short = NAMES[name]
        with_effect = learned.get(short) or {}
        shown = f"{with_effect['value']:.4g} ± {with_effect['std']:.2g}" if with_effect else "(split by direction)"
        kept = f"{simulated[short]:.4g}" if short in simulated else "—"
        rows.append(
            f"| {short} | {value:.4f} ± {PUBLISHED_STD[name]:.4f} | {base[short]['value']:.4f} ± "
            f"{base[short]['std']:.3f} | {shown} | {kept} | {base[short]['unit']} |"
        )
    rows += [
        f"| {e['name']} | — | — | {e['value']:.4g} ± {e['std']:.2g} | {simulated.get(n, e['value']):.4g} "
        f"| {e['unit']} |"
        for n, e in learned.items()
        if n not in NAMES.values()
    ]
    return "\n".join(rows)


def errors_on(window: ServoWindow, document: ServoActuator, completed: ServoActuator) -> dict[str, dict[str, float]]:
    """Each model's error on ``window``, its constants fixed: ema's learned, the published symmetric and asymmetric."""
    prepared = [prepare_servo(window, document)]
    servo = completed.servo
    assert servo is not None and completed.nominal is not None
    ours = {
        "mass_kg": servo.mass_kg,
        "fdj_n": completed.nominal.fdj_n,
        "offset_n": servo.force_offset_n,
        "viscous_up_ns_per_m": servo.viscous_ns_per_m,
        "viscous_down_ns_per_m": servo.viscous_down_ns_per_m,
        **servo.effect_constants,
    }
    effects = {**servo.effects, **({"viscous_down": 1.0} if servo.viscous_down_ns_per_m is not None else {})}
    return {
        "ema, learned": model_errors_pct(prepared, {k: v for k, v in ours.items() if v is not None}, effects),
        "published, symmetric": model_errors_pct(prepared, PUBLISHED, {}),
        "published, asymmetric": model_errors_pct(prepared, PUBLISHED_ASYMMETRIC, {"viscous_down": 1.0}),
    }


def calibration_lines(report: ServoCalibration, base: dict[str, dict]) -> list[str]:
    """What ``ema calibrate`` learned of the log and named in it, and the model's errors before and after."""
    learned = {e.name: e.model_dump() for e in report.learned}
    before, after = report.model_error_pct_before, report.model_error_pct_after
    assert before is not None and after is not None, "a servo's calibration reports its model error"
    return [
        identification_table(learned, base, {e.name: e.value for e in report.as_simulated}),
        "",
        "*As simulated*: each constant moved by what Eq. 5.1 reads of the log simulated in closed loop at it (the "
        "solution reads a simulated effect through the decimation and filters, which shrink it): the constants the "
        "completed document keeps, at which an estimate of this log reads its nominal.",
        "",
        f"`ema calibrate` named {', then '.join(report.selected_effects) or 'nothing'}: "
        + "; ".join(s.reason for s in report.selection_steps if s.selected)
        + ".",
        "",
        "| model | inverse (IDIM) error | closed-loop force error |",
        "|---|---:|---:|",
        f"| the benchmark's symmetric model, its report | {PUBLISHED_ERROR_PCT:.2f} % | 5.85 % (its Simulink) |",
        f"| ema, before (M, C, FDJ, offset) | {before['drive_force_n']:.2f} % | "
        f"{before['drive_force_n_closed_loop']:.2f} % |",
        f"| ema, after ({', '.join(report.selected_effects)}) | {after['drive_force_n']:.2f} % "
        f"| {after['drive_force_n_closed_loop']:.2f} % |",
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--held-out", type=Path, help="the benchmark's validation run (a .mat)")
    parser.add_argument("--held-out-map", type=Path, help="its log map")
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure(None)
    mapping, document_path = EMPS / "log-map.json", EMPS / "actuator.json"
    window, document = estimation_run(), as_kind(read_actuator(document_path), ServoActuator)
    wall, answer = cli_seconds(EMPS / "DATA_EMPS.mat", mapping, document_path)
    stages = answer["timings_s"]
    calibrated = calibrate([window], CalibrationRequest(PipelineConfig(), document))
    report = calibrated.report
    assert isinstance(report, ServoCalibration), "a servo's calibration answers a servo's report"
    base = _base_model(window, document)
    lines = [
        CITATION,
        "",
        f"`ema estimate` on the {window.duration_s:.1f} s log, as typed (one process, 2 cores): {wall:.1f} s wall; "
        "stages " + ", ".join(f"{stage} {stages[stage]:.2f} s" for stage in STAGES) + ".",
        f"It reads FDJ {answer['estimates']['FDJ']['value']:.3f} ± {answer['estimates']['FDJ']['std']:.3f} N; the "
        f"closed loop at its answer follows the logged force within "
        f"{answer['check']['output_error_pct']['drive_force_n']:.2f} % (the benchmark's Simulink model at its "
        "constants: 5.85 %).",
        "",
        *calibration_lines(report, base),
    ]
    lines += ["", reading(answer, base), ""]
    if calibrated.completed is not None:
        again = estimate(window, actuator=calibrated.completed).model_dump(mode="json")
        lines += [
            "What the network reads, beside physics:",
            "",
            network_line("with the bundled document", answer),
            network_line("with the calibrated document", again),
            "",
        ]
    lines += [recorded_gain_line(window, document, answer)]
    if calibrated.completed is not None:
        completed = as_kind(calibrated.completed, ServoActuator)
        runs = {"bundled": (document, answer), "calibrated": (completed, again)}
        if args.held_out is not None:
            held_out = read(args.held_out, args.held_out_map or mapping)
            lines += ["", f"The held-out run ({args.held_out.name}):", "", *held_out_lines(held_out, runs)]
        else:
            stand_in = pulsed_copy(window, PULSES)
            lines += [
                "",
                PULSED_SAID,
                "",
                *held_out_lines(stand_in, runs, name="stand-in"),
                "",
                *sweep_lines(window, runs),
            ]
    body = "\n".join(lines)
    print(body)
    if args.docs:
        write_section("A real EMA at 1 kHz: the EMPS benchmark", typed_command(), body, RESULTS_MD)


WRONG_KP = (0.5, 30.0)  # the log's recorded kp times these: a log whose recorded gain is not its loop's


def recorded_gain_line(window: ServoWindow, document: ServoActuator, answer: dict) -> str:
    """The log read with its recorded kp altered: the gains its command follows (``log_loop``), and FDJ read."""
    kp = window.constants["position_gain_per_s"]
    read = []
    for factor in WRONG_KP:
        wrong = replace(window, constants={**window.constants, "position_gain_per_s": factor * kp})
        fdj = estimate(wrong, actuator=document).estimates.FDJ
        read.append(f"kp x{factor:g}: FDJ {fdj.value:.3f} ± {fdj.std:.3f} N")
    gains = log_loop(completed(document, window), window)
    assert gains is not None, "the EMPS log's command follows a position loop"
    return (
        f"A log whose recorded gain is not its loop's: the same log with its kp ({kp:g} 1/s) recorded "
        f"{' or '.join(f'{f:g}' for f in WRONG_KP)} times over is simulated with the gains its command follows, "
        f"read by least squares (kp {gains.position_gain_per_s:.2f} 1/s, kv {gains.speed_gain_per_mps:.2f}, "
        f"{100 * gains.off_share:.2f} % RMS off the logged command), and reads {'; '.join(read)} (as logged: "
        f"{answer['estimates']['FDJ']['value']:.3f} N), with the note `controller_mismatch` naming both gains."
    )


def reading(answer: dict, base: dict[str, dict]) -> str:
    """What the tables say, in words, from this run's figures."""
    used = {name: m["weight_network"] for name, m in answer["methods"].items()}
    notes = sorted({n["code"] for n in answer["notes"]})
    return (
        "Reading it. ema's physics stage is the benchmark's IDIM-LS, leaving out two kinds of rows: the filters' "
        "transients at the log's end as well as its start, and the samples where the load rests (there static "
        f"friction holds it and sgn(q̇) reads the encoder's dither); that moves FDJ to {base['FDJ']['value']:.2f} N "
        f"and C to {base['viscous']['value']:.1f} N·s/m. Its std of FDJ, {base['FDJ']['std']:.3f} N, is Newey–West's: "
        f"{base['FDJ']['std'] / PUBLISHED_STD['fdj_n']:.1f}x the least-squares std, which takes the residual for "
        "white where a reversal's misfit spans many samples. The log holds more than the model (its Eq. 5.1 "
        f"residual {answer['check']['equation_error_ratio']:.2f}x what the model's noise leaves), so the network "
        "learns from the window's own closed-loop runs each carrying the window's misfit at a random shift and "
        f"sign; it carries a weight of {max(used.values()):.2f} at most in the answer ({', '.join(notes)}): its "
        "held-out errors, misfit included, are no smaller than the physics solution's, which answers, corrected "
        "by its bias on those simulations." + _form_said(answer)
    )


def _form_said(answer: dict) -> str:
    """The model-form note's words, where the answer's stds were widened by the effects the log holds."""
    form = next((n["text"] for n in answer["notes"] if n["code"] == "model_form"), None)
    return "" if form is None else f" Its std is wider than the solution's: {form} (`model_form`)."


def network_line(name: str, answer: dict) -> str:
    """What the network reads beside physics on one run, per constant, from this run's figures."""
    methods = answer["methods"]
    read = [f"{key} {m['physics']:.4g} / {m['network']:.4g}" for key, m in methods.items() if m["network"] is not None]
    disagree = [k for k, m in methods.items() if (m.get("network_note") or {}).get("code") == "network_disagrees"]
    said = f"disagrees on {', '.join(disagree)}" if disagree else "no constant beyond the network's own spread"
    return f"- {name}: physics / network {'; '.join(read)}: {said}."


def _base_model(window: ServoWindow, document: ServoActuator) -> dict[str, dict]:
    """The symmetric model's constants as ema's physics stage reads them (Newey–West stds)."""
    solution = physics_of(prepare_servo(window, document))
    return {NAMES[n]: {"value": solution.values[n], "std": solution.stds[n], "unit": UNITS[n]} for n in NAMES}


PULSES = (7, 40, 3.0)  # the stand-in's excitation (``foreign.excitation``): its seed, pulses and their height [V]
SWEEP = tuple((seed, count, height) for seed in (1, 2) for count in (20, 80) for height in (1.5, 5.0, 8.0))
PULSED_SAID = (
    "The held-out run is not here. A stand-in, read as it would be: the estimation run with an excitation added to "
    f"its command ({PULSES[1]} pulses of {PULSES[2]:g} V for 10-40 ms and a slow sine, seed {PULSES[0]}) "
    "and felt by the load: its position and force moved by what the independent closed-form servo "
    "(`tests/foreign/servo.py`, at the benchmark's asymmetric constants and the log's gains) does under that "
    "excitation. Its misfit is the real log's; the pulses' response is a simulator's, so this shows how the checks "
    "behave on a log whose command is not only its controller's, not what the held-out run reads."
)


def pulsed_copy(window: ServoWindow, pulses: tuple[int, int, float]) -> ServoWindow:
    """The estimation run with an excitation (``PULSES``' form) added to its command and felt: the foreign servo's
    response to it (its run with the excitation less its run without, over the log's set point) added to the logged
    position and force, the force saturated where the sum passes the drive's limit."""
    s, c = window.signals, window.constants
    gains = (c["position_gain_per_s"], c["speed_gain_per_mps"], c["drive_gain_n_per_unit"])
    load = foreign.Load(
        mass_kg=PUBLISHED_ASYMMETRIC["mass_kg"],
        fdj_n=PUBLISHED_ASYMMETRIC["fdj_n"],
        viscous_up_ns_per_m=PUBLISHED_ASYMMETRIC["viscous_up_ns_per_m"],
        viscous_down_ns_per_m=PUBLISHED_ASYMMETRIC["viscous_down_ns_per_m"],
        offset_n=PUBLISHED_ASYMMETRIC["offset_n"],
    )
    seed, count, height_v = pulses
    excitation = foreign.excitation(seed, window.n_samples, height_v, count)
    plain = foreign.simulate(s["set_point_m"], load, gains=gains)
    pulsed = foreign.simulate(s["set_point_m"], load, added_v=excitation, gains=gains)
    moved = {"position_m": pulsed[0] - plain[0], "drive_force_n": pulsed[1] - plain[1]}
    signals = {name: values + moved.get(name, 0.0) for name, values in s.items()}
    top = foreign.LIMIT * gains[2]  # the drive saturates the sum as it saturated each run
    signals["drive_force_n"] = np.clip(signals["drive_force_n"], -top, top)
    return replace(window, signals=signals, window_id=f"{window.window_id} pulsed")


@dataclass(frozen=True)
class Checked:
    """A second run read with a document, against the estimation run's answer with it: the lab's three checks."""

    answer: Estimate  # the second run's: its closed-loop check
    gap_n: float  # |FDJ of one run − the other's|
    std_n: float  # the std of that difference
    disagrees: list[str]  # the constants the network disagrees with physics on


def checked(window: ServoWindow, document: ServoActuator, first: dict) -> Checked:
    """``window`` estimated with ``document``, against ``first`` (the estimation run's answer with it, as JSON)."""
    answer = estimate(window, actuator=document)
    fdj, before = answer.estimates.FDJ, first["estimates"]["FDJ"]
    return Checked(
        answer,
        abs(before["value"] - fdj.value),
        float(np.hypot(before["std"], fdj.std or 0.0)),
        [n for n, m in answer.methods.items() if m.network_note and m.network_note.code == "network_disagrees"],
    )


def sweep_lines(window: ServoWindow, runs: dict[str, tuple[ServoActuator, dict]]) -> list[str]:
    """Stand-ins of other excitations (``SWEEP``), each read with both documents: the lab's three checks on each."""
    lines = [
        "Stand-ins of other excitations, each read with the bundled / the calibrated document: the closed loop's force "
        "error, FDJ apart from the estimation run's in stds of the difference, and any `network_disagrees`:",
        "",
        "| seed | pulses | height [V] | added command, share of the command's RMS | force error | FDJ apart | "
        "network_disagrees |",
        "|---:|---:|---:|---:|---|---|---|",
    ]
    for pulses in SWEEP:
        copy = pulsed_copy(window, pulses)
        errors, apart, disagree = [], [], []
        for document, first in runs.values():
            read_out = checked(copy, document, first)
            errors.append(f"{read_out.answer.check.output_error_pct['drive_force_n']:.2f} %")
            apart.append(f"{read_out.gap_n / read_out.std_n:.2f}")
            disagree += read_out.disagrees
        lines.append(
            f"| {pulses[0]} | {pulses[1]} | {pulses[2]:g} | {_added_share(copy, runs['bundled'][0])} | "
            f"{' / '.join(errors)} | {' / '.join(apart)} | {', '.join(sorted(set(disagree))) or 'none'} |"
        )
    return lines


def _added_share(window: ServoWindow, document: ServoActuator) -> str:
    """The command added to the loop's that the log shows, as a share of the logged command's RMS."""
    servo = completed(document, window)
    added = followed_loop(servo, window).added
    if added is None:
        return "not read"
    logged = window.signals["drive_force_n"] / (servo.drive_gain_n_per_unit or 1.0)
    return f"{100 * rms(added.values) / rms(logged):.0f} %"


def held_out_lines(
    window: ServoWindow, runs: dict[str, tuple[ServoActuator, dict]], name: str = "held-out run"
) -> list[str]:
    """The held-out run read with each document (``runs``: the document and the estimation run's answer with it):
    both runs' FDJ against 2 std of their difference, the held-out run's closed-loop check and whether the network
    disagrees with physics there; then each model's error on it, its constants fixed."""
    lines = [
        f"| document | estimation run FDJ [N] | {name} FDJ [N] | apart, against 2 std of the difference | "
        f"{name}'s closed loop: force error, verdict | network_disagrees |",
        "|---|---:|---:|---:|---|---|",
    ]
    for label, (document, first) in runs.items():
        read_out = checked(window, document, first)
        second, check = read_out.answer.estimates.FDJ, read_out.answer.check
        gap, allowed, disagrees = read_out.gap_n, 2 * read_out.std_n, read_out.disagrees
        lines.append(
            f"| {label} | {first['estimates']['FDJ']['value']:.3f} ± {first['estimates']['FDJ']['std']:.3f} | "
            f"{second.value:.3f} ± {second.std:.3f} | {gap:.3f} N, {'within' if gap <= allowed else 'beyond'} "
            f"{allowed:.3f} N | {check.output_error_pct['drive_force_n']:.2f} %, "
            f"{'reproduced' if check.reproduced else 'not reproduced'} | {', '.join(disagrees) or 'none'} |"
        )
    lines += ["", "| model, constants fixed | inverse error | closed-loop force error |", "|---|---:|---:|"]
    document, completed = runs["bundled"][0], runs["calibrated"][0]
    for name, errors in errors_on(window, document, completed).items():
        lines.append(f"| {name} | {errors['drive_force_n']:.2f} % | {errors['drive_force_n_closed_loop']:.2f} % |")
    return lines


if __name__ == "__main__":
    main()
