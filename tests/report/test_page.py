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
            page.on("requestfailed", lambda r: failed.append((r.url, r.failure)))
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.goto((folder / "index.html").as_uri(), wait_until="load")
            images = page.evaluate("Array.from(document.images).map(i => [i.getAttribute('src'), i.complete, "
                                   "i.naturalWidth, i.naturalHeight])")
            links = page.evaluate("Array.from(document.links).map(a => a.getAttribute('href'))")
            headings = page.evaluate("Array.from(document.querySelectorAll('h1,h2')).map(h => h.textContent)")
            # Each player's file decodes in the browser, as long as the pass it holds.
            audio = page.evaluate("""Promise.all(Array.from(document.querySelectorAll('audio')).map(a =>
                new Promise(done => { a.onloadedmetadata = () => done([a.getAttribute('src'), a.duration]);
                                      a.onerror = () => done([a.getAttribute('src'), -1]);
                                      a.preload = 'auto'; a.load(); })))""")
        finally:
            browser.close()
    pngs = sorted(f.name for f in files if f.suffix == ".png")
    assert sorted(src for src, *_ in images) == pngs and len(pngs) == 5
    assert all(done and w > 0 and h > 0 for _, done, w, h in images), images
    # A media element drops its first request for the ranges it wants (net::ERR_ABORTED): that its
    # file then decodes is checked below.
    failed = [(url, why) for url, why in failed if not (url.endswith(".wav") and why == "net::ERR_ABORTED")]
    assert not failed and not errors, (failed, errors)
    assert all((folder / href).is_file() for href in links), links
    for section in ("Headline", "Per vehicle class", "Noise against the limit", "Grinding outlook per band",
                    "Squealing trains (loudest first)", "Appendix for engineers", "Site parameters"):
        assert section in headings
    assert ("Speed advice per class" in headings) == (report[0].advisory is not None)
    wavs = sorted(str(f.relative_to(folder)) for f in files if f.suffix == ".wav")
    assert sorted(src for src, _ in audio) == wavs and len(wavs) == 3  # three passes, none recorded
    assert all(d > 2 * 2.0 for _, d in audio), audio                    # the train between 2 s margins
    assert "Listen: the loudest passes, predicted and recorded" in headings


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


def test_the_loudest_passes_are_heard_predicted_and_recorded_on_one_scale(report, tmp_path):
    """--listen 2 with a station's archive holding the loudest pass's recording: two predicted
    files (the two loudest by predicted LpAFmax), the recording beside the loudest on the report's
    scale (its samples x the station's sensitivity / 20 Pa), none beside the other; a predicted
    file read back gives its pass-by level (its own line-source prediction within 0.15 dB)."""
    from scipy.io import wavfile

    from rail_monitor.core.friction import FRICTION_NAMES
    from rail_monitor.models.iso3095 import passby_levels
    from rail_monitor.report.listening import FULL_SCALE_PA, MARGIN_S, listening
    from rail_monitor.whatif.audio import pass_audio

    from conftest import write_pass_audio

    run, values, _, _ = report
    model = sorted(run.noise)[0]
    order = np.argsort(-run.noise[model]["lpafmax_dba"], kind="stable")
    keys = [(int(run.noise[model]["stamp_ns"][k]), str(run.noise[model]["train_id"][k])) for k in order[:2]]
    archive = tmp_path / "archive"
    write_pass_audio(archive, *keys[0], lead_s=1.0, seed=9)
    cfg = SiteConfig.from_values({**values, "station.sensitivity_pa_per_unit": 0.5})
    rows = listening(run, cfg, tmp_path / "out", 2, archive)
    assert [r["train"] for r in rows] == [k[1] for k in keys]
    assert rows[0]["measured"].endswith("_measured.wav") and rows[1]["measured"] == ""
    fs, recorded = wavfile.read(next(archive.glob("*.wav")))
    _, on_scale = wavfile.read(tmp_path / "out" / rows[0]["measured"])
    np.testing.assert_allclose(on_scale, (recorded * 0.5 / FULL_SCALE_PA).astype(np.float32), rtol=1e-6)
    # The predicted file is that pass's predicted audio (class, speed, consist, friction, angle of
    # attack) in pascals / 20 Pa: read back on that scale, the levels of the signal itself.
    fs, p = wavfile.read(tmp_path / "out" / rows[0]["predicted"])
    i = int(np.flatnonzero((run.passes.train_id == keys[0][1]) & (run.passes.stamp_ns == keys[0][0]))[0])
    want = pass_audio(values, str(run.passes.vehicle_class[i]), float(run.passes.speed_mps[i]),
                      int(run.passes.vehicle_count[i]) or None, FRICTION_NAMES[int(run.passes.friction_state[i])],
                      1e3 * float(run.passes.angle_of_attack_rad[i]), model, fs_hz=fs, margin_s=MARGIN_S, seed=0)
    window = (MARGIN_S, MARGIN_S + want.pass_time_s)
    heard = passby_levels(p.astype(float) * FULL_SCALE_PA, fs, *window)
    assert heard.lpaeq_tp_db == pytest.approx(passby_levels(want.pressure_pa, fs, *window).lpaeq_tp_db, abs=1e-3)


