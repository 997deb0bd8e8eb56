"""The corrugation state of a site: identity, batch = one by one, forecast, surveys, grinding,
speed advice and checkpoints (rail_monitor.corrugation_state; MODELS.md section 2)."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.corrugation_state import (
    NS_PER_DAY,
    CorrugationEstimator,
    CorruptCheckpoint,
    GrowthTables,
    corrugation_config,
)
from rail_monitor.errors import ConfigError
from rail_monitor.passes import FRICTION_DRY, PassTable, rejection_reasons, with_class_defaults


@pytest.fixture(scope="module")
def site_():
    from rail_monitor.site import load_site

    from conftest import SITE_FILE

    return load_site(SITE_FILE)


@pytest.fixture(scope="module")
def tables(site_):
    """The default configuration's growth tables (shared: building them takes about 2 s)."""
    return GrowthTables(site_, corrugation_config({}))


def _estimator(site_, tables, **values) -> CorrugationEstimator:
    cfg = corrugation_config({f"corrugation.{k}": v for k, v in values.items()})
    return CorrugationEstimator(site_, cfg, tables if not values else None)


def _passes(site_, speeds, friction=FRICTION_DRY, start_s=0.0, step_s=600.0, prefix="T") -> PassTable:
    v = np.asarray(speeds, float)
    n = len(v)
    return with_class_defaults(PassTable(
        stamp_ns=(1_790_000_000 + start_s + np.arange(n) * step_s).astype(np.int64) * 10**9,
        train_id=[f"{prefix}{i}" for i in range(n)], vehicle_class=["emu"] * n, vehicle_count=[4] * n,
        axle_count=[0] * n, speed_mps=v, angle_of_attack_rad=[0.0] * n, wheel_load_n=[0.0] * n,
        friction_state=np.broadcast_to(friction, n), train_length_m=[0.0] * n), site_)


@pytest.fixture(scope="module")
def sample(site_, sample_passes):
    return with_class_defaults(sample_passes.take(rejection_reasons(sample_passes, site_) == ""), site_)


def test_batch_equals_one_by_one_and_replays_do_not_count_twice(site_, tables, sample):
    part = sample.take(slice(0, 400))
    batch, single = _estimator(site_, tables), _estimator(site_, tables)
    assert batch.advance(part).all()
    for i in range(len(part)):
        single.advance(part.take(slice(i, i + 1)))
    np.testing.assert_allclose(single.log_components, batch.log_components, rtol=0, atol=1e-12)
    assert (single.pass_count, single.axle_pass_count) == (batch.pass_count, batch.axle_pass_count) == (
        400, int(part.axle_count.sum()))
    # The same passes again, alone or inside a batch with new ones: only the new ones count.
    before = batch.log_components.copy()
    assert not batch.advance(part).any()
    np.testing.assert_array_equal(batch.log_components, before)
    more = sample.take(slice(380, 420))
    counted = batch.advance(more)
    assert counted.sum() == 20 and not counted[:20].any()
    # A pass older than the kept history is not counted either (it may have been, long ago).
    old = _passes(site_, [19.0], start_s=-400 * 86_400.0, prefix="OLD")
    assert not batch.advance(old).any()


def test_duplicates_inside_one_batch_count_once(site_, tables):
    p = _passes(site_, [19.0, 19.0])
    twice = p.take([0, 0, 1])
    est = _estimator(site_, tables)
    assert est.advance(twice).tolist() == [True, False, True] and est.pass_count == 2


def test_speed_spread_at_the_site_lowers_peak_growth_about_40_percent(site_, tables):
    # MODELS.md section 2 (generic UIC60, CV about 25 % cuts peak growth about 40 %): the site's
    # EMU on its UIC60 track at 20 m/s mean, dry rail, band-component peak. Measured 42 %; range 35-50 %.
    est = _estimator(site_, tables)
    peaks = []
    for cv in (0.0, 0.05, 0.1, 0.15, 0.2, 0.25):
        v = np.array([20.0]) if cv == 0 else np.linspace(20 * (1 - 3 * cv), 20 * (1 + 3 * cv), 121)
        w = np.exp(-0.5 * ((v - 20) / (20 * cv)) ** 2) if cv else np.ones(1)
        peaks.append(est.evaluate(v, w, FRICTION_DRY).peak_growth)
    assert np.all(np.diff(peaks) < 0), peaks
    assert 0.35 <= 1 - peaks[-1] / peaks[0] <= 0.50


