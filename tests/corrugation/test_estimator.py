"""The corrugation state: passes counted once, a batch equal to one pass at a time, the kept history
(rail_monitor.corrugation.estimator)."""

from __future__ import annotations

import numpy as np
import pytest

from corrugation.conftest import _estimator, _passes


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


@pytest.mark.parametrize("in_order", [True, False])
def test_a_batch_a_model_fails_on_leaves_its_passes_to_count(site_, tables, sample, in_order, monkeypatch):
    # The node retries a failed batch pass by pass: the failed attempt must not have marked them seen.
    est = _estimator(site_, tables)
    part = sample.take(slice(0, 30) if in_order else [*range(15, 30), *range(15)])
    with monkeypatch.context() as m:
        m.setattr(est, "_growth", lambda *a: 1 / 0)
        with pytest.raises(ZeroDivisionError):
            est.advance(part)
    assert est.advance(part).all() and est.pass_count == 30


def test_running_forecast_sums_match_a_recount_after_pruning(site_, tables, sample):
    # The forecast keeps running sums over the kept passes (added per pass, removed as passes age
    # out of the history); they must equal a recount from the kept passes.
    est = _estimator(site_, tables)
    for chunk in range(0, 3000, 250):
        est.advance(sample.take(slice(chunk, chunk + 250)))
    assert len(est.kept.stamp_ns) < 3000                     # 90 days of history, 28 kept
    running = est.recent_growth().copy()
    est.resum()
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


def test_the_compiled_engine_keeps_the_numpy_engines_state(site_, tables, sample):
    # Batch mode's engine (numba: models.corrugation_jit) against the live nodes' (numpy), over a
    # history in chunks with a replayed stretch: the sums (additions in the same order) bit for
    # bit; the band r.m.s. and forecast to the last bits of exp and log and the Newton stop.
    engines = {e: _estimator(site_, tables) for e in ("numpy", "numba")}
    trajs = {}
    for engine, est in engines.items():
        est.engine = engine
        trajs[engine] = [est.advance_history(sample.take(s)) for s in (slice(0, 700), slice(650, 1500))]
    want, got = engines["numpy"], engines["numba"]
    for name in ("log_components", "growth_by_state", "_growth_before", "_growth_total"):
        assert np.array_equal(getattr(want, name), getattr(got, name)), name
    assert np.array_equal(want.season.growth, got.season.growth) and np.abs(got.season.growth).sum() > 0
    for w, g in zip(trajs["numpy"], trajs["numba"], strict=True):
        assert np.array_equal(w.index, g.index)
        np.testing.assert_allclose(g.amplitude, w.amplitude, rtol=1e-13)
        assert np.array_equal(g.forecast.growth_per_axle_pass, w.forecast.growth_per_axle_pass)
        np.testing.assert_allclose(g.forecast.days_to_threshold, w.forecast.days_to_threshold, rtol=1e-11)