def test_a_modifier_mixed_in_from_the_first_day_is_compared_by_friction_state(tmp_path):
    """A quarter of the passes on the friction modifier from the first day (issue 55's new user):
    the report compares friction states (one row each, the modifier's predicted squeal 0 %, the
    other states' predicted cut within Eadie & Santoro's 6.3-22.8 dB(A)) and says so, with no
    'before' made of the passes ahead of the first modifier pass."""
    from rail_monitor.core.friction import FRICTION_MODIFIER, FRICTION_NAMES
    from rail_monitor.report import friction_modifier
    from rail_monitor.report.page import _headline_lines, headline
    from rail_monitor.site_file import load_parameter_file

    from conftest import SAMPLE

    values = load_parameter_file(SITE_FILE)
    passes = read_passes(SAMPLE).take(slice(0, 2000))
    passes.friction_state[1::4] = FRICTION_MODIFIER
    run = load_run(write_bag(run_models(passes, values), tmp_path / "bag", "curve_250"))
    cfg = SiteConfig.from_values(values)
    t = pass_table(run, cfg).as_dict()
    lim = report_tables.limits(cfg)
    rows = friction_modifier.by_state(t, lim)
    by = {r["friction state"]: r for r in rows}
    assert sorted(by) == sorted(set(t["friction_state"][t["status"] == "processed"].tolist()))
    assert by[FRICTION_NAMES[FRICTION_MODIFIER]]["squealing, predicted [%]"] == 0.0
    assert by[FRICTION_NAMES[FRICTION_MODIFIER]]["passes"] == int((passes.friction_state == FRICTION_MODIFIER).sum())
    for name, r in by.items():
        cut = r["friction-modifier cut, predicted, mean of squealing [dB(A)]"]
        assert name == FRICTION_NAMES[FRICTION_MODIFIER] or r["squealing, predicted [%]"] == 0.0 \
            or 6.3 <= cut <= 22.8, (name, cut)
    tables = {"friction": rows, "outlook": [], "noise": [], "classes": []}
    head = headline(run, t, lim, tables, cfg.site.time_zone)
    line = next(x for x in _headline_lines(head, lim) if x.startswith("Friction modifier"))
    assert "friction states compared (the bag holds no applicator start)" in line and "before" not in line
    assert "published: 6.3-22.8 dB(A)" in line


def test_measured_squeal_by_angle_of_attack_and_the_repeat_squealers_named():
    """The report's tables of measured against predicted squeal per angle-of-attack band (measured
    passes only, a rejected pass left out) and of the vehicles the repeat-squealer alert named."""
    from rail_monitor.alerts.config import KIND_SQUEAL_OFFENDER
    from rail_monitor.alerts.manager import Alert

    t = {"status": np.array(["processed"] * 5 + ["speed_mps not positive"]),
         "measured_squeal_detected": np.array([True, False, "", True, True, True], object),
         "squeal_risk": np.array(["medium", "none", "high", "low", "high", "high"]),
         "angle_of_attack_mrad": np.array([1.0, 1.5, 3.0, 3.5, 12.0, 12.0]),
         "stamp_ns": np.arange(6)}
    rows = report_tables.squeal_by_angle(t, {"squeal_min_risk": "medium"})
    assert rows == [{"angle of attack [mrad]": "0-2", "measured passes": 2, "squealing, predicted [%]": 50.0,
                     "squealing, measured [%]": 50.0},
                    {"angle of attack [mrad]": "2-4", "measured passes": 1, "squealing, predicted [%]": 0.0,
                     "squealing, measured [%]": 100.0},
                    {"angle of attack [mrad]": ">= 10", "measured passes": 1, "squealing, predicted [%]": 100.0,
                     "squealing, measured [%]": 100.0}]
    named = Alert(KIND_SQUEAL_OFFENDER, "vehicle V7", 1, True, "repeat squealer: vehicle V7 ...", 1e-7, 1e-5, "-",
                  10**18, 10**18, 0)
    cleared = Alert(KIND_SQUEAL_OFFENDER, "vehicle V9", 0, False, "cleared", 0.5, 0.01, "-", 10**18, 10**18, 0)
    assert [r["vehicle or train"] for r in report_tables.repeat_squealers([named, cleared], "UTC")] == ["vehicle V7"]


