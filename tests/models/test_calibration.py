"""The Bayesian update of ln K_b from a survey (rail_monitor.models.calibration)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

from rail_monitor.models import calibration
from rail_monitor.models.corrugation_state import band_log_amplitude


def _case(seed: int):
    rng = np.random.default_rng(seed)
    start = np.log(1e-6 * rng.uniform(0.5, 2.0, (6, 5)))
    growth = rng.uniform(0.0, 0.6, (4, 6, 5)) * rng.uniform(0.2, 1.0, (4, 1, 1))
    truth = np.log([2.5, 3.0, 2.0, 3.5])
    measured = band_log_amplitude(start + np.einsum("f,fbp->bp", np.exp(truth), growth))
    return start, growth, measured + 0.05 * rng.standard_normal(6)


def _objective(post, start, growth, measured, sigma):
    p_inv = np.linalg.inv(post.cov)

    def f(delta):
        level = band_log_amplitude(start + np.einsum("f,fbp->bp", np.exp(delta), growth))
        r = (measured - level) / sigma
        return 0.5 * r @ r + 0.5 * delta @ p_inv @ delta
    return f


def test_update_is_the_posterior_mode_and_its_laplace_covariance():
    # Independent method: the same negative log posterior minimised by BFGS, its Hessian by central
    # differences. Mode within 1e-5, covariance within 1e-3 relative.
    start, growth, measured = _case(4)
    post = calibration.prior(1.0, 0.3)
    sigma = np.full(6, 0.05)
    fit, delta = calibration.update(post, start, growth, measured, sigma)
    f = _objective(post, start, growth, measured, sigma)
    ref = minimize(f, np.zeros(4), method="BFGS", options={"gtol": 1e-10})
    np.testing.assert_allclose(delta, ref.x, atol=1e-5)
    np.testing.assert_allclose(fit.mean, post.mean + delta)
    h, eye = 1e-4, np.eye(4)
    hess = np.array([[(f(delta + h * (eye[i] + eye[j])) - f(delta + h * (eye[i] - eye[j]))
                       - f(delta - h * (eye[i] - eye[j])) + f(delta - h * (eye[i] + eye[j]))) / (4 * h * h)
                      for j in range(4)] for i in range(4)])
    np.testing.assert_allclose(fit.cov, np.linalg.inv(hess), rtol=1e-3)


def test_wide_prior_and_exact_data_recover_the_truth():
    # Noise-free data and a prior 100x wider than the data's information: the mode is the truth
    # to 1e-6 (no other value explains the data).
    start, growth, _ = _case(5)
    truth = np.log([2.5, 3.0, 2.0, 3.5])
    measured = band_log_amplitude(start + np.einsum("f,fbp->bp", np.exp(truth), growth))
    fit, _ = calibration.update(calibration.prior(100.0, 100.0), start, growth, measured, 1e-4)
    np.testing.assert_allclose(fit.mean, truth, atol=1e-6)


def test_prior_quantiles():
    # The prior's marginal sd is sqrt(s^2 + r^2); P10/P90 are exp(-+1.2816 sd) of the default.
    post = calibration.prior(1.0, 0.3)
    sd = np.sqrt(1.09)
    p10, p50, p90 = post.quantiles(np.full(4, 1e-5))
    np.testing.assert_allclose(p50, 1e-5)
    np.testing.assert_allclose(p10, 1e-5 * np.exp(-1.2815515655446004 * sd), rtol=1e-12)
    np.testing.assert_allclose(p90 * p10, 1e-10, rtol=1e-12)
