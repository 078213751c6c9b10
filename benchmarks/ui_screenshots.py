"""Screenshots of the operator's pages for docs/figures: a fresh service holding tests/service/fleet.py's small
fleet, each page loaded in headless Chromium.

    python -m benchmarks.ui_screenshots [--out docs/figures]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from service.store import EstimateStore
from sim.actuator import THESIS
from sim.params import HealthParams
from sim.synthetic import synthetic_window
from tests.clients.test_replay import _free_port, _start_server
from tests.service.conftest import SMALL
from tests.service.fleet import store_fleet
from tests.service.test_ui_browser import visit
from training.pipeline import estimate_window


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent.parent / "docs" / "figures")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        database = Path(folder) / "history.sqlite3"
        base = estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), SMALL, actuator=THESIS)
        store = EstimateStore(database)
        store_fleet(store, base)
        store.close()
        port = _free_port()
        server = _start_server(port, database)
        try:
            url = f"http://127.0.0.1:{port}"
            for name, path in (("ui-fleet.png", "/ui"), ("ui-actuator.png", "/ui/actuators/tail-2/elevator-left")):
                _, errors, hosts, _ = visit(url, path, args.out / name)
                print(f"{args.out / name}: console errors {errors}, hosts {sorted(hosts)}")
        finally:
            server.terminate()
            server.wait(timeout=30)


if __name__ == "__main__":
    main()