def test_seed_like_speed_control_lengthens_the_grinding_interval_as_the_seed_reports(site_):
    # Seed section 2.1: on a suburban curve, re-spreading pass speeds at the same mean gave a
    # grinding interval x1.7 and grinding cost down up to 45 %. Scenario: one EMU class on dry rail
    # at 17 m/s with a narrow field spread (CV 5 %), advice allowed 11 m/s (the slowest passes lose
    # under 10 s over a 300 m section, the seed's "less than 20 s") to the 22.2 m/s line speed, at
    # most 20 % of trains per 0.5 m/s bin. Tested: interval x1.6-2.0, cost down 35-50 %.
    rng = np.random.default_rng(7)
    est = _estimator(site_, None, advice_min_speed_mps=11.0, advice_max_speed_mps=22.2)
    est.advance(_passes(site_, rng.normal(17.0, 0.85, 2000), step_s=900.0))
    advice = est.advise()
    assert 1.6 <= advice.grinding_interval_factor <= 2.0
    assert 0.35 <= 1 - 1 / advice.grinding_interval_factor <= 0.50
    p, v = advice.recommended_probability, advice.speed_bin_centres_mps
    assert p @ v == pytest.approx(advice.mean_speed_mps, rel=1e-9) and p.sum() == pytest.approx(1.0)
    assert v[p > 1e-9].min() >= 11.0 and v[p > 1e-9].max() <= 22.2 and p.max() <= 0.2 + 1e-9
    # The what-if service's view of the advice agrees with the advisory.
    check = est.evaluate(v, p)
    assert check.peak_growth == pytest.approx(advice.recommended_peak_growth, rel=1e-9)
    assert check.grinding_interval_factor == pytest.approx(advice.grinding_interval_factor, rel=1e-9)


def test_forecast_agrees_with_stepping_the_passes(site_, tables):
    # Independent method: the forecast number of passes, then advancing pass by pass at the same
    # speed and friction, crosses the threshold within one pass of the forecast.
    est = _estimator(site_, tables, min_traffic_days=0.0)  # 50 passes span 8 h
    est.advance(_passes(site_, [19.0] * 50, prefix="A"))
    fc = est.forecast()
    assert 0 < fc.passes_to_threshold < np.inf and not fc.grinding_due
    assert fc.passes_per_day == pytest.approx(49 / (49 * 600 / 86_400))
    assert fc.days_to_threshold == pytest.approx(fc.passes_to_threshold / fc.passes_per_day)
    n = int(np.floor(fc.passes_to_threshold))
    start = 50 * 600.0
    est.advance(_passes(site_, [19.0] * n, start_s=start, prefix="B"))
    worst = fc.worst_band
    assert est.amplitude[worst] < est.threshold[worst]
    est.advance(_passes(site_, [19.0], start_s=start + n * 600.0, prefix="C"))
    assert est.amplitude[worst] >= est.threshold[worst]
    assert est.forecast().grinding_due and est.forecast().days_to_threshold == 0.0


def test_no_forecast_in_days_until_the_passes_span_min_traffic_days(site_, tables):
    # 50 passes 10 min apart span 8.2 h: the daily timetable would bias a rate from them.
    est = _estimator(site_, tables)
    est.advance(_passes(site_, [19.0] * 50))
    fc = est.forecast()
    assert np.isnan(fc.passes_per_day) and fc.days_to_threshold == np.inf and not fc.grinding_due
    assert 0 < fc.passes_to_threshold < np.inf   # the forecast in passes does not need the rate
    est.advance(_passes(site_, [19.0] * 100, start_s=50 * 600.0, prefix="B"))  # now 25 h
    assert est.forecast().passes_per_day == pytest.approx(149 / (149 * 600 / 86_400))


def test_lead_time_makes_grinding_due_before_the_threshold(site_, tables):
    est = _estimator(site_, tables, min_traffic_days=0.0)
    est.advance(_passes(site_, [19.0] * 50))
    days = est.forecast().days_to_threshold
    assert not est.forecast().grinding_due
    near = _estimator(site_, None, lead_time_days=float(np.ceil(days)), min_traffic_days=0.0)
    near.advance(_passes(site_, [19.0] * 50))
    fc = near.forecast()
    assert fc.grinding_due and np.all(near.amplitude < near.threshold)
    assert fc.grinding_due_ns == near.newest_ns + int(fc.days_to_threshold * NS_PER_DAY)


