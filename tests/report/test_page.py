"""The report folder (issue 24): the page renders in headless Chromium with every image loaded,
the PDF has a page per figure after its text pages, summary.json is strict JSON, and the figures
follow the report's conventions (µm, plain log ticks, thresholds and limits in the legend,
colour by vehicle class, local time)."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from rail_monitor.bagio.reader import read_passes
from rail_monitor.batch.bag import write_bag
from rail_monitor.batch.run import run_models
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.report import plots as report_plots
from rail_monitor.report import tables as report_tables
from rail_monitor.report.run_data import load_run
from rail_monitor.report.run_tables import pass_table
from rail_monitor.report.summary import build_report

from conftest import EXAMPLE_CSV, SITE_FILE

CHROMIUM = "/usr/bin/chromium"
# The flags this closed network needs (no background connections, no sandbox as root).
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    from rail_monitor.site_file import load_parameter_file

    values = load_parameter_file(SITE_FILE)
    tmp = tmp_path_factory.mktemp("page")
    bag = write_bag(run_models(read_passes(EXAMPLE_CSV), values), tmp / "bag", "curve_250")
    run = load_run(bag)
    files = build_report(run, SiteConfig.from_values(values), tmp / "report", "curve_250.yaml")
    return run, values, files, tmp / "report"


def _chromium():
    if not os.access(CHROMIUM, os.X_OK):
        if os.environ.get("RAIL_MONITOR_REQUIRE_BROWSER"):
            pytest.fail(f"{CHROMIUM} is missing (Debian's chromium package; .ci/run installs it)")
        pytest.skip(f"{CHROMIUM} is not installed (Debian's chromium package)")
    from playwright.sync_api import sync_playwright

    return sync_playwright


def test_the_page_renders_in_chromium_with_every_image_loaded(report):
    _, _, files, folder = report
    sync_playwright = _chromium()
    failed, errors = [], []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page()
            page.on("requestfailed", lambda r: failed.append(r.url))
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.goto((folder / "index.html").as_uri(), wait_until="load")
            images = page.evaluate("Array.from(document.images).map(i => [i.getAttribute('src'), i.complete, "
                                   "i.naturalWidth, i.naturalHeight])")
            links = page.evaluate("Array.from(document.links).map(a => a.getAttribute('href'))")
            headings = page.evaluate("Array.from(document.querySelectorAll('h1,h2')).map(h => h.textContent)")
        finally:
            browser.close()
    pngs = sorted(f.name for f in files if f.suffix == ".png")
    assert sorted(src for src, *_ in images) == pngs and len(pngs) == 5
    assert all(done and w > 0 and h > 0 for _, done, w, h in images), images
    assert not failed and not errors, (failed, errors)
    assert all((folder / href).is_file() for href in links), links
    for section in ("Headline", "Per vehicle class", "Noise against the limit", "Grinding outlook per band",
                    "Squealing trains (loudest first)", "Appendix for engineers", "Site parameters"):
        assert section in headings
    assert ("Speed advice per class" in headings) == (report[0].advisory is not None)


def test_pdf_summary_and_squealing_trains(report):
    run, values, _, folder = report
    pdf = (folder / "report.pdf").read_bytes()
    assert pdf.startswith(b"%PDF") and pdf.count(b"/Type /Page\n") + pdf.count(b"/Type /Page ") >= 6
    summary = json.loads((folder / "summary.json").read_text(), parse_constant=lambda c: pytest.fail(c))
    t = pass_table(run, SiteConfig.from_values(values)).as_dict()
    lim = report_tables.limits(SiteConfig.from_values(values))
    squealing = report_tables.squealing(t, lim["squeal_min_risk"])
    assert summary["squealing_passes"] == int(squealing.sum()) and summary["software_version"]
    assert summary["grinding"]["days"] == pytest.approx(float(run.states["days_to_threshold"][-1]), rel=1e-12)
    mech = next(n for n in summary["noise"] if n["model"] == "mechanics")
    x = t["mechanics_lpafmax_dba"]
    assert mech["P95 [dB(A)]"] == pytest.approx(np.percentile(x, 95), rel=1e-12)
    assert mech["above limit [%]"] == pytest.approx(100 * np.mean(x > lim["limit_dba"]), rel=1e-12)
    import pandas as pd

    trains = pd.read_csv(folder / "squealing_trains.csv")
    assert set(trains["train_id"]) == set(t["train_id"][squealing])
    assert list(trains["squeal level [dB(A)]"]) == sorted(trains["squeal level [dB(A)]"], reverse=True)


def test_the_speed_advice_table_is_the_advisory_of_the_bag(report):
    # One row per class and band of the bag's last SpeedAdvisory, as the plan computed it.
    from rail_monitor.advice.plan import advice_of_message

    run = report[0]
    assert run.advisory is not None
    rows = report_tables.speed_advice(run)
    a = advice_of_message(run.advisory)
    assert [r["class"] for r in rows] == a.band_vehicle_class
    assert [r["advised [%]"] for r in rows] == pytest.approx(100 * a.band_recommended_share, rel=1e-12)
    for name in a.vehicle_class:
        assert sum(r["advised [%]"] for r in rows if r["class"] == name) == pytest.approx(100.0)


def _labels(fig) -> list[str]:
    return [text for ax in fig.axes for text in ax.get_legend_handles_labels()[1]]


def _ticks(fig) -> list[str]:
    fig.canvas.draw()
    return [t.get_text() for ax in fig.axes for axis in (ax.xaxis, ax.yaxis)
            for t in axis.get_ticklabels(which="both")]


def test_figures_follow_the_report_conventions(report):
    run, values, _, _ = report
    t = pass_table(run, SiteConfig.from_values(values)).as_dict()
    lim = report_tables.limits(SiteConfig.from_values(values))
    fig = report_plots.corrugation(run.states, "Australia/Brisbane")
    assert "µm" in fig.axes[0].get_ylabel() and "Australia/Brisbane" in fig.axes[0].get_xlabel()
    assert any("threshold" in label for label in _labels(fig))
    assert not any("10^" in s or "times" in s or "^{" in s for s in _ticks(fig))  # plain numbers on the log axis
    models = list(run.noise)
    model = next(iter(run.noise))
    spectra = {"label": "reference pass", model: _Spectrum()}
    fig = report_plots.noise(t, models[:1], lim, spectra, spectra, "UTC")
    labels = _labels(fig)
    assert {"emu", "dmu", "freight"} <= set(labels) and f"limit {lim['limit_dba']:g} dB(A)" in labels
    fig = report_plots.speeds(run.passes.speed_mps, run.advisory)
    assert "km/h" in fig.axes[0].get_xlabel() and "train passes" in fig.axes[0].get_ylabel()
    report_plots.plt.close("all")


class _Spectrum:
    """The two fields of a NoisePrediction the spectra panel draws."""

    band_centre_hz = np.array([100.0, 1000.0])
    lp_db = np.array([[70.0, 80.0]])
