"""The calibration loop on windows with an undeclared effect (and clean ones): docs/calibration.md.

Each case: two 0.5 s in-flight windows (different §5.6 commands) with realistic sensor noise,
simulated with the effect switched on; the loop is not told about it. Run:
python benchmarks/calibration_study.py
"""

from __future__ import annotations

import time
from pathlib import Path

from training.calibration.calibrate import Calibrator
from training.calibration.figure import residual_figure

from clients.report import machine
from sim.effects import EffectSet
from sim.params import HealthParams
from sim.synthetic import synthetic_window

DOCS = Path(__file__).resolve().parent.parent / "docs"
TRUTH = {"FDJ": 0.053, "eta_O": 0.80}
CASES = [
    ("clean", {}),
    ("clean (other commands)", {}),
    ("hinge_moment_bias", {"hinge_moment_bias": {"bias_nm": 15.0}}),
    ("viscous", {"viscous": {"coefficient_nms": 5e-5}}),
    ("backlash", {"backlash": {"extra_rad": 0.004}}),
    ("position_friction", {"position_friction": {"amplitude_nm": 0.05}}),
    ("torque_constant", {"torque_constant": {"gain": 0.92}}),
    ("current_sensor_gain", {"current_sensor_gain": {"gain": 1.08}}),
    ("stribeck", {"stribeck": {"amplitude_nm": 0.03, "speed_radps": 200.0}}),
    ("cogging", {"cogging": {"amplitude_nm": 0.02, "periods_per_rev": 6.0}}),
    ("hinge_moment_bias + viscous", {"hinge_moment_bias": {"bias_nm": 12.0}, "viscous": {"coefficient_nms": 5e-5}}),
]


def fmt(effects: dict | None) -> str:
    """``{effect: {parameter: value}}`` as text."""
    if not effects:
        return "—"
    return "; ".join(", ".join(f"{k} {v:.3g}" for k, v in p.items()) for p in effects.values())


def main() -> None:
    health = HealthParams.single(0.1, TRUTH["FDJ"], TRUTH["eta_O"])
    rows = []
    for index, (name, effects) in enumerate(CASES):
        seeds = (31, 32) if "other" in name else (11, 12)
        windows = [synthetic_window(health, seed=s, effects=EffectSet(effects)) for s in seeds]
        started = time.perf_counter()
        calibrator = Calibrator().fit(windows, TRUTH)
        report = calibrator.report_
        figure = DOCS / "figures" / f"calibration_{index:02d}.png"
        variable = (report["unexplained_structure"] or {}).get("variable")
        residual_figure(
            calibrator.residuals_before_, calibrator.residuals_after_, report["selected_effect"], variable, figure
        )
        before, after = report["error_pct_before"], report["error_pct_after"]
        rms_b, rms_a = report["residual_rms_before"], report["residual_rms_after"]
        note = "; then ".join(step["reason"] for step in report["selection_steps"])
        if report["selection"].get("indistinguishable_from"):
            note += f"; same ΔT_R trace as {', '.join(report['selection']['indistinguishable_from'])}"
        if report["unexplained_structure"]:
            note += f"; {report['unexplained_structure']['description']}"
        rows.append(
            f"| [{name}](figures/calibration_{index:02d}.png) | {fmt(effects)} "
            f"| {' + '.join(report['selected_effects']) or '—'} | {fmt(report['effects'])} "
            f"| {rms_b['residual_torque']:.4f} → {rms_a['residual_torque']:.4f} "
            f"| {before['FDJ']:.2f} → {after['FDJ']:.2f} | {before['eta_O']:.2f} → {after['eta_O']:.2f} | {note} |"
        )
        print(f"{name}: {report['selected_effect']} ({time.perf_counter() - started:.0f} s)", flush=True)
    lines = [
        "# Calibration: the undeclared effect, found and added",
        "",
        f"- machine: {machine()}",
        f"- date: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}",
        "- command: `python benchmarks/calibration_study.py`",
        "",
        "Two 0.5 s in-flight windows per case (FDJ 0.053 N·m, η_O 0.80; realistic sensor noise), simulated",
        "with the effect on; the loop (`training/calibration/`) is not told about it. It estimates with the",
        "base model, simulates the windows with those estimates, and scores every candidate effect on the",
        "residual torque, dead-band and hinge-moment channels, averaged over blocks as long as the",
        "residual's correlation time (the effective sample size). Forward selection (up to two effects):",
        "an effect is named only with a BIC gain > 10, a held-out gain, a bootstrap stability ≥ 70 % and",
        "no rival within 10; the effects are then added to the simulator, their parameters refined twice",
        "on what is left, and the windows re-estimated.",
        "Errors are |estimate − truth| / truth in %; the residual is the RMS of ΔT_R [N·m].",
        "",
        "| case | true effect | selected | fitted parameters | residual RMS | FDJ error % | η_O error % | why |",
        "|---|---|---|---|---:|---:|---:|---|",
        *rows,
        "",
        "## Limits, as measured",
        "",
        "- **torque_constant / current_sensor_gain** leave the same trace in the residual torque (∝ k_T·I).",
        "  The loop simulates both and keeps the one whose motor speed matches: a torque constant also",
        "  changes the back-EMF, hence the top speed; a current-sensor gain does not.",
        "- **stribeck** at the speeds these windows spend time at looks like viscous friction: when the BIC",
        "  cannot separate them by 10, no name is forced and the residual is described (it follows speed).",
        "  The FDJ error it causes then stays; a window with slow motion would separate them.",
        "- **cogging** ripples at p·ω/2π ≈ 600 Hz at a flight window's motor speeds; the 2 ms reconstruction",
        "  kernel attenuates it, so the first fit finds its order and phase but too small an amplitude; the",
        "  refinement rounds, which compare like with like through the same kernel, restore it. It barely",
        "  biases FDJ or η_O either way.",
    ]
    (DOCS / "calibration.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
