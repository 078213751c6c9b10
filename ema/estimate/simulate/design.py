"""How every kind's dataset is drawn around its physics reading: points filling a box evenly, a network's inputs, and
the window's own misfit carried by each simulation.

A network trained over fixed ranges cannot answer outside them: a worn actuator's constant is read near the edge of
the box, with a std that does not notice. So each kind centres its box on its physics reading, ±``SPAN_SIGMAS`` of
that reading's std wide, and fills it with a scrambled Halton sequence (``halton``): a few dozen simulations cover it
evenly where uniform draws leave holes and clusters.
"""

from __future__ import annotations

import itertools

import numpy as np

from ema.model.checks import InputError

SPAN_SIGMAS = 6.0  # the box's half-width in jackknife standard deviations of the centre
HALTON_PRIMES = (2, 3, 5, 7, 11, 13, 17, 19)


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
