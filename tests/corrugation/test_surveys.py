"""Roughness surveys re-fit K_b and update the level, grinding resets the state
(rail_monitor.corrugation.surveys)."""

from __future__ import annotations

import numpy as np
import pytest

from corrugation.conftest import _estimator, _passes
from rail_monitor.corrugation import surveys


def test_two_surveys_refit_k_b(site_, tables):
    # Truth: K_b twice the configured values. Exact surveys of the true rail before and after the
    # same passes (20,000, about 139 days) let the posterior recover the factor: within 2 % (the
    # first-order growth law and the prior's pull, at 1 dB survey uncertainty).
    truth = _estimator(site_, None, **{"k_b.dry": 2e-5, "k_b.wet": 1e-5, "k_b.friction_modifier": 6e-6,
                                       "k_b.contaminated": 4e-6})
    est = _estimator(site_, tables)
    rng = np.random.default_rng(1)
    passes = _passes(site_, rng.normal(19.0, 1.0, 20_000), friction=rng.integers(1, 5, 20_000))
    first = truth.amplitude.copy()
    assert surveys.apply_survey(est, est.bands, first) is None          # no growth since grinding: no fit
    truth.advance(passes)
    est.advance(passes)
    fit = surveys.apply_survey(est, est.bands, truth.amplitude)
    assert fit.fits == 1
    np.testing.assert_allclose(est.k_b, truth.k_b, rtol=0.02)
    np.testing.assert_allclose(fit.k_b(est.cfg.k_b), est.k_b, rtol=1e-12)
    p10, p90 = est.k_b_p10, est.k_b_p90
    assert np.all(p10 < est.k_b) and np.all(est.k_b < p90)
    # the model's prediction now fits: each level is the joint posterior's, which leaves a band about
    # half (its level variance over that plus the survey's) of what the fitted K_b's first-order
    # growth law does not explain; within 0.3 %
    np.testing.assert_allclose(est.amplitude, truth.amplitude, rtol=0.003)
    with pytest.raises(ValueError, match="no survey wavelength"):
        surveys.apply_survey(est, [5.0], [1e-6])
    with pytest.raises(ValueError, match="positive"):
        surveys.apply_survey(est, est.bands, -first)
    with pytest.raises(ValueError, match="not a roughness survey"):
        surveys.apply_survey(est, np.full(10**6, 0.05), np.full(10**6, 1e-6))


def test_survey_level_is_the_kalman_update(site_, tables):
    # With no growth since the last grinding, the prediction's variance is the post-grinding one
    # (3 dB) and the survey's 1 dB: the level moves 9/10 of the way to the measurement (in ln Z),
    # and its variance becomes 9/10 of the survey's (the Kalman gain; e.g. Gelb, Applied Optimal
    # Estimation, MIT Press 1974, ch. 4).
    est = _estimator(site_, tables)
    before = est.log_amplitude.copy()
    measured = est.amplitude * 2.0
    surveys.apply_survey(est, est.bands, measured)
    np.testing.assert_allclose(est.log_amplitude - before, 0.9 * np.log(2.0), rtol=1e-12)
    np.testing.assert_allclose(np.diag(est.level_cov), 0.9 * (np.log(10) / 20) ** 2, rtol=1e-12)
    assert not est.growth_by_state.any()


def test_growth_by_state_sums_to_the_state(site_, tables):
    # The growth split by friction state adds up to the state's growth, one by one or at once.
    rng = np.random.default_rng(3)
    passes = _passes(site_, rng.normal(19.0, 2.0, 300), friction=rng.integers(1, 5, 300))
    at_once, one_by_one = _estimator(site_, tables), _estimator(site_, tables)
    start = at_once.log_components.copy()
    at_once.advance(passes)
    for k in range(len(passes)):
        one_by_one.advance(passes.take(np.arange(len(passes)) == k))
    np.testing.assert_array_equal(at_once.growth_by_state, one_by_one.growth_by_state)
    np.testing.assert_allclose(start + at_once.growth_by_state.sum(axis=0), at_once.log_components, rtol=1e-12)


def test_grinding_resets_the_state(site_, tables):
    est = _estimator(site_, tables)
    est.advance(_passes(site_, [19.0] * 100))
    surveys.apply_grinding(est, 123 * 10**9)
    np.testing.assert_allclose(est.amplitude, est.post_grinding, rtol=1e-12)
    assert (est.pass_count, est.axle_pass_count, est.total_pass_count, est.last_grinding_ns) == (0, 0, 100, 123 * 10**9)
    surveys.apply_grinding(est, 124 * 10**9, est.bands[:3], [1e-7, 2e-7, 3e-7])
    np.testing.assert_allclose(est.amplitude[:3], [1e-7, 2e-7, 3e-7], rtol=1e-12)
    np.testing.assert_allclose(np.diag(est.level_cov)[:3], (np.log(10) / 20) ** 2, rtol=1e-12)
    np.testing.assert_allclose(np.diag(est.level_cov)[3:], (3 * np.log(10) / 20) ** 2, rtol=1e-12)


def test_events_apply_in_stamp_order_and_a_refused_one_changes_nothing(site_, tables):
    est = _estimator(site_, tables)
    est.advance(_passes(site_, np.full(50, 19.0)))
    before = (est.log_components.copy(), est.level_cov.copy(), est.level_kb_cov.copy(), est.survey_log_amplitude.copy(),
              est.last_survey_ns)
    bad_grinding = surveys.MaintenanceEvent(10**18, surveys.KIND_GRINDING, np.array([9.0]), np.array([1e-6]))
    for event, why in ((bad_grinding, "no survey wavelength"),
                       (surveys.MaintenanceEvent(10**18, 7, est.bands, est.post_grinding), "unknown kind")):
        with pytest.raises(ValueError, match=why):
            surveys.apply_event(est, event)
        after = (est.log_components, est.level_cov, est.level_kb_cov, est.survey_log_amplitude, est.last_survey_ns)
        for a, b in zip(before, after, strict=True):
            np.testing.assert_array_equal(a, b)
    surveys.apply_event(est, surveys.MaintenanceEvent(10**18, surveys.KIND_GRINDING, np.zeros(0), np.zeros(0)))
    with pytest.raises(ValueError, match="not newer"):
        surveys.apply_event(est, surveys.MaintenanceEvent(10**18, surveys.KIND_SURVEY, est.bands, est.post_grinding))
    # before the first pass stamped later: equal stamps come before the event, order as sent
    assert surveys.split_before(np.array([1, 5, 5, 9, 3]), 5) == 3
    assert surveys.split_before(np.array([1, 5]), 5) == 2 and surveys.split_before(np.array([], np.int64), 0) == 0
    assert [e.stamp_ns for e in surveys.in_time_order([bad_grinding, surveys.MaintenanceEvent(
        3, 1, est.bands, est.post_grinding)])] == [3, 10**18]
