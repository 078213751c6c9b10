"""Where a window's dataset is drawn: around the physics estimate, as wide as its uncertainty says.

The thesis samples fixed ranges (FDJ 0.04–0.06 N·m, η_O 0.68–0.98), and a network trained there
cannot answer outside them: a worn actuator's friction is read near the edge of the box, with a
std that does not notice. Here every window gets its own box, centred on the Eq. 5.1 estimate
(``ema.kinds.rotary.physics.friction``), ±``SPAN_SIGMAS`` of its jackknife std wide but never narrower than
``MIN_HALF_SPAN``, and clipped only to what is physical (``PHYSICAL``): FDJ from a tenth of
nominal to ten times it, η_O down into Case 1C's irreversible range, FSJ ≥ FDJ. The points fill
the box with a scrambled Halton sequence: a few dozen simulations cover it evenly where uniform
draws leave holes and clusters.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ema.model.checks import InputError
from ema.model.params import HealthParams

# What is physical, whatever the window: FDJ from a tenth of the actuator's nominal to ten times it, η_O
# down into the irreversible range (thesis Case 1C).
PHYSICAL_FDJ_SHARE = (0.1, 10.0)
PHYSICAL_ETA_O = (0.25, 0.995)
SPAN_SIGMAS = 6.0  # the box's half-width in jackknife standard deviations of the centre
MIN_HALF_SPAN = {"fdj_nm": 0.05, "eta_o": 0.025}  # FDJ relative to the centre, η_O absolute
HALTON_PRIMES = (2, 3, 5, 7, 11, 13, 17, 19)


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


def halton(n: int, seed: int, dims: int = 3) -> np.ndarray:
    """(n, dims) points of a Halton sequence in the first ``dims`` prime bases, randomly shifted modulo 1
    (Cranley–Patterson)."""
    if not 1 <= dims <= len(HALTON_PRIMES):
        raise InputError("dims", f"a Halton sequence here has 1 to {len(HALTON_PRIMES)} dimensions, got {dims}")
    index = np.arange(1, n + 1)
    columns = []
    for base in HALTON_PRIMES[:dims]:
        value, fraction, i = np.zeros(n), 1.0 / base, index.copy()
        while np.any(i > 0):
            value += fraction * (i % base)
            i //= base
            fraction /= base
        columns.append(value)
    shift = np.random.default_rng(seed).uniform(size=dims)
    return np.mod(np.stack(columns, axis=1) + shift, 1.0)


def draw(box: Box, n: int, seed: int) -> HealthParams:
    """``n`` health points filling ``box`` (FDJ, η_O and FSD on the three Halton axes)."""
    if n < 1:
        raise InputError("n_simulations", f"must be at least 1, got {n}")
    unit = halton(n, seed)
    fdj = _scale(unit[:, 0], box.fdj_nm)
    return HealthParams(fsj_nm=fdj * _scale(unit[:, 2], box.fsd), fdj_nm=fdj, eta_o=_scale(unit[:, 1], box.eta_o))


def binned(values: np.ndarray, bins: int) -> np.ndarray:
    """(…, bins) means of ``values`` over ``bins`` equal parts of the window: a network's inputs."""
    edges = np.linspace(0, values.shape[-1], bins + 1).astype(int)
    return np.stack([values[..., a:b].mean(axis=-1) for a, b in itertools.pairwise(edges)], axis=-1)


def shifted_copies(misfit: np.ndarray, count: int, seed: int) -> np.ndarray:
    """(count, N) a window's ``misfit`` (N,), each row at its own circular shift and sign (drawn from ``seed``): a
    disturbance of the window's own size and spectrum, at no fixed place, for its simulations to carry."""
    rng = np.random.default_rng(seed)
    shifts = rng.integers(0, len(misfit), size=count)
    signs = rng.choice([-1.0, 1.0], size=count)
    return signs[:, None] * np.stack([np.roll(misfit, shift) for shift in shifts])
