"""A small fleet's stored histories for the operator's pages: each actuator's FDJ over flight hours by a law of
its own (copies of one real estimate with FDJ and η_O replaced), and the truth of what each should show."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

import httpx
import numpy as np

from ema.estimate.documents import Estimate, parameter
from ema.history.open import History, open_history
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from tests.servers import free_port, start_server
from tests.service.conftest import SMALL, settled_lines

# actuator -> (FDJ at 0 h [N·m], FDJ per flight hour, curvature per h², what its page must say)
FLEET = {
    "tail-1/elevator-left": (0.050, 0.0, 0.0, "no degradation detected"),
    "tail-1/elevator-right": (0.050, 1e-4, 0.0, "crossing predicted"),
    "tail-2/elevator-left": (0.052, 2e-5, 4e-7, "crossing predicted"),
    "tail-3/elevator-left": (0.070, 1.5e-4, 0.0, "already crossed"),
}


def store_fleet(store: History, base: Estimate, windows: int = 20, seed: int = 0) -> None:
    """Every actuator of ``FLEET``, ``windows`` windows over 190 flight hours."""
    rng = np.random.default_rng(seed)
    hours = np.linspace(0.0, 190.0, windows)
    for actuator_id, (start, slope, curvature, _) in FLEET.items():
        for i, h in enumerate(hours):
            fdj = start + slope * h + curvature * h**2 + 3e-4 * rng.normal()
            estimates = base.estimates.model_copy(update={"FDJ": parameter(fdj, 3e-4, 0.05, unit="N·m")})
            window = base.window.model_copy(update={"flight_hours": float(h), "content_sha256": f"{actuator_id}-{i}"})
            store.add(
                base.model_copy(
                    update={
                        "actuator_id": actuator_id,
                        "window_id": f"w{i:02d}",
                        "estimates": estimates,
                        "window": window,
                    }
                )
            )


@contextlib.contextmanager
def served_fleet(database: Path) -> Iterator[str]:
    """The URL of a service on a free port whose store (``database``) holds the fleet, copies of one small real
    estimate, once its keeper has computed every actuator's line; the service is stopped on leaving."""
    base = estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), SMALL, actuator=THESIS)
    store = open_history(database)
    store_fleet(store, base)
    store.close()
    port = free_port()
    server = start_server(port, database)
    url = f"http://127.0.0.1:{port}"
    try:
        settled_lines(lambda: httpx.get(f"{url}/v1/actuators", timeout=30).json())
        yield url
    finally:
        server.terminate()
        server.wait(timeout=30)
