"""The squeal model's prediction of a window's measured squeal share, to check the model against
the station (no rclpy).

Before a fit takes a window's measured passes of a friction state, the posterior it had (the one
the squeal model predicted those passes on) gives each pass i, at each grid cell c, the chance
p_ic that the station flags it squealing (squeal.calibration: the model's level against the
risk threshold, with the station's own flag error). Given c, the count K of flagged passes is a
sum of independent Bernoulli trials (Poisson binomial), with mean mu_c = sum_i p_ic and variance
v_c = sum_i p_ic (1 - p_ic). Its predictive distribution is the posterior mixture over cells,

    P(K <= k) = sum_c w_c Phi((k - mu_c) / sqrt(v_c)),

each cell's Poisson binomial taken as normal (Lyapunov's central limit theorem: the p_ic lie in
[e, 1 - e] with e the flag error, so v_c grows with the passes). The quantiles of K / n are the
predicted share's P10/P50/P90: they hold both the curve's uncertainty and the window's sampling
scatter, so a right model leaves a window's measured share outside its P10-P90 one window in five,
and outside on the same side three windows running one time in 500.

References
----------
.. [1] Y. H. Wang, "On the number of successes in independent trials", Statistica Sinica 3 (1993)
   295-312: the Poisson binomial distribution, its mean and variance, and its normal
   approximation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr

CDF_POINTS = 401  # the share's mixture CDF evaluated at this many points over [0, 1]


@dataclass(frozen=True)
class ShareCheck:
    """One friction state's measured passes taken by a fit: how many, how many flagged squealing,
    and the share of them the model predicted flagged (P10, P50, P90) [-] before it took them."""

    passes: int
    squealed: int
    predicted: tuple[float, float, float]

    @property
    def share(self) -> float:
        """The measured share flagged squealing [-]."""
        return self.squealed / self.passes


def share_quantiles(weights: np.ndarray, mean: np.ndarray, var: np.ndarray, passes: int,
                    q: tuple[float, ...] = (0.1, 0.5, 0.9)) -> tuple[float, ...]:
    """Quantiles q of the predicted share of ``passes`` passes flagged squealing [-].

    Parameters
    ----------
    weights : numpy.ndarray
        The posterior's weight of each grid cell [-], summing to 1.
    mean, var : numpy.ndarray
        Per cell (the shape of weights), the mean and variance of the count flagged [-]: the sums
        of p and p (1 - p) over the passes.
    passes : int
        The passes counted, n >= 1 [-].
    q : tuple of float
        The quantiles wanted, in (0, 1).

    Returns
    -------
    tuple of float
        The quantiles of K / n under the normal mixture of the module docstring [-], within [0, 1].
    """
    w, mu, sd = (np.ravel(x) for x in (weights, mean, np.sqrt(var)))
    x = np.linspace(0.0, 1.0, CDF_POINTS)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (x[:, None] * passes - mu[None, :]) / sd[None, :]
    cdf = np.where(np.isnan(z), (x[:, None] * passes >= mu[None, :]).astype(float), ndtr(z)) @ w
    cdf = np.maximum.accumulate(np.clip(cdf, 0.0, 1.0))
    # The inverse CDF on the points (a flat stretch takes its first point).
    return tuple(float(x[min(int(np.searchsorted(cdf, p)), CDF_POINTS - 1)]) for p in q)
