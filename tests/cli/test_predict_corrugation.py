"""rail-monitor predict corrugation as a user runs it (rail_monitor.cli.predict_corrugation), in-process."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rail_monitor.advice import growth as advice
from rail_monitor.cli import main
from rail_monitor.core.passes import FRICTION_DRY
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator


def test_predict_corrugation_json_equals_the_library_and_plots(tmp_path, site, capsys):
    png = tmp_path / "growth.png"
    assert main(["predict", "corrugation", "--speed-mean", "17", "--speed-cv", "0.05", "--passes-per-day", "100",
                 "--json", "--plot-growth", str(png)]) == 0
    doc = json.loads(capsys.readouterr().out)
    est = CorrugationEstimator(site, corrugation_config({}))
    v = 17 * (1 + 0.05 * np.linspace(-3, 3, 121))
    want = advice.evaluate(est, v, np.exp(-0.5 * ((v - 17) / 0.85) ** 2), FRICTION_DRY, 100.0)
    assert doc["peak_growth"] == pytest.approx(want.peak_growth, rel=1e-12)
    assert doc["days_to_threshold"] == pytest.approx(want.days_to_threshold, rel=1e-9)
    assert len(doc["bands"]) == len(est.bands)
    # Without --history: the site's traffic mix for the kernel, and its traffic-weighted axles per train.
    assert doc["kernel_vehicle_class"] is None and doc["axles_per_train"] == pytest.approx(site.mean_axles_per_train)
    assert png.stat().st_size > 10_000


def test_a_class_without_history_uses_its_own_kernel_and_axles(site, capsys):
    assert main(["predict", "corrugation", "--vehicle-class", "freight", "--passes-per-day", "10", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    est = CorrugationEstimator(site, corrugation_config({}))
    cls = site.vehicle("freight")
    v = cls.speed_mean_mps * (1 + cls.speed_sd_mps / cls.speed_mean_mps * np.linspace(-3, 3, 121))
    w = np.exp(-0.5 * ((v - cls.speed_mean_mps) / cls.speed_sd_mps) ** 2)
    want = advice.evaluate(est, v, w, FRICTION_DRY, 10.0, "freight")
    mix = advice.evaluate(est, v, w, FRICTION_DRY, 10.0)
    assert doc["kernel_vehicle_class"] == "freight" and doc["axles_per_train"] == cls.mean_axles_per_train
    assert doc["peak_growth"] == pytest.approx(want.peak_growth, rel=1e-12) and want.peak_growth != mix.peak_growth
    assert doc["days_to_threshold"] == pytest.approx(want.days_to_threshold, rel=1e-9)
    # The traffic-weighted mean axles per train of the site (80 % EMU of 4.5 cars: 22.8), not the
    # classes' plain mean (39.3).
    assert site.mean_axles_per_train == pytest.approx(
        sum(c.traffic_share * c.mean_axles_per_train for c in site.vehicles.values())
        / sum(c.traffic_share for c in site.vehicles.values()))


def test_advice_is_per_class_on_a_history(capsys):
    from conftest import SAMPLE

    assert main(["predict", "corrugation", "--history", str(SAMPLE), "--advise", "--json"]) == 0
    adv = json.loads(capsys.readouterr().out)["advice"]
    assert adv["vehicle_class"] == ["emu", "dmu", "freight"] and len(adv["summary"]) == 4
    assert adv["grinding_interval_factor"] >= 1.0
    assert max(n - c for n, c in zip(adv["noise_recommended_dba"], adv["noise_current_dba"], strict=True)) <= 0.5


def test_a_bare_distribution_is_advised_as_a_history_of_its_passes(tmp_path, site_values, capsys):
    """Issue 57: the paper's scenario asked directly (a mean and a CV, no history) goes through the same
    optimiser: its advice is the advice on a bag of the 2,000 passes standing for it, field for field."""
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.whatif.corrugation import distribution_passes, speed_distribution

    bare = ["predict", "corrugation", "--vehicle-class", "emu", "--speed-mean", "17", "--speed-cv", "0.05",
            "--passes-per-day", "100", "--advise", "--json"]
    assert main(bare) == 0
    a = json.loads(capsys.readouterr().out)["advice"]
    passes = distribution_passes(site_values, "emu", *speed_distribution(17.0, 0.05), FRICTION_DRY)
    write_passes_bag(passes, tmp_path / "passes", "curve_250")
    assert main(["predict", "corrugation", "--history", str(tmp_path / "passes"), "--advise", "--json"]) == 0
    b = json.loads(capsys.readouterr().out)["advice"]
    assert a == b and a["vehicle_class"] == ["emu"] and a["grinding_interval_factor"] > 1.0


def test_the_papers_scenario_asked_directly_lengthens_the_grinding_interval(tmp_path, capsys):
    """The UQ paper's section 2.1 (a suburban curve: re-spread speeds at the same mean, interval about
    x1.7, grinding cost down up to 45 %) with the advice of tests/advice/test_plan.py (11 to 22.2 m/s,
    1.8 km/h bands, at most 20 % a band), now from the command line on a bare distribution: interval
    x1.4-2.0, as there."""
    site = tmp_path / "paper.yaml"
    assert main(["site", str(site), "--set", "corrugation.advice_min_speed_mps=11.0", "--set",
                 "corrugation.advice_max_speed_mps=22.2", "--set", "corrugation.advice_band_kmh=1.8", "--set",
                 "corrugation.advice_max_share=0.2"]) == 0
    capsys.readouterr()
    assert main(["predict", "corrugation", "--site", str(site), "--vehicle-class", "emu", "--speed-mean", "17",
                 "--speed-cv", "0.05", "--advise", "--json"]) == 0
    a = json.loads(capsys.readouterr().out)["advice"]
    assert 1.4 <= a["grinding_interval_factor"] <= 2.0, a["grinding_interval_factor"]
    png = tmp_path / "cost.png"
    assert main(["predict", "corrugation", "--site", str(site), "--vehicle-class", "emu", "--speed-mean", "17",
                 "--speed-cv", "0.05", "--advise", "--plot-cost", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"   # the paper's Figure 2 in shape
    assert main(["predict", "corrugation", "--site", str(site), "--plot-cost", str(png)]) == 2
    assert "--plot-cost compares current and advised speeds" in capsys.readouterr().err


def test_an_unreadable_history_is_one_line_and_exit_2(tmp_path, capsys):
    bad = tmp_path / "broken.mcap"
    bad.write_bytes(b"\x89MCAP0\r\n garbage")
    assert main(["predict", "corrugation", "--history", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and str(bad) in err


def test_a_table_without_json(capsys):
    assert main(["predict", "corrugation", "--speeds", "15", "17", "19", "--weights", "1", "2", "1"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("# site curve_250, post-grinding rail, dry") and out[-1].startswith("peak g ")


def test_a_history_s_surveys_refit_k_b_and_give_the_forecast_interval(tmp_path, site, site_values, capsys):
    """The surveys in a history bag are applied in stamp order (as an estimator advanced and surveyed
    by hand), and the forecast comes with its P10/P50/P90 interval and K_b's."""
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.bagio.reader import read_bag_passes
    from rail_monitor.core.passes import rejection_reasons, with_class_defaults
    from rail_monitor.corrugation import surveys

    from conftest import SAMPLE

    passes = read_bag_passes(SAMPLE).sorted().take(slice(0, 4000))
    est = CorrugationEstimator(site, corrugation_config(site_values))
    at = int(passes.stamp_ns[2500]) + 1
    event = surveys.MaintenanceEvent(at, surveys.KIND_SURVEY, est.bands, 1.3 * est.post_grinding)
    bag = write_passes_bag(passes, tmp_path / "h", "curve_250", events=[event])
    assert main(["predict", "corrugation", "--history", str(bag), "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    ok = with_class_defaults(passes.take(rejection_reasons(passes, site) == ""), site)
    n = int(np.argmax(ok.stamp_ns > at))
    est.advance(ok.take(slice(0, n)))
    surveys.apply_survey(est, event.wavelength_m, event.amplitude_m, at)
    est.advance(ok.take(slice(n, None)))
    assert got["calibration_surveys"] == 1 and got["surveys_and_grinding"] == 1
    np.testing.assert_allclose(got["k_b_by_friction"], est.k_b, rtol=1e-12)
    assert np.all(np.array(got["k_b_p10_by_friction"]) < est.k_b) and np.all(est.k_b < got["k_b_p90_by_friction"])
    iv = est.forecast_interval()
    np.testing.assert_allclose(got["forecast_interval"]["days_to_threshold_p10_p50_p90"], iv.days, rtol=1e-12)
    p10, p50, p90 = iv.days
    assert p10 < p50 < p90
    assert all(len(b["days_to_threshold_p10_p50_p90"]) == 3 for b in got["bands"])
    assert main(["predict", "corrugation", "--history", str(bag)]) == 0
    assert "(P10 / P50 / P90:" in capsys.readouterr().out
