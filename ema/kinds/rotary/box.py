"""The rotary's dataset box: where a window's simulations are drawn, around its Eq. 5.1 reading.

The thesis samples fixed ranges (FDJ 0.04–0.06 N·m, η_O 0.68–0.98). Here every window gets its own box, centred on
the physics estimate (``ema.kinds.rotary.physics.friction``), ±``SPAN_SIGMAS`` of its jackknife std wide but never
narrower than ``MIN_HALF_SPAN``, and clipped only to what is physical: FDJ from a tenth of nominal to ten times it,
η_O down into Case 1C's irreversible range, FSJ ≥ FDJ. Its points are the shared Halton design's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.estimate.simulate.design import SPAN_SIGMAS, halton
from ema.model.checks import InputError
from ema.model.params import HealthParams

# What is physical, whatever the window: FDJ from a tenth of the actuator's nominal to ten times it, η_O
# down into the irreversible range (thesis Case 1C).
PHYSICAL_FDJ_SHARE = (0.1, 10.0)
PHYSICAL_ETA_O = (0.25, 0.995)
MIN_HALF_SPAN = {"fdj_nm": 0.05, "eta_o": 0.025}  # FDJ relative to the centre, η_O absolute


@dataclass(frozen=True)
class Box:
    """Sampling intervals of one dataset; FSJ is drawn as FSD · FDJ."""

    fdj_nm: tuple[float, float]  # FDJ [N·m]
    eta_o: tuple[float, float]  # η_O [-]
    fsd: tuple[float, float] = (1.2, 2.8)  # FSJ / FDJ [-]: static friction above dynamic

    def __post_init__(self) -> None:
        for name in ("fdj_nm", "eta_o", "fsd"):
            low, high = getattr(self, name)
            if not 0.0 < low < high:
                raise InputError(name, f"interval must satisfy 0 < low < high, got ({low:g}, {high:g})")

    def normalize(self, fdj_nm: np.ndarray, eta_o: np.ndarray) -> np.ndarray:
        """(n, 2): FDJ and η_O mapped to [0, 1] over the box."""
        return np.stack([_unit(fdj_nm, self.fdj_nm), _unit(eta_o, self.eta_o)], axis=-1)

    def denormalize(self, normalized: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(FDJ, η_O) from (n, 2) values in box units (extrapolating outside [0, 1])."""
        return _scale(normalized[:, 0], self.fdj_nm), _scale(normalized[:, 1], self.eta_o)


def physical_fdj_nm(nominal_fdj_nm: float) -> tuple[float, float]:
    """The FDJ an actuator of this nominal can physically have."""
    return PHYSICAL_FDJ_SHARE[0] * nominal_fdj_nm, PHYSICAL_FDJ_SHARE[1] * nominal_fdj_nm


def physical(nominal_fdj_nm: float) -> Box:
    """What an actuator of this nominal FDJ can physically be (``physical_fdj_nm``, ``PHYSICAL_ETA_O``)."""
    return Box(fdj_nm=physical_fdj_nm(nominal_fdj_nm), eta_o=PHYSICAL_ETA_O)


def _unit(values: np.ndarray, interval: tuple[float, float]) -> np.ndarray:
    return (np.asarray(values) - interval[0]) / (interval[1] - interval[0])


def _scale(unit: np.ndarray, interval: tuple[float, float]) -> np.ndarray:
    return interval[0] + np.asarray(unit) * (interval[1] - interval[0])


def _interval(centre: float, half: float, limits: tuple[float, float]) -> tuple[float, float]:
    """centre ± half, shifted (not shrunk) to stay inside ``limits`` where it can."""
    low, high = centre - half, centre + half
    if low < limits[0]:
        low, high = limits[0], min(limits[0] + 2 * half, limits[1])
    if high > limits[1]:
        low, high = max(limits[1] - 2 * half, limits[0]), limits[1]
    return low, high


def box_around(fdj_nm: float, fdj_std_nm: float, eta_o: float, eta_o_std: float, nominal_fdj_nm: float) -> Box:
    """The box for a window whose physics estimate is (FDJ ± std, η_O ± std), inside what an actuator of
    ``nominal_fdj_nm`` can physically be."""
    for name, value in (("fdj_nm", fdj_nm), ("eta_o", eta_o), ("fdj_std_nm", fdj_std_nm), ("eta_o_std", eta_o_std)):
        if not np.isfinite(value):
            raise InputError(name, f"must be finite to centre a dataset on, got {value}")
    limits = physical(nominal_fdj_nm)
    fdj_nm = float(np.clip(fdj_nm, *limits.fdj_nm))
    eta_o = float(np.clip(eta_o, *limits.eta_o))
    fdj_half = max(SPAN_SIGMAS * fdj_std_nm, MIN_HALF_SPAN["fdj_nm"] * fdj_nm)
    eta_half = max(SPAN_SIGMAS * eta_o_std, MIN_HALF_SPAN["eta_o"])
    return Box(
        fdj_nm=_interval(fdj_nm, fdj_half, limits.fdj_nm),
        eta_o=_interval(eta_o, eta_half, limits.eta_o),
    )


def centre(box: Box) -> HealthParams:
    """The box's centre, FSJ at twice FDJ."""
    fdj = float(np.mean(box.fdj_nm))
    return HealthParams.single(2.0 * fdj, fdj, float(np.mean(box.eta_o)))


def draw(box: Box, n: int, seed: int) -> HealthParams:
    """``n`` health points filling ``box`` (FDJ, η_O and FSD on the three Halton axes)."""
    if n < 1:
        raise InputError("n_simulations", f"must be at least 1, got {n}")
    unit = halton(n, seed)
    fdj = _scale(unit[:, 0], box.fdj_nm)
    return HealthParams(fsj_nm=fdj * _scale(unit[:, 2], box.fsd), fdj_nm=fdj, eta_o=_scale(unit[:, 1], box.eta_o))
