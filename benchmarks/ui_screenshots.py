"""Screenshots of the operator's pages for docs/figures: a fresh service holding tests/service/fleet.py's small
fleet, each page loaded in headless Chromium.

    python -m benchmarks.ui_screenshots [--out docs/figures]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from tests.service.fleet import served_fleet
from tests.service.test_ui_browser import visit


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent.parent / "docs" / "figures")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder, served_fleet(Path(folder) / "history.sqlite3") as url:
        for name, path in (("ui-fleet.png", "/ui"), ("ui-actuator.png", "/ui/actuators/tail-2/elevator-left")):
            _, errors, hosts, _ = visit(url, path, args.out / name)
            print(f"{args.out / name}: console errors {errors}, hosts {sorted(hosts)}")


if __name__ == "__main__":
    main()