def test_the_squeal_models_fits_are_reported_from_the_bag(tmp_path):
    """A run whose measured squeal re-fits the squeal model (two weeks, weekly fits): the report's
    table gives each friction state's latest fit as the bag recorded it, and its figure plots every
    fit's P50 with the P10-P90 band and the configured curve, and how its windows' measured squeal
    shares stood against the shares predicted for them (issue 55)."""
    from rail_monitor.core.simulator_params import simulator_config
    from rail_monitor.core.site import site_from_values
    from rail_monitor.simulation.measurements import station_on_true_rail
    from rail_monitor.simulation.simulator import simulate
    from rail_monitor.site_file import load_parameter_file

    values = {**load_parameter_file(SITE_FILE), "simulator.days": 15.0}
    table = simulate(site_from_values(values), simulator_config(values)).sorted()
    station = station_on_true_rail(table, values, 1.0, 5, {"dry": (0.36, -0.030)})
    result = run_models(table, values, threads=1, measurements=station.measurements)
    assert len(result.calibrations) >= 2
    run = load_run(write_bag(result, tmp_path / "bag", "curve_250"))
    last = {code: q for code, _, q, _ in result.calibrations[-1].states}
    rows = {r["friction state"]: r for r in report_tables.squeal_fits(run.squeal_fits, "UTC")}
    assert rows["dry"]["k1 P10 / P50 / P90"] == " / ".join(f"{v:.4g}" for v in last[1].k1)
    assert rows["dry"]["measured passes"] == last[1].passes and rows["dry"]["k1 configured"] == 0.3
    assert len(run.squeal_fits["dry"]["stamp_ns"]) == len(result.calibrations)
    # The windows judged against the share predicted before each fit, as the bag carries them.
    windows = [w for c in result.calibrations for w in c.share_windows() if w[0] == "dry"]
    outside = sum(not lo <= k / n <= hi for _, n, k, lo, hi in windows)
    assert rows["dry"]["windows outside predicted P10-P90"] == f"{outside} of {len(windows)}"
    _, n, k, lo, hi = windows[-1]
    assert rows["dry"]["last window: measured / predicted [%]"] == f"{100 * k / n:.1f} / {100 * lo:.1f}-{100 * hi:.1f}"
    fig = report_plots.squeal_fits(run.squeal_fits, "UTC")
    assert [ax.get_ylabel() for ax in fig.axes] == ["friction peak k1 [-]", "falling slope k2 [-]"]
    files = build_report(run, SiteConfig.from_values(values), tmp_path / "report", "curve_250.yaml")
    page = next(f for f in files if f.name == "index.html").read_text()
    assert "The squeal model fitted to the measured squeal" in page and "squeal_fits" in page


