"""Which estimator to believe, and how much: held-out simulations first, then the window itself.

Both estimators run on held-out simulations of the window's own scenario (its command, load,
first state and noise; health drawn in the same box). The physics solution's mean error there is its
bias on this scenario (the 2 ms reconstruction blurs the reversals, the motor saturates); it is
subtracted as far as those K simulations resolve it (James–Stein shrinkage). The errors then give
each parameter's MSE-optimal blend (``ema.estimate.assess.blend``) and an in-distribution std. The network
joins the answer only where the blend cuts the physics solution's error there by ``1 − NETWORK_MARGIN``
or more: a weight chosen on a few dozen simulations overstates what the network adds on data the
simulator did not draw, and so does the full bias. Those simulations cannot
see a mismatch between the model and the measured window, so two checks on the window follow:

- **Consistency.** The network reads the window's residual torque, the physics solution reads it
  too, through Eq. 5.1. On held-out simulations their difference has a known spread; on the
  window it must fall inside it (|z| ≤ ``MAX_DISAGREEMENT_Z``), and the network's answer must
  lie in the box it was trained on. Otherwise the network is extrapolating from a trace the
  simulator does not produce, and only the physics solution is kept.
- **Equation error.** The window's Eq. 5.1 residual RMS over the simulations' (the same noise,
  no missing physics): ≈ 1 when the model explains the window. Above, the stds are scaled by it
  (the Birge ratio): structure the model lacks widens the uncertainty instead of hiding in it.
  Whether the model *lacks* something is a test: the simulations' own ratios scatter around 1,
  log-normally with a spread s read from them, and the window is one more draw under the null. The
  note ``model_misfit`` is said only beyond exp(t₀.₉₉,ₖ₋₁ · s · √(1 + 1/K)) (``misfit_limit``): a
  clean window draws it ``MISFIT_FALSE_ALARM`` of the time.

The std is never below the physics estimator's own std on the window, widened as it is read: a block-jackknife
std sees only noise and is widened by the ratio; a std read from the window's own residual (Newey–West) carries the
misfit already and stands unscaled (``Candidates.physics_std_source``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from ema.estimate.assess.blend import best_blend
from ema.estimate.documents import TARGETS, MethodReport, Note
from ema.estimate.stats import rms

MAX_DISAGREEMENT_Z = 3.0
MIN_CHECKS = 4  # held-out simulations the scoring needs (those that could not slide are left out)
BOX_TOLERANCE = 0.1  # the network may answer this far outside its box (in box units) before it extrapolates
NETWORK_MARGIN = 0.8  # the network joins only if the blend's RMS error on the checks is below this share of physics'
STUDENT_95 = {8: 2.31, 16: 2.12, 32: 2.04}  # t quantiles: a std read from K simulations is itself uncertain
MISFIT_FALSE_ALARM = 0.01  # the share of clean windows the model_misfit note may be said of
Z_99 = 2.3263  # the normal's 0.99 quantile, for MISFIT_FALSE_ALARM


@dataclass(frozen=True)
class Candidates:
    """Each estimator's answer for the window and for the K held-out simulations, per target."""

    physics: dict[str, float]
    physics_std: dict[str, float]
    network: dict[str, float] | None
    network_unit: np.ndarray | None  # (2,) the window's network answer in box units
    check_truth: dict[str, np.ndarray]
    check_physics: dict[str, np.ndarray]
    check_network: dict[str, np.ndarray] | None
    targets: tuple[str, ...] = TARGETS  # what both estimate, in the network's output order
    # Where the physics estimator's std comes from: "jackknife", the spread of the window's segments, which sees
    # only noise (the equation-error ratio widens it as it widens the held-out errors); "residual", the window's
    # own residual, its size and its correlation (Newey–West), which carries a misfit already (only the held-out
    # errors are widened)
    physics_std_source: Literal["jackknife", "residual"] = "jackknife"


@dataclass(frozen=True)
class Assessed:
    values: dict[str, float]
    stds: dict[str, float]
    methods: dict[str, MethodReport]
    inflation: float
    notes: list[Note]


def _t_factor(k: int) -> float:
    """The 95 % Student quantile for K check windows, relative to the normal's 1.96."""
    nearest = min(STUDENT_95, key=lambda n: abs(n - k))
    return max(1.0, STUDENT_95[nearest] / 1.96) if k < 60 else 1.0


def student_99(dof: int) -> float:
    """Student's t 0.99 quantile for ``dof`` degrees of freedom (Cornish–Fisher to 1/dof³: within 1 % from 4)."""
    z, v = Z_99, max(dof, 1)
    third = (3 * z**7 + 19 * z**5 + 17 * z**3 - 15 * z) / (384 * v**3)
    return z + (z**3 + z) / (4 * v) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * v**2) + third


def misfit_limit(check_rms: np.ndarray) -> float:
    """The equation-error ratio a clean window exceeds ``MISFIT_FALSE_ALARM`` of the time: the held-out simulations'
    RMS errors, over their median, are log-normal with a spread s; a new draw passes exp(t·s·√(1 + 1/K)) with
    that probability (inf where too few simulations to read s)."""
    finite = check_rms[np.isfinite(check_rms) & (check_rms > 0)]
    k = len(finite)
    if k < MIN_CHECKS:
        return float("inf")
    spread = float(np.std(np.log(finite / np.median(finite)), ddof=1))
    return float(np.exp(student_99(k - 1) * spread * np.sqrt(1 + 1 / k)))


