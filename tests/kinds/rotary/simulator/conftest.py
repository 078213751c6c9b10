import numpy as np
import pytest

from ema.model import runtime
from ema.model.params import HealthParams


@pytest.fixture
def threads():
    """``runtime.set_threads`` for the test, the budget restored after it."""
    before = runtime.threads()
    yield runtime.set_threads
    runtime.set_threads(before)


@pytest.fixture
def nominal() -> HealthParams:
    return HealthParams.single()


def ramp_knots(start_deg: float, rate_degps: float, n_samples: int, sample_rate_hz: float = 10_000.0) -> np.ndarray:
    """A constant-rate command, as knots at the log-interval boundaries."""
    return start_deg + rate_degps * np.arange(n_samples + 1) / sample_rate_hz
