"""The shallow network of thesis §5.2 / Table 6.1 and its training with early stopping, in NumPy.

One tanh hidden layer, a saturating linear output (MATLAB's satlins) applied when predicting
only: training on the linear output keeps a gradient where a saturated output would have none
(a first L-BFGS step that overshoots ±1 froze training that way), MSE, a 75/15/10
split, at most 1 000 epochs, stop after 12 validation failures and keep the best-validation
weights. An epoch is one iteration of SciPy's full-batch L-BFGS (its line search included), so
that early stopping sees every step; MATLAB's trainscg is a conjugate gradient, and SciPy's
nonlinear conjugate gradient (``optimizer="cg"``) stands for it in the optimizer comparison
(docs/results.md). The loss's gradient is the two layers' back-propagation written out: a network
of ~2 000 weights on a hundred examples needs no framework.

Two choices beyond the thesis, both measured there: the output layer starts near zero with its
bias at the targets' mean (training starts from the best constant instead of a random offset
that L-BFGS sometimes could not leave), and the standardized inputs are projected on their
leading principal components (whitened) before the tanh layer. The residual-torque traces of
one command differ by a few smooth modes; 1 000 raw inputs carry those modes plus noise, and
the projection makes each epoch ~20x cheaper and keeps the noise out (``components=None``
trains on the raw inputs, as the thesis did).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import OptimizeResult, minimize

from ema.model.checks import InputError

OPTIMIZERS = {"lbfgs": "L-BFGS-B", "cg": "CG"}  # ema's name -> SciPy's method
LBFGS_MEMORY = 50  # correction pairs L-BFGS keeps (SciPy's default, 10, converged slower on these problems)


@dataclass(frozen=True)
class LearnConfig:
    hidden: int = 100  # hidden neurons
    max_epochs: int = 1000
    max_validation_failures: int = 12
    goal_mse: float = 1e-7  # stop when the training MSE reaches it (thesis: 1e-6; we aim lower)
    components: int | None = 16  # principal components fed to the tanh layer; None: the raw inputs
    split: tuple[float, float, float] = (0.75, 0.15, 0.10)  # train / validation / test
    optimizer: str = "lbfgs"  # a key of OPTIMIZERS
    seed: int = 0

    def __post_init__(self) -> None:
        if not 1 <= self.hidden <= 2000:
            raise InputError("hidden_units", f"must be in [1, 2000], got {self.hidden}")
        if self.optimizer not in OPTIMIZERS:
            raise InputError("optimizer", f"unknown optimizer {self.optimizer!r}; known: {', '.join(OPTIMIZERS)}")
        if not 1 <= self.max_epochs <= 100_000:
            raise InputError("max_epochs", f"must be in [1, 100000], got {self.max_epochs}")
        if self.components is not None and not 1 <= self.components <= 5000:
            raise InputError("components", f"must be in [1, 5000] or None, got {self.components}")
        if abs(sum(self.split) - 1.0) > 1e-9 or min(self.split) <= 0:
            raise InputError("split", f"must be three positive fractions summing to 1, got {self.split}")


@dataclass(frozen=True)
class InputTransform:
    """Raw inputs (B, F) -> standardized, projected (B, P); fixed, from the training split."""

    mean: np.ndarray  # (F,)
    std: np.ndarray  # (F,)
    projection: np.ndarray  # (F, P) principal directions, scaled; the identity with components=None

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return ((x - self.mean) / self.std) @ self.projection


def input_transform(x_train: np.ndarray, components: int | None) -> InputTransform:
    """The standardization and projection of the training inputs (N, F).

    Components keep their relative spread (scaled by the leading one's std, not whitened).
    """
    mean = x_train.mean(axis=0)
    std = x_train.std(axis=0, ddof=1) if len(x_train) > 1 else np.zeros(x_train.shape[1])
    std = np.maximum(std, 1e-6 * float(std.max()) + 1e-300)  # a column constant over the set stays finite
    if components is None:
        return InputTransform(mean, std, np.eye(x_train.shape[1]))
    z = (x_train - mean) / std  # (N, F)
    _, singular, vh = np.linalg.svd(z, full_matrices=False)  # vh: (min(N, F), F)
    k = min(components, len(singular))
    scale = singular[0] / np.sqrt(max(len(x_train) - 1, 1))  # std of the leading component's scores
    return InputTransform(mean, std, vh[:k].T / scale)


@dataclass(frozen=True)
class Layers:
    """The trained part, (B, P) -> tanh (B, H) -> linear (B, T), as views into one flat weight vector."""

    weights: np.ndarray  # (P·H + H + H·T + T,) the optimizer's variable
    inputs: int  # P
    hidden: int  # H
    targets: int  # T

    @property
    def parts(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(W1 (P, H), b1 (H,), W2 (H, T), b2 (T,)), views of ``weights``."""
        p, h, t = self.inputs, self.hidden, self.targets
        ends = np.cumsum([p * h, h, h * t])
        w1, b1, w2, b2 = np.split(self.weights, ends)
        return w1.reshape(p, h), b1, w2.reshape(h, t), b2

    def __call__(self, z: np.ndarray) -> np.ndarray:
        w1, b1, w2, b2 = self.parts
        return np.tanh(z @ w1 + b1) @ w2 + b2


def initial_layers(inputs: int, hidden: int, y_train: np.ndarray, rng: np.random.Generator) -> Layers:
    """Layers drawn as a linear layer's usual start, U(±1/√fan_in), the output's weights a tenth of that
    and its bias the targets' mean: training starts near the best constant (module docstring)."""
    targets = y_train.shape[1]
    w1 = rng.uniform(-1, 1, (inputs, hidden)) / np.sqrt(inputs)
    b1 = rng.uniform(-1, 1, hidden) / np.sqrt(inputs)
    w2 = 0.1 * rng.uniform(-1, 1, (hidden, targets)) / np.sqrt(hidden)
    weights = np.concatenate([w1.ravel(), b1, w2.ravel(), y_train.mean(axis=0)])
    return Layers(weights, inputs, hidden, targets)


def mse_and_gradient(weights: np.ndarray, layers: Layers, z: np.ndarray, y: np.ndarray) -> tuple[float, np.ndarray]:
    """The mean squared error over all (N, T) outputs at ``weights`` and its gradient (back-propagation):
    with r = (out − y)·2/(N·T), ∂W2 = aᵀr, ∂b2 = Σr, and through tanh' = 1 − a², ∂W1 = zᵀ(rW2ᵀ ⊙ (1 − a²))."""
    w1, b1, w2, b2 = replace(layers, weights=weights).parts
    a = np.tanh(z @ w1 + b1)  # (N, H)
    error = a @ w2 + b2 - y  # (N, T)
    r = error * (2.0 / error.size)
    back = (r @ w2.T) * (1.0 - a * a)  # (N, H)
    gradient = np.concatenate([(z.T @ back).ravel(), back.sum(axis=0), (a.T @ r).ravel(), r.sum(axis=0)])
    return float(np.mean(error * error)), gradient


@dataclass(frozen=True)
class ShallowNet:
    """inputs (B, F) -> standardized, projected (B, P) -> tanh (B, H) -> linear (B, T)."""

    transform: InputTransform
    layers: Layers

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """(B, T) the linear output, unsaturated."""
        return self.layers(self.transform(np.atleast_2d(np.asarray(x, dtype=np.float64))))


@dataclass
class LearnedNetwork:
    model: ShallowNet
    epochs: int
    stop_reason: str  # "validation", "goal", "max_epochs" or "converged" (the optimizer can go no further)
    train_mse: float
    val_mse: float
    test_mse: float
    seconds: float
    split: dict[str, np.ndarray] = field(repr=False)  # indices of each part
    history: list[tuple[float, float]] = field(default_factory=list, repr=False)  # (train, val) per epoch


def split_indices(n: int, fractions: tuple[float, float, float], rng: np.random.Generator) -> dict[str, np.ndarray]:
    """Random train/validation/test indices (thesis: assigned randomly)."""
    order = rng.permutation(n)
    n_train = round(fractions[0] * n)
    n_val = round(fractions[1] * n)
    if min(n_train, n_val, n - n_train - n_val) < 1:
        raise InputError("n_simulations", f"{n} simulations cannot be split {fractions}")
    return {"train": order[:n_train], "val": order[n_train : n_train + n_val], "test": order[n_train + n_val :]}


class EarlyStopping:
    """The optimizer's per-iteration callback: each epoch's (train, validation) MSE, the best-validation
    weights kept, and the stop (``StopIteration``) after ``max_validation_failures`` epochs without a better
    validation, or at the goal."""

    def __init__(self, layers: Layers, z_val: np.ndarray, y_val: np.ndarray, config: LearnConfig) -> None:
        self.layers, self.z_val, self.y_val, self.config = layers, z_val, y_val, config
        self.history: list[tuple[float, float]] = []
        self.best_weights, self.best_val = layers.weights.copy(), float("inf")  # the start, until an epoch ends
        self.failures, self.stop_reason = 0, ""

    def __call__(self, intermediate_result: OptimizeResult) -> None:
        layers = replace(self.layers, weights=intermediate_result.x)
        train_mse, val_mse = float(intermediate_result.fun), float(np.mean((layers(self.z_val) - self.y_val) ** 2))
        self.history.append((train_mse, val_mse))
        if val_mse < self.best_val:
            self.best_val, self.best_weights, self.failures = val_mse, intermediate_result.x.copy(), 0
        else:
            self.failures += 1
        if self.failures >= self.config.max_validation_failures:
            self.stop_reason = "validation"
        elif train_mse <= self.config.goal_mse:
            self.stop_reason = "goal"
        if self.stop_reason:
            raise StopIteration


def optimizer_options(config: LearnConfig) -> dict[str, float | int]:
    """SciPy's options: an iteration per epoch, and no stopping rule of the optimizer's own on small steps or
    gradients (it would end training silently; the validation check decides)."""
    if config.optimizer == "cg":
        return {"maxiter": config.max_epochs, "gtol": 0.0}
    epochs = config.max_epochs
    return {"maxiter": epochs, "maxcor": LBFGS_MEMORY, "ftol": 0.0, "gtol": 0.0, "maxfun": 25 * epochs}


def learn_network(inputs: np.ndarray, targets: np.ndarray, config: LearnConfig) -> LearnedNetwork:
    """Train one network on (N, F) inputs and (N, T) targets in [0, 1]; seeded end to end."""
    start = time.perf_counter()
    rng = np.random.default_rng(config.seed)
    parts = split_indices(len(inputs), config.split, rng)
    x, y = np.asarray(inputs, dtype=np.float64), np.asarray(targets, dtype=np.float64)  # (N, F), (N, T)
    transform = input_transform(x[parts["train"]], config.components)
    z = transform(x)  # (N, P): projected once, not in every line-search evaluation
    z_train, y_train = z[parts["train"]], y[parts["train"]]
    layers = initial_layers(z.shape[1], config.hidden, y_train, rng)
    stopping = EarlyStopping(layers, z[parts["val"]], y[parts["val"]], config)
    minimize(
        mse_and_gradient,
        layers.weights,
        args=(layers, z_train, y_train),
        jac=True,
        method=OPTIMIZERS[config.optimizer],
        callback=stopping,
        options=optimizer_options(config),
    )
    best = replace(layers, weights=stopping.best_weights)
    stop_reason = stopping.stop_reason or ("max_epochs" if len(stopping.history) >= config.max_epochs else "converged")
    return LearnedNetwork(
        model=ShallowNet(transform, best),
        epochs=len(stopping.history),
        stop_reason=stop_reason,
        train_mse=float(np.mean((best(z_train) - y_train) ** 2)),
        val_mse=float(np.mean((best(z[parts["val"]]) - y[parts["val"]]) ** 2)),
        test_mse=float(np.mean((best(z[parts["test"]]) - y[parts["test"]]) ** 2)),
        seconds=time.perf_counter() - start,
        split=parts,
        history=stopping.history,
    )


def predict(model: ShallowNet, inputs: np.ndarray) -> np.ndarray:
    """(N, T) predictions clamped to the [0, 1] range the targets were normalized to."""
    return np.clip(model(inputs), 0.0, 1.0)