def test_two_surveys_refit_k_b(site_, tables):
    # Truth: K_b twice the configured values. Surveys of the true rail before and after the same
    # passes let the estimator recover the factor (first order in K_b: within 1 %).
    truth = _estimator(site_, None, **{"k_b.dry": 2e-5, "k_b.wet": 1e-5, "k_b.friction_modifier": 6e-6,
                                       "k_b.contaminated": 4e-6})
    est = _estimator(site_, tables)
    rng = np.random.default_rng(1)
    passes = _passes(site_, rng.normal(19.0, 1.0, 3000), friction=rng.integers(1, 5, 3000))
    first = truth.amplitude.copy()
    assert est.apply_survey(est.bands, first) is None          # the first survey only sets the state
    truth.advance(passes)
    est.advance(passes)
    scale = est.apply_survey(est.bands, truth.amplitude)
    assert scale == pytest.approx(2.0, rel=0.01)
    np.testing.assert_allclose(est.k_b, truth.k_b, rtol=0.01)
    np.testing.assert_allclose(est.amplitude, truth.amplitude, rtol=1e-9)
    with pytest.raises(ValueError, match="no survey wavelength"):
        est.apply_survey([5.0], [1e-6])
    with pytest.raises(ValueError, match="positive"):
        est.apply_survey(est.bands, -first)


def test_grinding_resets_the_state(site_, tables):
    est = _estimator(site_, tables)
    est.advance(_passes(site_, [19.0] * 100))
    est.apply_grinding(123 * 10**9)
    np.testing.assert_allclose(est.amplitude, est.post_grinding, rtol=1e-12)
    assert (est.pass_count, est.axle_pass_count, est.total_pass_count, est.last_grinding_ns) == (0, 0, 100, 123 * 10**9)
    est.apply_grinding(124 * 10**9, est.bands[:3], [1e-7, 2e-7, 3e-7])
    np.testing.assert_allclose(est.amplitude[:3], [1e-7, 2e-7, 3e-7], rtol=1e-12)


def test_checkpoint_round_trip_and_refusals(site_, tables, tmp_path):
    est = _estimator(site_, tables)
    passes = _passes(site_, np.linspace(15, 21, 200))
    est.advance(passes.take(slice(0, 150)))
    est.apply_survey(est.bands, est.amplitude * 1.1)
    path = tmp_path / "state" / "corrugation.npz"
    est.save(path)
    assert [p.name for p in path.parent.iterdir()] == ["corrugation.npz"]   # no temporary left behind
    again = _estimator(site_, tables)
    again.load(path)
    np.testing.assert_array_equal(again.log_components, est.log_components)
    np.testing.assert_array_equal(again.k_b, est.k_b)
    assert again.total_pass_count == 150
    # Resumed: the passes already counted are recognised, the rest count.
    assert again.advance(passes).sum() == 50
    est.advance(passes)
    np.testing.assert_allclose(again.log_components, est.log_components, rtol=0, atol=1e-12)
    (tmp_path / "bad.npz").write_bytes(b"not a checkpoint")
    with pytest.raises(ConfigError, match="not a readable corrugation checkpoint"):
        again.load(tmp_path / "bad.npz")
    other = _estimator(site_, None, longest_wavelength_m=0.5)
    with pytest.raises(ConfigError, match="bands differ"):
        other.load(path)


