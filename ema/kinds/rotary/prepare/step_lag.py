"""A hinge moment that may be out of step with the other channels, where Eq. 5.1 leans that way
without deciding.

``ema.kinds.rotary.prepare.consistency`` refuses a window whose hinge moment, read 3–50 ms away
(``STEP_LAGS_S``), follows Eq. 5.1 ``MIN_BETTER`` times better: exported on another clock. Below that
the window is answered as logged, yet where the deflection moves slowly Eq. 5.1 hardly feels 20 ms,
and an answer read at the wrong lag is off by what reading the moment at the right one changes.
Once the window's departures are taken off (an offset, a gain, C), the moment read at any of those
lags explains a window in step worse than as logged, or barely better; out of step, it explains it better at
about the lag the export shifted it by.

So the window is still read as logged, and the story "out of step by the best of those lags" is
weighed against it by the likelihood ratio of their equation errors
(``ema.estimate.stats.rms_log_likelihood_ratio``) and a small prior (``PRIOR_LOG_ODDS``, which also pays
for trying ten lags): its weight w. Each target's std grows by √w·|gap|, the RMS distance of the
logged reading from the mixture's (gap: what reading the moment at that lag changes), and a note says
so from ``NOTE_WEIGHT``. The prior trades the out-of-step windows caught against in-step stds grown.

The deflection weighs in too: in the aircraft's band the moment follows it at once, so the lag the
band reads (``hinge_lag.band_log_likelihood``, as for a filter's lag) is the moment's, and its
likelihood at the best lag against none joins the ratio; it weighs against any lag where the moment
is in step. Where the deflection moves too slowly for the band, the ratio alone stays the limit.

The current needs no such reading: its lag breaks Eq. 5.1 at every acceleration, and
``ema.kinds.rotary.prepare.consistency`` refuses it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.stats import odds_weight
from ema.kinds.rotary.evidence import UNDECIDED_NOTE_WEIGHT, UNDECIDED_PRIOR_LOG_ODDS, rms_log_likelihood_ratio
from ema.kinds.rotary.physics.shifts import shifted_solutions
from ema.kinds.rotary.prepare.consistency import step_lags
from ema.kinds.rotary.prepare.hinge_lag import band_log_likelihood
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

# the prior odds of "out of step" against "in step", and the weight from which a note says so
PRIOR_LOG_ODDS, NOTE_WEIGHT = UNDECIDED_PRIOR_LOG_ODDS, UNDECIDED_NOTE_WEIGHT


@dataclass(frozen=True)
class StepLag:
    """The best lag of ``STEP_LAGS_S`` the hinge moment follows Eq. 5.1 at, and the weight of its story."""

    lag_s: float = 0.0  # the moment read this much later explains it best (0: none tried)
    better: float = 1.0  # the equation error as logged over that at the lag
    weight: float = 0.0  # the posterior weight of "out of step by lag_s"
    spread: dict[str, float] = field(default_factory=dict)  # per target, the std the story adds


def step_lag(window: RotaryWindow, drive: DriveConstants) -> StepLag:
    """The hinge moment's out-of-step story on ``window`` (its departures taken off, ``drive`` as read)."""
    rate, lags = window.sample_rate_hz, np.concatenate([[0.0], step_lags(window)])
    if len(lags) == 1:
        return StepLag()
    solutions = shifted_solutions(dict(window.signals), rate, lags, drive, "hinge_moment_nm")
    errors = solutions.residual_rms_nm
    if not np.all(np.isfinite(errors)):
        return StepLag()  # too little sliding motion: the physics solution says so next
    best = 1 + int(np.argmin(errors[1:]))
    flying = not window.on_ground  # on the ground the moment follows no deflection: the band reads no lag
    band = band_log_likelihood(dict(window.signals), rate, lags[[0, best]], drive.gear_ratio) if flying else [0, 0]
    equation = rms_log_likelihood_ratio(
        errors[0], errors[best], float(solutions.n_sliding[0]), rate, resolution_nm=float(solutions.resolution_nm[0])
    )
    log_ratio = equation + band[1] - band[0]
    weight = odds_weight(log_ratio + PRIOR_LOG_ODDS)
    spread = {
        name: float(np.sqrt(weight) * abs(values[best] - values[0]))
        for name, values in solutions.values(slice(None)).items()
    }
    return StepLag(float(lags[best] / rate), float(errors[0] / errors[best]), weight, spread)


def step_lag_note(found: StepLag) -> list[Note]:
    """The story, for the result's notes, where it weighs ``NOTE_WEIGHT`` or more."""
    if found.weight < NOTE_WEIGHT:
        return []
    return [
        Note(
            code="hinge_out_of_step",
            parameter="hinge_moment_nm",
            text=f"the hinge moment follows Eq. 5.1 {100 * (found.better - 1):.1f} % better read "
            f"{1e3 * found.lag_s:+g} ms later: "
            f"out of step with the other channels (exported on another clock?) with weight {found.weight:.2f}, too "
            f"little "
            "to refuse the window; read as logged, the stds include what reading it so would change",
        )
    ]