def bias_corrected(physics: np.ndarray, truth: np.ndarray) -> tuple[float, np.ndarray]:
    """The physics solution's bias on this scenario as far as the held-out simulations resolve it, and each
    simulation's estimate corrected alike by the mean of the *others'* errors (leave-one-out: honest errors).

    K errors of mean b and standard error s give b·max(0, 1 − s²/b²) (positive-part James–Stein): a
    bias measured at many s is kept whole, one that the noise of K draws alone would show is dropped.
    """
    errors = physics - truth
    k = len(errors)
    if k < MIN_CHECKS:
        return 0.0, physics  # too few to measure a bias with
    bias = float(errors.mean())
    shrink = max(0.0, 1.0 - float(errors.var(ddof=1)) / k / bias**2) if bias else 0.0
    left_out = (errors.sum() - errors) / (k - 1)
    return shrink * bias, physics - shrink * left_out


def network_note(c: Candidates, name: str) -> Note | None:
    """Why the network's answer for ``name`` cannot be used on this window, or None."""
    if c.network is None or c.check_network is None or c.network_unit is None:
        return Note(code="network_absent", parameter=name, text="no network")
    if len(c.check_truth[name]) < MIN_CHECKS:
        text = "too few held-out simulations could be scored to trust the network with"
        return Note(code="network_too_few_checks", parameter=name, text=text)
    index = c.targets.index(name)
    if not -BOX_TOLERANCE <= c.network_unit[index] <= 1 + BOX_TOLERANCE:
        text = f"the network answered {c.network_unit[index]:.2f} box units: outside the box it was trained in"
        return Note(code="network_out_of_box", parameter=name, text=text)
    spread = c.check_network[name] - c.check_physics[name]
    centre, scale = float(np.mean(spread)), max(float(np.std(spread)), 1e-12)
    z = (c.network[name] - c.physics[name] - centre) / scale
    if abs(z) > MAX_DISAGREEMENT_Z:
        text = (
            f"network and physics disagree by {z:.1f} times their spread on simulations: the network reads "
            "a trace the simulator does not produce"
        )
        return Note(code="network_disagrees", parameter=name, text=text)
    return None


def _assess_parameter(c: Candidates, name: str, inflation: float) -> tuple[float, float, MethodReport, Note | None]:
    """(value, std, report, note for the answer) of one parameter."""
    truth = c.check_truth[name]
    bias, phys = bias_corrected(c.check_physics[name], truth)
    physics, rms_physics = c.physics[name] - bias, rms(phys - truth)
    note = network_note(c, name)
    answer_note = None
    if note is not None and c.network is not None:
        answer_note = Note(code="physics_only", parameter=name, text=f"{name}: physics solution only; {note.text}")
    weight, rms_used, rms_net, value = 0.0, rms_physics, None, physics
    if note is None and c.network is not None and c.check_network is not None:
        blend = best_blend(truth, c.check_network[name], phys)
        rms_net = blend.rms_error_network
        if blend.rms_error <= NETWORK_MARGIN * rms_physics:
            weight, rms_used, value = blend.weight_network, blend.rms_error, blend.apply(c.network[name], physics)
        else:  # routine, so the method report says it and the answer does not
            note = Note(
                code="network_not_better",
                parameter=name,
                text=(
                    f"the network would cut the physics solution's error on held-out simulations by "
                    f"{100 * (1 - blend.rms_error / max(rms_physics, 1e-300)):.0f} %, under the "
                    f"{100 * (1 - NETWORK_MARGIN):.0f} % it must"
                ),
            )
    held_out = _t_factor(len(truth)) * rms_used
    if c.physics_std_source == "residual":
        std = max(inflation * held_out, c.physics_std[name])
    else:
        std = inflation * max(held_out, c.physics_std[name])
    report = MethodReport(
        physics=c.physics[name],
        physics_bias=bias,
        physics_std=c.physics_std[name],
        network=None if c.network is None else c.network[name],
        weight_network=weight,
        rms_error_physics=rms_physics,
        rms_error_network=rms_net,
        rms_error_blend=rms_used,
        network_note=note,
    )
    return value, std, report, answer_note


def assess(c: Candidates, equation_error_ratio: float, limit: float) -> Assessed:
    """Per target, the bias-corrected physics solution, blended with the network where it earns it; the stds
    widened by the equation-error ratio and never below the window's jackknife std; a misfit said only past
    ``limit`` (``misfit_limit``)."""
    inflation = max(1.0, equation_error_ratio)
    values, stds, methods, notes = {}, {}, {}, list[Note]()
    for name in c.targets:
        values[name], stds[name], methods[name], note = _assess_parameter(c, name, inflation)
        if note is not None:
            notes.append(note)
    if equation_error_ratio > limit:
        widened = (
            "stds read from that residual, its size and its correlation, so they carry it; the held-out errors "
            "widened by that factor"
            if c.physics_std_source == "residual"
            else "stds widened by that factor"
        )
        notes.append(
            Note(
                code="model_misfit",
                text=(
                    f"the window's Eq. 5.1 residual is {equation_error_ratio:.2f}x what noise alone leaves, beyond the "
                    f"{limit:.2f}x a window the model explains reaches {100 * MISFIT_FALSE_ALARM:g} % of the time: the "
                    f"model lacks something this window holds ({widened}; `ema calibrate` traces it)"
                ),
            )
        )
    return Assessed(values, stds, methods, inflation, notes)
