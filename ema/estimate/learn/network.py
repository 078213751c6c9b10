"""The shallow network of thesis §5.2 / Table 6.1 and its training with early stopping.

One tanh hidden layer, a saturating linear output (MATLAB's satlins) applied when predicting
only: training on the linear output keeps a gradient where a saturated output would have none
(a first L-BFGS step that overshoots ±1 froze training that way), MSE, a 75/15/10
split, at most 1 000 epochs, stop after 12 validation failures and keep the best-validation
weights. MATLAB's trainscg has no torch twin; full-batch L-BFGS is used because it measured
both faster and more accurate than Adam on these problems (docs/results.md, optimizer table).

Two choices beyond the thesis, both measured there: the output layer starts at zero with its
bias at the targets' mean (training starts from the best constant instead of a random offset
that L-BFGS sometimes could not leave), and the standardized inputs are projected on their
leading principal components (whitened) before the tanh layer. The residual-torque traces of
one command differ by a few smooth modes; 1 000 raw inputs carry those modes plus noise, and
the projection makes each epoch ~20x cheaper and keeps the noise out (``components=None``
trains on the raw inputs, as the thesis did).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import torch
from torch import nn

from ema.estimate import runtime
from ema.model.checks import InputError

OPTIMIZERS = ("lbfgs", "adam")


@dataclass(frozen=True)
class LearnConfig:
    hidden: int = 100  # hidden neurons
    max_epochs: int = 1000
    max_validation_failures: int = 12
    goal_mse: float = 1e-7  # stop when the training MSE reaches it (thesis: 1e-6; we aim lower)
    components: int | None = 16  # principal components fed to the tanh layer; None: the raw inputs
    split: tuple[float, float, float] = (0.75, 0.15, 0.10)  # train / validation / test
    optimizer: str = "lbfgs"
    learning_rate: float = 1.0  # L-BFGS step scale (line search sets the step); Adam: use ~3e-3
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


class ShallowNet(nn.Module):
    """inputs (B, F) -> standardized, projected (B, P) -> tanh (B, H) -> linear (B, T).

    ``predict`` saturates the output to [0, 1]. The projection (F, P) is fixed, from the training
    split; with ``components=None`` it is the identity and P = F.
    """

    mean: torch.Tensor
    std: torch.Tensor
    projection: torch.Tensor

    def __init__(
        self, mean: torch.Tensor, std: torch.Tensor, projection: torch.Tensor, hidden: int, targets: torch.Tensor
    ):
        super().__init__()
        self.register_buffer("mean", mean)  # (F,) input standardization
        self.register_buffer("std", std)  # (F,)
        self.register_buffer("projection", projection)  # (F, P) principal directions, scaled
        self.hidden = nn.Linear(projection.shape[1], hidden)
        self.output = nn.Linear(hidden, targets.shape[1])
        with torch.no_grad():  # start near the best constant: small weights, the targets' mean as bias
            self.output.weight.mul_(0.1)
            self.output.bias.copy_(targets.mean(dim=0))

    def project(self, x: torch.Tensor) -> torch.Tensor:
        """(B, F) raw inputs -> (B, P) standardized, projected: fixed, so training does it once."""
        return ((x - self.mean) / self.std) @ self.projection

    def head(self, z: torch.Tensor) -> torch.Tensor:
        """(B, P) -> tanh (B, H) -> linear (B, T): the trained part."""
        return self.output(torch.tanh(self.hidden(z)))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.head(self.project(x))


def input_transform(x_train: torch.Tensor, components: int | None) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """(mean (F,), std (F,), projection (F, P)) from the training inputs (N, F).

    Components keep their relative spread (scaled by the leading one's std, not whitened).
    """
    mean = x_train.mean(dim=0)
    std = x_train.std(dim=0)
    std = std.clamp_min(1e-6 * float(std.max()) + 1e-300)  # a column constant over the set stays finite
    if components is None:
        return mean, std, torch.eye(x_train.shape[1], dtype=x_train.dtype)
    z = (x_train - mean) / std  # (N, F)
    _, singular, vh = torch.linalg.svd(z, full_matrices=False)  # vh: (min(N, F), F)
    k = min(components, len(singular))
    scale = singular[0] / np.sqrt(max(len(x_train) - 1, 1))  # std of the leading component's scores
    return mean, std, vh[:k].T / scale


@dataclass
class Trained:
    model: ShallowNet
    epochs: int
    stop_reason: str  # "validation", "goal" or "max_epochs"
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


def _mse(model: ShallowNet, z: torch.Tensor, y: torch.Tensor) -> float:
    with torch.no_grad():
        return float(torch.mean((model.head(z) - y) ** 2))


def _optimizer(model: ShallowNet, config: LearnConfig) -> torch.optim.Optimizer:
    if config.optimizer == "adam":
        return torch.optim.Adam(model.parameters(), lr=config.learning_rate)
    return torch.optim.LBFGS(
        model.parameters(),
        lr=config.learning_rate,
        max_iter=1,  # one iteration per epoch, so early stopping sees every step
        max_eval=25,  # the default, 1.25 x max_iter = 1, leaves the line search no evaluation
        history_size=50,
        line_search_fn="strong_wolfe",
        tolerance_grad=0.0,  # its own stopping rules (on tiny gradients) would end training silently;
        tolerance_change=0.0,  # the epoch loop's validation check decides instead
    )


def _snapshot(model: nn.Module) -> dict[str, torch.Tensor]:
    """A copy of the model's parameters and buffers: a clone per tensor (deepcopy walks each object in
    Python, and the best state is copied at every epoch that improves)."""
    return {name: value.detach().clone() for name, value in model.state_dict().items()}


def train(inputs: np.ndarray, targets: np.ndarray, config: LearnConfig) -> Trained:
    """Train one network on (N, F) inputs and (N, T) targets in [0, 1]; seeded end to end."""
    start = time.perf_counter()
    runtime.torch_ready()  # the process's budget, where one was set before torch was loaded
    torch.manual_seed(config.seed)
    parts = split_indices(len(inputs), config.split, np.random.default_rng(config.seed))
    x = torch.as_tensor(inputs, dtype=torch.float64)  # (N, F)
    y = torch.as_tensor(targets, dtype=torch.float64)  # (N, T)
    x_train, y_train = x[parts["train"]], y[parts["train"]]
    model = ShallowNet(*input_transform(x_train, config.components), config.hidden, y_train).double()
    with torch.no_grad():
        z = model.project(x)  # (N, P): projected once, not in every line-search evaluation
    z_train = z[parts["train"]]
    loss_fn = nn.MSELoss()
    optimizer = _optimizer(model, config)

    def closure() -> torch.Tensor:
        model.zero_grad()  # what optimizer.zero_grad does, without the torch._dynamo guard it pays at each call
        loss = loss_fn(model.head(z_train), y_train)
        loss.backward()
        return loss

    best_val, best_state, failures, stop_reason = float("inf"), _snapshot(model), 0, "max_epochs"
    history: list[tuple[float, float]] = []
    for _ in range(config.max_epochs):
        optimizer.step(closure)  # type: ignore[arg-type]  # torch types the closure as returning float
        train_mse = _mse(model, z_train, y_train)
        val_mse = _mse(model, z[parts["val"]], y[parts["val"]])
        history.append((train_mse, val_mse))
        if val_mse < best_val:
            best_val, best_state, failures = val_mse, _snapshot(model), 0
        else:
            failures += 1
        if failures >= config.max_validation_failures:
            stop_reason = "validation"
            break
        if train_mse <= config.goal_mse:
            stop_reason = "goal"
            break
    model.load_state_dict(best_state)
    return Trained(
        model=model,
        epochs=len(history),
        stop_reason=stop_reason,
        train_mse=_mse(model, z_train, y_train),
        val_mse=best_val,
        test_mse=_mse(model, z[parts["test"]], y[parts["test"]]),
        seconds=time.perf_counter() - start,
        split=parts,
        history=history,
    )


def predict(model: ShallowNet, inputs: np.ndarray) -> np.ndarray:
    """(N, T) predictions clamped to the [0, 1] range the targets were normalized to."""
    model.eval()
    with torch.no_grad():
        out = model(torch.as_tensor(np.atleast_2d(inputs), dtype=torch.float64))
    return np.clip(out.numpy().astype(np.float64), 0.0, 1.0)
