"""The speed plan's linear programme (rail_monitor.advice.speed_plan) against brute force."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.advice.speed_plan import optimise_speed_plan, plan_growth


def _feasible(v, mean):
    """Every p = (t, 1 - t - q, q) with the mean speed, on a fine grid."""
    t = np.linspace(0, 1, 200_001)
    q = (mean - v[1] + (v[1] - v[0]) * t) / (v[2] - v[1])   # from v0 t + v1 (1 - t - q) + v2 q = mean
    p = np.stack([t, 1 - t - q, q], axis=1)
    return p[np.all(p >= 0, axis=1)]


def _scan(growth, v, mean, extra=None):
    """The least peak growth over the feasible p (and extra = (coef, bound): coef @ p <= bound)."""
    p = _feasible(v, mean)
    if extra is not None:
        p = p[p @ extra[0] <= extra[1]]
    return (p @ growth.T).max(axis=1).min()


def test_the_plan_is_the_minimax_of_a_brute_force_scan_with_and_without_a_further_limit():
    # One class, three bands, two equalities: one free parameter, scanned densely as the check.
    rng = np.random.default_rng(3)
    v = np.array([10.0, 15.0, 20.0])
    growth = rng.normal(1e-6, 5e-7, (12, 3))
    allowed = np.ones((1, 3), bool)
    best = optimise_speed_plan(growth[None], [1.0], v[None], allowed, [16.0], [1.0])
    assert best.peak_growth == pytest.approx(_scan(growth, v, 16.0), rel=1e-5)
    assert best.share[0] @ v == pytest.approx(16.0, rel=1e-9) and best.share.sum() == pytest.approx(1.0)
    assert best.growth == pytest.approx(plan_growth(growth[None], [1.0], best.share), rel=1e-12)
    # A limit the free optimum breaks (e.g. a noise level per band), halfway between the least
    # value any feasible plan reaches and the free optimum's.
    coef = np.array([80.0, 82.0, 86.0])
    reach = _feasible(v, 16.0) @ coef
    if best.share[0] @ coef - reach.min() < 0.1:
        coef, reach = -coef, -reach
    bound = 0.5 * (float(best.share[0] @ coef) + float(reach.min()))
    limited = optimise_speed_plan(growth[None], [1.0], v[None], allowed, [16.0], [1.0], [(coef[None], bound)])
    assert limited.share[0] @ coef <= bound + 1e-9
    assert limited.peak_growth == pytest.approx(_scan(growth, v, 16.0, (coef, bound)), rel=1e-5)
    assert limited.peak_growth >= best.peak_growth
    capped = optimise_speed_plan(growth[None], [1.0], v[None], allowed, [16.0], [0.4])
    assert capped.share.max() <= 0.4 + 1e-9 and capped.peak_growth >= best.peak_growth - 1e-15
    with pytest.raises(ValueError, match="speed plan"):
        optimise_speed_plan(growth[None], [1.0], v[None], allowed, [25.0], [1.0])


def test_classes_keep_their_own_means_and_bands_and_are_weighed_by_axles():
    rng = np.random.default_rng(5)
    g = rng.normal(1e-6, 5e-7, (2, 8, 4))
    v = np.array([[10.0, 12.0, 14.0, 16.0], [10.0, 12.0, 14.0, 16.0]])
    allowed = np.array([[True, True, True, True], [True, True, True, False]])
    plan = optimise_speed_plan(g, [0.7, 0.3], v, allowed, [13.0, 11.5], [1.0, 1.0])
    assert plan.share[1, 3] == 0.0
    np.testing.assert_allclose((plan.share * v).sum(axis=1), [13.0, 11.5], rtol=1e-9)
    np.testing.assert_allclose(plan.share.sum(axis=1), 1.0, rtol=1e-12)
    assert plan.peak_growth == pytest.approx(float((0.7 * g[0] @ plan.share[0] + 0.3 * g[1] @ plan.share[1]).max()))
