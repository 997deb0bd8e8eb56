"""The last year's growth day by day and the forecast interval that follows it
(rail_monitor.corrugation.season, rail_monitor.corrugation.forecast)."""

from __future__ import annotations

import numpy as np
import pytest

from corrugation.conftest import _estimator, _passes
from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.corrugation.forecast import _seasonal_days
from rail_monitor.corrugation.season import SEASON_DAYS, DailyGrowth
from rail_monitor.models import corrugation_state as cstate

RNG = np.random.default_rng(6)


def _case(draws: int = 4, bands: int = 3, points: int = 5):
    state = np.log(1e-6) + RNG.normal(0.0, 0.3, (draws, bands, points))
    per_day = RNG.uniform(0.0, 2e-3, (bands, points))  # ln Z per day
    threshold = np.log(4e-6) * np.ones(bands)
    return state, per_day, threshold


def test_a_season_of_equal_days_gives_the_closed_form_forecast():
    # Every day the same growth: the day-by-day path with linear interpolation within a day must
    # equal the closed form (models.corrugation_state.passes_to_band_level, growth per day), to 1e-3 day.
    state, per_day, thr = _case()
    season = np.zeros((SEASON_DAYS, 4, *per_day.shape))
    season[:, 0] = 0.7 * per_day
    season[:, 2] = 0.3 * per_day
    got = _seasonal_days(state, np.ones((len(state), 4)), season, thr)
    want = cstate.passes_to_band_level(state, np.broadcast_to(per_day, state.shape), thr)
    assert np.all(want > 50) and np.any(want > SEASON_DAYS)  # crossings inside and beyond the season
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-3)
    # a friction state's draw scale multiplies its own growth only
    twice = _seasonal_days(state, np.array([[1.0, 1.0, 3.0 + 1 / 3, 1.0]] * len(state)), season, thr)
    np.testing.assert_allclose(twice, cstate.passes_to_band_level(state, np.broadcast_to(1.7 * per_day, state.shape),
                                                              thr), atol=1e-3)


def test_days_without_growth_delay_the_crossing_by_their_number():
    state, per_day, thr = _case()
    per_day = 8 * per_day
    season = np.zeros((SEASON_DAYS, 4, *per_day.shape))
    season[100:, 1] = per_day                          # 100 quiet days first (a line closure)
    got = _seasonal_days(state, np.ones((len(state), 4)), season, thr)
    closed = cstate.passes_to_band_level(state, np.broadcast_to(per_day, state.shape), thr)
    inside = closed < SEASON_DAYS - 100
    assert inside.any()
    np.testing.assert_allclose(got[inside], 100 + closed[inside], atol=1e-3)