def test_the_friction_modifier_is_compared_before_and_after_the_applicator_s_start(tmp_path):
    """A simulated site whose applicator starts on day 10 of 20 (85 % of dry passes on the modifier
    from then on), measured by a station on the true rail: the report compares every pass before
    the start with every pass after it, over all passes and over the dry rail's (wet and
    contaminated left out), and its shares and energy-mean levels are those recomputed here from the
    run's own arrays and the station's measurements (to 1e-9), over all passes of a side and over
    its loudest (as many as squealed before); in both groups the modifier cuts the predicted and the
    measured squeal share and the model's levels (measured here, dry rail: 9.9 % to 1.2 % predicted,
    12.0 % to 3.7 % heard, the loudest 9.9 % of passes 7.0 dB(A) quieter in the model; all passes:
    10.9 % to 4.8 %, 2.5 dB(A), as wet passes still squeal); the headline quotes the dry rail against
    Eadie & Santoro's range."""
    from rail_monitor.core.friction import FRICTION_DRY, FRICTION_MODIFIER
    from rail_monitor.core.simulator_params import simulator_config
    from rail_monitor.core.site import site_from_values
    from rail_monitor.report import friction_modifier
    from rail_monitor.report.page import _headline_lines, headline
    from rail_monitor.simulation.measurements import station_on_true_rail
    from rail_monitor.simulation.simulator import applicator_events, simulate
    from rail_monitor.site_file import load_parameter_file

    values = {**load_parameter_file(SITE_FILE), "simulator.days": 20.0, "simulator.friction_modifier_start_day": 10.0}
    cfg = simulator_config(values)
    table = simulate(site_from_values(values), cfg).sorted()
    station = station_on_true_rail(table, values, 1.0, 5)
    result = run_models(table, values, threads=1, measurements=station.measurements)
    events = applicator_events(cfg)
    run = load_run(write_bag(result, tmp_path / "bag", "curve_250", applicators=events))
    assert run.applicator == events
    site_cfg = SiteConfig.from_values(values)
    t, lim = pass_table(run, site_cfg).as_dict(), report_tables.limits(site_cfg)
    rows = friction_modifier.before_after(t, lim, run.applicator)
    assert [r["rail"] for r in rows] == [friction_modifier.RAILS[0]] * 3 + [friction_modifier.RAILS[1]] * 3

    start, acc = events[0].stamp_ns, result.accepted
    squeals = result.squeal["risk"] >= 2  # medium: the site's squeal_min_risk
    level = 10 * np.log10(10 ** (result.squeal["level_dba"] / 10) + 10 ** (site_cfg.squeal.background_level_dba / 10))
    by_key = {m.key: m for m in station.measurements}
    heard = [by_key.get((int(s), str(i))) for s, i in zip(acc.stamp_ns, acc.train_id, strict=True)]
    dry = np.isin(acc.friction_state, [FRICTION_DRY, FRICTION_MODIFIER])
    for (before, after, cut), group in ((rows[:3], np.ones(len(acc), bool)), (rows[3:], dry)):
        first = group & (acc.stamp_ns < start)
        for row, side in ((before, first), (after, group & (acc.stamp_ns > start))):
            mine = [m for m, on in zip(heard, side, strict=True) if on and m is not None]
            assert row["count"] == side.sum() > 600
            assert row["squealing, predicted [%]"] == pytest.approx(100 * squeals[side].mean(), abs=1e-9)
            assert row["squealing, measured [%]"] == pytest.approx(
                100 * np.mean([m.squeal_detected for m in mine]), abs=1e-9)
            assert row[friction_modifier.PREDICTED_LEVEL] == pytest.approx(
                10 * np.log10(np.mean(10 ** (level[side] / 10))), abs=1e-9)
            assert row[friction_modifier.MEASURED_LEVEL] == pytest.approx(
                10 * np.log10(np.mean([10 ** (m.lpafmax_dba / 10) for m in mine])), abs=1e-9)
            # the loudest: as many passes as the group's share predicted to squeal before the start
            for key, levels in ((friction_modifier.PREDICTED_LOUDEST, level[side]),
                                (friction_modifier.MEASURED_LOUDEST, np.array([m.lpafmax_dba for m in mine]))):
                top = np.sort(levels)[::-1][:round(squeals[first].mean() * len(levels))]
                assert row[key] == pytest.approx(10 * np.log10(np.mean(10 ** (top / 10))), abs=1e-9), key
        assert after["squealing, predicted [%]"] < before["squealing, predicted [%]"]
        assert after["squealing, measured [%]"] < before["squealing, measured [%]"]
        assert cut[friction_modifier.PREDICTED_LEVEL] > 0 and cut[friction_modifier.PREDICTED_LOUDEST] > 0
    before = rows[3]
    tables = {"friction": [], "applicator": rows, "outlook": [], "noise": [], "classes": []}
    line = next(x for x in _headline_lines(headline(run, t, lim, tables, "UTC"), lim)
                if x.startswith("Friction modifier"))
    assert "before and after the applicator's start" in line and "(top-of-rail friction modifier (simulated))" in line
    assert "on the dry rail (wet and contaminated passes left out" in line and "Over all passes:" in line
    assert f"{before['squealing, predicted [%]']:.1f} % of {before['count']} passes predicted to squeal" in line
    assert "published: 6.3-22.8 dB(A)" in line