def test_an_unreadable_checkpoint_falls_back_to_the_previous_one(site_, tables, tmp_path, tally):
    """Issue 8: a corrupt or truncated newest checkpoint is detected (zip CRCs, missing arrays) and
    the previous good one is resumed; with neither readable the estimator refuses, never zero."""
    est = _estimator(site_, tables)
    passes = _passes(site_, np.linspace(15, 21, 300))
    path = tmp_path / "corrugation.npz"
    est.advance(passes.take(slice(0, 100)))
    est.save(path)
    at_100 = est.log_components.copy()
    est.advance(passes.take(slice(100, 200)))
    est.save(path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["corrugation.npz", "corrugation.npz.prev"]
    newest = path.read_bytes()
    faults = {"truncated": newest[: len(newest) // 2], "zero-length": b"",
              "flipped byte": newest[:200] + bytes([newest[200] ^ 0xFF]) + newest[201:],
              "not a zip": b"PK\x03\x04" + b"\x00" * 64}
    for what, data in faults.items():
        path.write_bytes(data)
        again = _estimator(site_, tables)
        used, skipped = again.resume(path)
        assert used == tmp_path / "corrugation.npz.prev", what
        assert len(skipped) == 1 and str(path) in skipped[0] and "\n" not in skipped[0], what
        np.testing.assert_array_equal(again.log_components, at_100)
        assert again.total_pass_count == 100
        # replaying the history counts only what the fallback had not seen
        assert again.advance(passes.take(slice(0, 200))).sum() == 100, what
        np.testing.assert_array_equal(again.log_components, est.log_components)
    # a crash between save()'s two renames leaves only the previous file
    path.unlink()
    assert _estimator(site_, tables).resume(path)[0] == tmp_path / "corrugation.npz.prev"
    # both unreadable: refuse (one line), do not start from zero
    path.write_bytes(b"")
    (tmp_path / "corrugation.npz.prev").write_bytes(newest[:300])
    with pytest.raises(CorruptCheckpoint, match="no readable previous checkpoint") as err:
        _estimator(site_, tables).resume(path)
    assert "\n" not in str(err.value)
    assert _estimator(site_, tables).resume(tmp_path / "none.npz") == (None, [])
    tally("checkpoint", f"{len(faults)} corrupt newest checkpoints, both corrupt, crash between renames",
          "previous good state resumed; refusal when neither is readable", 0)


def test_the_sample_history_gives_a_plausible_forecast(site_, tables, sample):
    # 90 days of the bundled history (96 trains a day): the worst band is a 50-80 mm one and
    # grinding is a year or more away with the default K_b (a metro curve is ground every 1-3 years).
    est = _estimator(site_, tables)
    assert est.advance(sample).all()
    fc = est.forecast()
    assert 0.05 <= est.bands[fc.worst_band] <= 0.08
    assert 365 <= fc.days_to_threshold <= 3 * 365
    assert fc.passes_per_day == pytest.approx(96.2, rel=0.01)


def test_bad_configuration_is_refused():
    with pytest.raises(ConfigError, match="shortest_wavelength_m"):
        corrugation_config({"corrugation.shortest_wavelength_m": 2.0, "corrugation.longest_wavelength_m": 1.0})
    with pytest.raises(ConfigError, match=r"corrugation\.k_b\.dyr"):
        corrugation_config({"corrugation.k_b.dyr": 1e-5})


def test_predict_corrugation_command(tmp_path, site_, tables):
    import json

    from conftest import run_cmd

    png = tmp_path / "growth.png"
    out = run_cmd("rail-monitor", "predict", "corrugation", "--speed-mean", "17", "--speed-cv", "0.05",
                  "--passes-per-day", "100", "--advise", "--json", "--plot-growth", str(png))
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    est = _estimator(site_, tables)
    v = 17 * (1 + 0.05 * np.linspace(-3, 3, 121))
    want = est.evaluate(v, np.exp(-0.5 * ((v - 17) / 0.85) ** 2), FRICTION_DRY, 100.0)
    assert doc["peak_growth"] == pytest.approx(want.peak_growth, rel=1e-12)
    assert doc["days_to_threshold"] == pytest.approx(want.days_to_threshold, rel=1e-9)
    assert len(doc["bands"]) == len(est.bands) and doc["advice"]["grinding_interval_factor"] > 1.0
    assert png.stat().st_size > 10_000
    bad = tmp_path / "broken.mcap"
    bad.write_bytes(b"\x89MCAP0\r\n garbage")
    out = run_cmd("rail-monitor", "predict", "corrugation", "--history", str(bad))
    assert out.returncode == 2 and out.stderr.count("\n") == 1 and "Traceback" not in out.stderr


def test_running_forecast_sums_match_a_recount_after_pruning(site_, tables, sample):
    # The forecast keeps running sums over the kept passes (added per pass, removed as passes age
    # out of the history); they must equal a recount from the kept passes.
    est = _estimator(site_, tables)
    for chunk in range(0, 3000, 250):
        est.advance(sample.take(slice(chunk, chunk + 250)))
    assert len(est.recent.stamp_ns) < 3000                     # 90 days of history, 28 kept
    running = est.recent_growth().copy()
    est._resum()
    np.testing.assert_allclose(running, est.recent_growth(), rtol=1e-9, atol=1e-18)


def test_a_history_at_once_equals_the_states_published_pass_by_pass(site_, tables, sample):
    # corrugation_estimator takes a backlog at once (advance_history: prefix sums over the kept
    # passes); one pass at a time it publishes advance() then forecast(). Both must give the same
    # state and forecast after every pass, across the pruning horizon (history_days) too.
    warm, part = sample.take(slice(0, 300)), sample.take(slice(300, 1100))
    at_once, single = _estimator(site_, tables), _estimator(site_, tables)
    at_once.advance(warm)
    single.advance(warm)
    traj = at_once.advance_history(part)
    assert len(traj) == len(part)
    for k in range(len(part)):
        assert single.advance(part.take(slice(k, k + 1)))[0]
        snap, fc = traj.state(k)
        one = single.forecast()
        np.testing.assert_allclose(snap.amplitude, single.amplitude, rtol=1e-12)
        assert (snap.pass_count, snap.newest_ns, snap.newest_train_id) == (
            single.pass_count, single.newest_ns, single.newest_train_id)
        np.testing.assert_allclose(fc.growth_per_axle_pass, one.growth_per_axle_pass, rtol=1e-9, atol=1e-18)
        assert fc.days_to_threshold == pytest.approx(one.days_to_threshold, rel=1e-9)
        assert (fc.worst_band, fc.grinding_due) == (one.worst_band, one.grinding_due)