def test_daily_growth_is_the_same_one_pass_at_a_time_and_keeps_one_year(site_, tables):
    one = _estimator(site_, tables)
    batch = _estimator(site_, tables)
    speeds = RNG.normal(19.0, 1.0, 1200)
    passes = _passes(site_, speeds, friction=RNG.integers(1, 5, 1200))
    passes.stamp_ns = passes.stamp_ns[0] + np.arange(len(passes), dtype=np.int64) * (NS_PER_DAY // 3)  # 400 days
    batch.advance(passes)
    for i in range(len(passes)):
        one.advance(passes.take(slice(i, i + 1)))
    np.testing.assert_array_equal(one.season.growth, batch.season.growth)
    np.testing.assert_array_equal(one.season.passes, batch.season.passes)
    assert len(batch.season.passes) == SEASON_DAYS + 1 and batch.season.passes.sum() <= len(passes)
    # growth per unit K_b: the day's sum over its passes' growth / K_b of their state
    day = int(passes.stamp_ns[-1] // NS_PER_DAY) - batch.season.first_day
    last = passes.take(passes.stamp_ns // NS_PER_DAY == passes.stamp_ns[-1] // NS_PER_DAY)
    fresh = _estimator(site_, tables)
    fresh.advance(last)
    np.testing.assert_allclose(np.einsum("fbp,f->bp", batch.season.growth[day], batch.k_b),
                               fresh.log_components - fresh.flat(fresh.post_grinding), rtol=1e-9, atol=1e-15)
    assert batch.forecast_interval().basis == "season"
    short = DailyGrowth(batch.log_components.shape)
    short.add(passes.stamp_ns[:600], passes.friction_state[:600], np.zeros((600, *batch.log_components.shape)),
              batch.k_b)
    assert short.profile(int(passes.stamp_ns[599])) is None  # 200 days: the recent window is used
    with pytest.raises(AssertionError):
        np.testing.assert_array_equal(batch.forecast_interval().days, _recent(batch).days)


def _recent(est):
    from rail_monitor.corrugation import forecast as fcst

    rate, axles = est.traffic()
    return fcst.interval(est.log_components, est.growth_by_state, est.recent_growth_by_state(), est.calibration,
                         est.level_cov, est.level_kb_cov, est.threshold, 1.0 / (rate * axles), est.newest_ns)


def test_the_daily_growth_survives_a_checkpoint(site_, tables, tmp_path):
    from rail_monitor.engine import checkpoint

    est = _estimator(site_, tables)
    passes = _passes(site_, RNG.normal(19.0, 1.0, 900), friction=RNG.integers(1, 5, 900))
    passes.stamp_ns = passes.stamp_ns[0] + np.arange(len(passes), dtype=np.int64) * (NS_PER_DAY // 2)
    est.advance(passes)
    checkpoint.save(est, tmp_path / "c.npz")
    back = _estimator(site_, tables)
    checkpoint.load(back, tmp_path / "c.npz")
    np.testing.assert_array_equal(back.season.growth, est.season.growth)
    assert (back.season.first_day, back.season.passes.tolist()) == (est.season.first_day, est.season.passes.tolist())
    np.testing.assert_array_equal(back.forecast_interval().days, est.forecast_interval().days)


def _managed_year(first_modified_day: int, days: int = SEASON_DAYS):
    """A year of daily growth per unit K_b (days, 4, 2, 3) with each state's growth per pass fixed:
    every day 20 passes on a dry or modified rail and 4 wet ones; before first_modified_day all 20
    dry, from it 3 dry and 17 under the modifier (a share of 0.85)."""
    per_pass = np.array([3.0, 1.0, 0.4, 0.2])[:, None, None] * np.array([[1.0, 2.0, 0.5], [0.3, 1.5, 1.0]]) * 1e-6
    passes = np.zeros((days, 4), np.int64)
    passes[:, 1] = 4
    passes[:, 0] = np.where(np.arange(days) < first_modified_day, 20, 3)
    passes[:, 2] = 20 - passes[:, 0]
    return passes[:, :, None, None] * per_pass, passes


def test_a_year_shared_as_its_own_days_is_unchanged():
    from rail_monitor.corrugation.season import managed_as_recent

    growth, passes = _managed_year(0)
    np.testing.assert_allclose(managed_as_recent(growth, passes, 0.85), growth, rtol=1e-12, atol=0)


def test_a_year_whose_applicator_started_within_it_is_shared_as_the_recent_passes():
    # Known answer: each state's growth per pass is the same every day, so the year in which the
    # modifier started on day 120, shared at the recent share (0.85), is the year with the modifier
    # from its first day, to rounding; and a recent share of 0 (the applicator stopped) gives the
    # all-dry year. Wet days are kept as they were.
    from rail_monitor.corrugation.season import managed_as_recent, modifier_share

    started, passes = _managed_year(120)
    always, _ = _managed_year(0)
    never, _ = _managed_year(SEASON_DAYS)
    np.testing.assert_allclose(managed_as_recent(started, passes, 0.85), always, rtol=1e-12, atol=0)
    np.testing.assert_allclose(managed_as_recent(started, passes, 0.0), never, rtol=1e-12, atol=0)
    assert modifier_share(np.array([1, 1, 1, 3, 2, 4, 3, 3, 3, 3])) == pytest.approx(5 / 8)
    assert modifier_share(np.array([2, 4])) is None


def test_the_forecast_follows_the_friction_management_of_the_recent_passes(site_, tables):
    # Two histories of the same 400 days of passes: one with the applicator on from the start, one
    # from day 120 (dry rail before it). The grinding cycle of the second (a rail ground now), its
    # season shared as its recent passes are, is within 5 % of the first's at P50; taken as it was
    # (the dry days repeated) it is shorter by more than that.
    rng = np.random.default_rng(11)
    n = 2400
    passes = _passes(site_, rng.normal(19.0, 1.0, n), friction=np.ones(n, np.int64))
    passes.stamp_ns = passes.stamp_ns[0] + np.arange(n, dtype=np.int64) * (NS_PER_DAY // 6)
    day = np.arange(n) // 6
    weather = rng.random(n)
    modified = rng.random(n) < 0.85
    always = np.where(weather < 0.15, 2, np.where(modified, 3, 1))
    late = np.where(day < 120, np.where(weather < 0.15, 2, 1), always)
    p50 = {}
    for name, friction in (("always", always), ("late", late)):
        est = _estimator(site_, tables)
        passes.friction_state = friction
        est.advance(passes)
        fc = est.forecast_interval(after_grinding=True)
        assert fc.basis == "season"
        p50[name] = fc.days[1]
        if name == "late":
            as_was = est.season.profile
            est.season.profile = lambda newest_ns, share=None, f=as_was: f(newest_ns)
            p50["as it was"] = est.forecast_interval(after_grinding=True).days[1]
    assert p50["late"] == pytest.approx(p50["always"], rel=0.05)
    assert p50["as it was"] < 0.95 * p50["always"]
