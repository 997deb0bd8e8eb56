"""Roughness surveys re-fit K_b, grinding resets the state (rail_monitor.corrugation.surveys)."""

from __future__ import annotations

import numpy as np
import pytest

from corrugation.conftest import _estimator, _passes
from rail_monitor.corrugation import surveys


def test_two_surveys_refit_k_b(site_, tables):
    # Truth: K_b twice the configured values. Surveys of the true rail before and after the same
    # passes let the estimator recover the factor (first order in K_b: within 1 %).
    truth = _estimator(site_, None, **{"k_b.dry": 2e-5, "k_b.wet": 1e-5, "k_b.friction_modifier": 6e-6,
                                       "k_b.contaminated": 4e-6})
    est = _estimator(site_, tables)
    rng = np.random.default_rng(1)
    passes = _passes(site_, rng.normal(19.0, 1.0, 3000), friction=rng.integers(1, 5, 3000))
    first = truth.amplitude.copy()
    assert surveys.apply_survey(est, est.bands, first) is None          # the first survey only sets the state
    truth.advance(passes)
    est.advance(passes)
    scale = surveys.apply_survey(est, est.bands, truth.amplitude)
    assert scale == pytest.approx(2.0, rel=0.01)
    np.testing.assert_allclose(est.k_b, truth.k_b, rtol=0.01)
    np.testing.assert_allclose(est.amplitude, truth.amplitude, rtol=1e-9)
    with pytest.raises(ValueError, match="no survey wavelength"):
        surveys.apply_survey(est, [5.0], [1e-6])
    with pytest.raises(ValueError, match="positive"):
        surveys.apply_survey(est, est.bands, -first)


def test_grinding_resets_the_state(site_, tables):
    est = _estimator(site_, tables)
    est.advance(_passes(site_, [19.0] * 100))
    surveys.apply_grinding(est, 123 * 10**9)
    np.testing.assert_allclose(est.amplitude, est.post_grinding, rtol=1e-12)
    assert (est.pass_count, est.axle_pass_count, est.total_pass_count, est.last_grinding_ns) == (0, 0, 100, 123 * 10**9)
    surveys.apply_grinding(est, 124 * 10**9, est.bands[:3], [1e-7, 2e-7, 3e-7])
    np.testing.assert_allclose(est.amplitude[:3], [1e-7, 2e-7, 3e-7], rtol=1e-12)
