"""The operator's pages in a real browser (Debian's headless Chromium, driven by Playwright): what a person
sees, that nothing is fetched from another host, and no console error. Skipped, saying why, only where no
Chromium can be found (``.ci/run`` installs it)."""

import shutil

import pytest

from tests.service.fleet import FLEET, served_fleet

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
playwright = pytest.importorskip("playwright.sync_api", reason="playwright is in the dev extra")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="no chromium on this machine (apt-get install chromium)")


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    with served_fleet(tmp_path_factory.mktemp("ui") / "history.sqlite3") as url:
        yield url


def visit(url: str, path: str, screenshot=None) -> tuple[str, list[str], set[str], int]:
    """(visible text, console errors, hosts requested, SVG plots with their points) of one page."""
    errors, hosts = [], set()
    with playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        page = browser.new_page()
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.on("request", lambda r: hosts.add(r.url.split("/")[2]))
        page.goto(url + path)
        text, plots = page.inner_text("body"), page.locator("svg:has(circle.estimate)").count()
        if screenshot is not None:
            page.screenshot(path=str(screenshot), full_page=True)
        browser.close()
    return text, errors, hosts, plots


def test_the_fleet_and_an_actuator_in_chromium(served, tmp_path):
    text, errors, hosts, _ = visit(served, "/ui", tmp_path / "fleet.png")
    assert all(actuator_id in text for actuator_id in FLEET) and "no degradation detected" in text
    assert "crossed in" in text or "earliest" in text  # remaining lives with their intervals
    assert not errors and hosts == {served.split("/")[2]}
    for actuator_id in FLEET:
        text, errors, hosts, plots = visit(served, f"/ui/actuators/{actuator_id}")
        assert plots == 3 and actuator_id in text and not errors and hosts == {served.split("/")[2]}
    assert _not_blank(tmp_path / "fleet.png")


def _not_blank(path) -> bool:
    """More than a few shades in the screenshot (a blank page has one)."""
    from PIL import Image

    with Image.open(path) as image:
        return len(image.convert("L").getcolors(maxcolors=256) or range(256)) > 10
