"""The error of a servo's model, as the identification benchmarks state it: the inverse model's reconstruction of
the decimated force, and the closed loop's of the logged force, each window simulated at the constants (those
the simulator has; the others left out). ``ema calibrate`` reports both before and after, and for the document
as it stands."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ema.kinds.servo.log_reading import ServoPrepared, document_effects
from ema.kinds.servo.loop_dataset import lane_parameters
from ema.kinds.servo.stacked_solve import problem
from ema.model.actuator import ServoActuator
from ema.model.checks import InputError


def closed_loop_error_pct(
    prepared: Sequence[ServoPrepared], values: dict[str, float], effects: dict[str, float] | None = None
) -> float:
    """100·‖F − F̂‖/‖F‖ over every window, each simulated in closed loop at ``values`` with ``effects`` (those the
    simulator has; the others left out)."""
    errors, norms = 0.0, 0.0
    for p in prepared:
        s, kept = p.window.signals, p.motion.samples
        run = p.closed_loop(lane_parameters(values, effects)[None, :])
        errors += float(np.sum((s["drive_force_n"][kept] - run.drive_force_n[0, kept]) ** 2))
        norms += float(np.sum(s["drive_force_n"][kept] ** 2))
    return float(100.0 * np.sqrt(errors / norms))


def model_errors_pct(
    prepared: Sequence[ServoPrepared], values: dict[str, float], effects: dict[str, float]
) -> dict[str, float]:
    """The error of a model whose constants are fixed (``values`` with ``effects``), as the benchmarks state it:
    the inverse model's reconstruction of the decimated force, and the closed loop's of the logged force."""
    p = problem(prepared, effects)
    names = [name for name in p.x if name in values]
    missing = set(p.x) - set(names)
    if missing:
        raise InputError("values", f"the model with {', '.join(effects) or 'no effect'} needs {', '.join(missing)}")
    residual = p.y - p.design(names) @ np.array([values[name] for name in names])
    return {
        "drive_force_n": float(100.0 * np.linalg.norm(residual) / np.linalg.norm(p.y)),
        "drive_force_n_closed_loop": closed_loop_error_pct(prepared, values, effects),
    }


PHASED = {"turn_ripple": ("turn_ripple_sin_n", "turn_ripple_cos_n", "turn_ripple_amplitude_n")}
# an effect tied to an angle no log carries (the motor's, against the load's zero, which moves from run to run):
# the document keeps its size, a window reads its phase (the columns of its sine and cosine, and the size's name)


def amplitudes(constants: dict[str, float]) -> dict[str, float]:
    """An adopted effect's constants as a document keeps them: a phased effect's size alone (``PHASED``)."""
    kept = dict(constants)
    for sine, cosine, size in PHASED.values():
        if sine in kept and cosine in kept:
            kept[size] = float(np.hypot(kept.pop(sine), kept.pop(cosine)))
    return kept


def phased(p: ServoPrepared, values: dict[str, float], effects: dict[str, float]) -> dict[str, float]:
    """``values`` with each phased effect's sine and cosine for window ``p``: the document's size, at the phase the
    window's Eq. 5.1 residual without it reads (its projection on the two columns)."""
    out = dict(values)
    for effect, (sine, cosine, size) in PHASED.items():
        if effect not in effects or size not in values:
            continue
        one = problem([p], effects)
        others = [name for name in one.x if name not in (sine, cosine)]
        residual = one.y - one.design(others) @ np.array([values[name] for name in others])
        (a, b), *_ = np.linalg.lstsq(one.design([sine, cosine]), residual, rcond=None)
        scale = values[size] / max(float(np.hypot(a, b)), 1e-300)
        out |= {sine: float(a * scale), cosine: float(b * scale)}
        out.pop(size)
    return out


def document_check(prepared: Sequence[ServoPrepared], actuator: ServoActuator) -> dict[str, float] | None:
    """The error of the document's own model as it stands (its load's constants fixed, a phased effect's phase read
    per window: ``phased``), inverse and closed loop; None where the document does not hold them, or holds an
    effect whose constants it does not keep."""
    servo, nominal = prepared[0].servo, actuator.nominal
    if servo.mass_kg is None or servo.viscous_ns_per_m is None or nominal is None or nominal.fdj_n is None:
        return None
    values = {"mass_kg": servo.mass_kg, "fdj_n": nominal.fdj_n, "offset_n": servo.force_offset_n or 0.0}
    if servo.viscous_down_ns_per_m is None:
        values["viscous_ns_per_m"] = servo.viscous_ns_per_m
    else:
        values |= {"viscous_up_ns_per_m": servo.viscous_ns_per_m, "viscous_down_ns_per_m": servo.viscous_down_ns_per_m}
    values |= amplitudes(servo.effect_constants)
    effects = document_effects(servo)
    try:
        if not any(size in values for _, _, size in PHASED.values()):
            return model_errors_pct(prepared, values, effects)
        return _combined(prepared, [model_errors_pct([p], phased(p, values, effects), effects) for p in prepared])
    except InputError:
        return None


def _combined(prepared: Sequence[ServoPrepared], each: list[dict[str, float]]) -> dict[str, float]:
    """Per-window errors in % as one over all the windows: each weighed by its signal's norm (inverse: the decimated
    force's; closed loop: the logged force's)."""
    norms = {
        "drive_force_n": [float(np.linalg.norm(problem([p], {}).y)) for p in prepared],
        "drive_force_n_closed_loop": [
            float(np.linalg.norm(p.window.signals["drive_force_n"][p.motion.samples])) for p in prepared
        ],
    }
    return {
        name: float(
            np.sqrt(
                sum((e[name] * n) ** 2 for e, n in zip(each, norms[name], strict=True))
                / sum(n * n for n in norms[name])
            )
        )
        for name in norms
    }
