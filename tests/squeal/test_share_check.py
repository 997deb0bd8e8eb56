"""The predicted share of a window's passes flagged squealing (rail_monitor.squeal.share_check,
issue 55): its quantiles against the exact Poisson binomial (an independent method: the
distribution built by convolution, pass by pass), and a right model's windows inside its P10-P90
as often as a P10-P90 should be."""

from __future__ import annotations

import numpy as np

from rail_monitor.squeal.share_check import CDF_POINTS, share_quantiles

Q = (0.1, 0.5, 0.9)


def _poisson_binomial(p: np.ndarray) -> np.ndarray:
    """P(K = k), k = 0..n, for independent trials of chances p (exact, by convolution)."""
    pmf = np.array([1.0])
    for pi in p:
        pmf = np.convolve(pmf, [1.0 - pi, pi])
    return pmf


def _exact_quantiles(weights: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Quantiles Q of K / n under the mixture over cells (rows of p) with the weights: the least
    k / n whose CDF reaches q."""
    cdf = np.cumsum(sum(w * _poisson_binomial(row) for w, row in zip(weights, p, strict=True)))
    n = p.shape[1]
    return np.array([np.searchsorted(cdf, q) / n for q in Q])


def _moments(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return p.sum(axis=1), (p * (1.0 - p)).sum(axis=1)


def test_one_cell_matches_the_exact_poisson_binomial():
    """One curve (no parameter uncertainty), 200 passes whose chances of a flag run from the flag
    error 0.05 to 0.95: the normal approximation's P10/P50/P90 of the share are within 1.5 passes
    of the exact distribution's (Wang 1993: the Poisson binomial's normal limit), plus the CDF grid's
    step."""
    rng = np.random.default_rng(3)
    p = rng.uniform(0.05, 0.95, (1, 200))
    got = np.array(share_quantiles(np.ones(1), *_moments(p), 200, Q))
    want = _exact_quantiles(np.ones(1), p)
    np.testing.assert_allclose(got, want, atol=1.5 / 200 + 1.0 / (CDF_POINTS - 1))


def test_a_two_curve_posterior_is_their_mixture():
    """Two cells weighted 0.3 and 0.7 whose shares differ by far more than the sampling scatter
    (about 0.15 and 0.45 of 300 passes): the mixture's quantiles match the exact mixture's, and the
    P10 lies with the first curve, the P50 and P90 with the second."""
    rng = np.random.default_rng(4)
    p = np.vstack([rng.uniform(0.05, 0.25, 300), rng.uniform(0.35, 0.55, 300)])
    w = np.array([0.3, 0.7])
    got = np.array(share_quantiles(w, *_moments(p), 300, Q))
    np.testing.assert_allclose(got, _exact_quantiles(w, p), atol=1.5 / 300 + 1.0 / (CDF_POINTS - 1))
    assert got[0] < 0.25 < 0.35 < got[1] < got[2]


def test_a_right_model_leaves_a_fifth_of_its_windows_outside_its_p10_p90():
    """600 windows of 40 to 400 passes whose flags are drawn from the model's own chances: the
    measured share is below P10 in 10 % of them and above P90 in 10 % (by the binomial law of 600
    windows, each side within 10 +- 3.7 % at three standard deviations), whatever the window's
    size."""
    rng = np.random.default_rng(5)
    below = above = 0
    windows = 600
    for _ in range(windows):
        n = int(rng.integers(40, 400))
        p = rng.uniform(0.02, 0.6) * rng.uniform(0.2, 1.0, (1, n))
        k = int((rng.random(n) < p[0]).sum())
        lo, _, hi = share_quantiles(np.ones(1), *_moments(p), n, Q)
        below += k / n < lo
        above += k / n > hi
    sd = 3.0 * np.sqrt(0.1 * 0.9 / windows)
    assert abs(below / windows - 0.1) <= sd and abs(above / windows - 0.1) <= sd, (below, above)
