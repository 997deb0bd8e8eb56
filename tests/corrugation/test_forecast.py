"""The grinding forecast (rail_monitor.corrugation.forecast) against stepping the passes, the traffic
span, the lead time and the sample history."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from corrugation.conftest import _estimator, _passes
from rail_monitor.core.contact import REGIME_FULL_SLIDING
from rail_monitor.core.timeutil import NS_PER_DAY


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


def test_the_sample_history_gives_a_plausible_forecast(site_, tables, sample):
    # 90 days of the bundled history (96 trains a day). With every pass in partial slip (as the
    # UQ paper's K_b of order 1e-5 assumes; k3 = 1 N puts saturation far beyond any creepage) the
    # worst band is a 50-80 mm one and grinding is 1-3 years away with the default K_b (a metro
    # curve is ground every 1-3 years).
    partial = dataclasses.replace(site_, contact=dataclasses.replace(site_.contact, k3_n=1.0))
    est = _estimator(partial, tables)
    assert est.advance(sample).all()
    assert not est.kept.regime.any()
    fc = est.forecast()
    assert 0.05 <= est.bands[fc.worst_band] <= 0.08
    assert 365 <= fc.days_to_threshold <= 3 * 365
    assert fc.passes_per_day == pytest.approx(96.2, rel=0.01)
    # With the site's contact the passes whose creepage exceeds saturation fully slide, and their
    # negative K_b (docs/models.md, Sliding) takes growth off the 50-80 mm bands: the worst in the
    # 50-80 mm band, grinding later.
    real = _estimator(site_, tables)
    real.advance(sample)
    sliding = real.kept.regime == REGIME_FULL_SLIDING
    assert 0.1 < sliding.mean() < 0.6
    fc_real = real.forecast()
    assert 0.05 <= real.bands[fc_real.worst_band] <= 0.08
    assert fc_real.days_to_threshold > fc.days_to_threshold


def test_a_forecast_beyond_any_time_stamp_has_no_date():
    # A band that barely grows (full-sliding passes nearly balancing the others) can be 1e12 days
    # away: the days stay, the date is 0 ("never"), and nothing overflows a 64-bit stamp.
    from rail_monitor.corrugation.forecast import MAX_DATED_DAYS, forecasts

    log_z = np.full((1, 2, 3), np.log(1e-6))
    growth = np.full((1, 2, 3), 1e-18)
    fc = forecasts(log_z, growth, np.array([100.0]), np.array([20.0]), np.array([1_790_000_000 * 10**9]),
                   np.full(2, 1e-5), 60.0, 20.0)
    assert fc.days_to_threshold[0] > MAX_DATED_DAYS and np.isfinite(fc.days_to_threshold[0])
    assert fc.grinding_due_ns[0] == 0 and not fc.grinding_due[0]


def test_interval_collapses_to_the_forecast_without_uncertainty(site_, tables):
    # Independent method: with a posterior of (almost) no spread and levels known exactly, every
    # quantile is the deterministic forecast's days to threshold (within 1e-6 relative); with the
    # prior's spread, P10 < P50 < P90 around it.
    from rail_monitor.models import calibration

    est = _estimator(site_, tables)
    rng = np.random.default_rng(2)
    est.advance(_passes(site_, rng.normal(19.0, 1.0, 400), friction=rng.integers(1, 5, 400)))
    point = est.forecast().days_to_threshold
    wide = est.forecast_interval()
    assert wide.days[0] < point < wide.days[2]
    est.calibration = dataclasses.replace(est.calibration, cov=1e-18 * np.eye(4))
    est.level_cov = np.zeros((len(est.bands), len(est.bands)))
    narrow = est.forecast_interval()
    np.testing.assert_allclose(narrow.days, point, rtol=1e-6)
    from scipy.stats import norm

    assert norm.ppf(0.1) == pytest.approx(calibration.Z_P10, abs=1e-15)
