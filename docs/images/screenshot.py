"""Regenerate report.png, the README's screenshot of the demo's report, in headless Chromium:

    ros2_ws/run demo && ros2_ws/run python docs/images/screenshot.py

Needs Debian's chromium (/usr/bin/chromium) and the pinned playwright of the workspace."""

from pathlib import Path

from playwright.sync_api import sync_playwright

TOP = Path(__file__).resolve().parents[2]
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]

with sync_playwright() as p:
    browser = p.chromium.launch(executable_path="/usr/bin/chromium", headless=True, args=FLAGS)
    page = browser.new_page(viewport={"width": 1200, "height": 1500})
    page.goto((TOP / "out" / "demo_report" / "index.html").as_uri(), wait_until="load")
    page.screenshot(path=str(Path(__file__).with_name("report.png")))
    browser.close()
