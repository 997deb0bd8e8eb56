"""Calibration of the wear coefficient K_b from roughness surveys: a Bayesian update in ln K_b.

The unknowns are u_f = ln(K_b,f / K_b,f default) for the four friction states. The prior is
Gaussian with covariance s^2 (1 1^T) + r^2 I: a common scale that is known to an order of
magnitude (s) and ratios between friction states that the wear model fixes more closely (r), so a
survey that constrains mostly the sum of the growth still moves every state's K_b.

A survey at t2 measures y_b = ln Z_b(t2) per band b. Since the last survey or grinding (t1) the
state's components grew by G_f (friction state f, computed at the K_b in use); since
ln|1 + K_b F^2 H| = K_b F^2 H to first order (K_b F^2 H is about 1e-6 per axle pass), changing u
by delta scales G_f by exp(delta_f), so the model's band level is

    yhat_b(delta) = ln sqrt(sum_p exp(2 (C_bp + sum_f exp(delta_f) G_f,bp)))

with C the components at t1 (UQ seminar paper eqs. 1-2; the band r.m.s. is the energy sum of its
components). C itself is known only to the state's uncertainty at t1, which the earlier surveys
left correlated with u: the unknowns of a survey are therefore z = (a, delta), a_b the error of
band b's level at t1 (C_b shifted by a_b moves yhat_b by a_b exactly), with the joint Gaussian
prior the last survey left. The posterior mode maximises the Gaussian likelihood of the measured
bands (the survey's variance per band) times that prior, found by Gauss-Newton; its Laplace
covariance is the inverse Hessian of the negative log posterior at the mode (H^T W H + P^-1 less
the residuals' curvature in delta; e.g. Gelman et al., Bayesian Data Analysis, 3rd ed., CRC 2013,
sec. 4.1 and 13.3). The levels after the survey (a + yhat(delta)) and u are carried forward with
their joint covariance, so each survey's posterior is the next one's prior: the state augmented
with the parameter, as an iterated extended Kalman filter (Gelb, Applied Optimal Estimation, MIT
Press 1974, sec. 6.1 and 9.2). Had the levels been carried without their correlation with u, each
survey would weigh only its own growth against two noisy levels, and a rail surveyed often would
keep a K_b posterior several times wider than its surveys support.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rail_monitor.models import corrugation_state as cstate

LN_PER_DB = np.log(10.0) / 20.0  # ln Z per dB of a roughness level (20 lg Z)
Z_P10 = -1.2815515655446004      # standard normal 10 % quantile
_MAX_ITERATIONS = 50
_STEP_TOLERANCE = 1e-12


@dataclass(frozen=True)
class KbPosterior:
    """Normal distribution of u = ln(K_b / K_b default) per friction state: mean (4,), covariance
    (4, 4), and the surveys it has taken."""

    mean: np.ndarray
    cov: np.ndarray
    fits: int = 0

    def k_b(self, default: np.ndarray, z: float = 0.0) -> np.ndarray:
        """K_b per friction state [-/axle pass] at the standard normal quantile z of each state's
        marginal (z = 0: the posterior median, the K_b in use)."""
        return np.asarray(default, float) * np.exp(self.mean + z * np.sqrt(np.diag(self.cov)))

    def quantiles(self, default: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """K_b per friction state at P10, P50 and P90 [-/axle pass]."""
        return self.k_b(default, Z_P10), self.k_b(default), self.k_b(default, -Z_P10)


def prior(scale_sd: float, ratio_sd: float, states: int = 4) -> KbPosterior:
    """The prior of u = ln(K_b / K_b default): u ~ N(0, scale_sd^2 1 1^T + ratio_sd^2 I).

    Parameters
    ----------
    scale_sd : float
        Standard deviation of the common scale of ln K_b [-].
    ratio_sd : float
        Standard deviation of each state's ratio to the others, in ln K_b [-].
    states : int
        Friction states [-].

    Returns
    -------
    KbPosterior
        Mean 0 and that covariance, no survey taken.

    References
    ----------
    .. [1] A. Gelman, J. B. Carlin, H. S. Stern, D. B. Dunson, A. Vehtari and D. B. Rubin, *Bayesian
       Data Analysis*, 3rd ed., CRC Press, Boca Raton, 2013, section 3.5 (the multivariate normal prior).
    """
    cov = scale_sd**2 * np.ones((states, states)) + ratio_sd**2 * np.eye(states)
    return KbPosterior(np.zeros(states), cov, 0)


def log_variance(sd_db: float) -> float:
    """Variance of ln Z of a level known to sd_db (one standard deviation).

    A level of 20 lg Z known to sd_db has ln Z known to sd_db ln(10) / 20.

    Parameters
    ----------
    sd_db : float
        Standard deviation of the level [dB].

    Returns
    -------
    float
        Variance of ln Z [-], (sd_db ln 10 / 20)^2: a level is 20 lg Z, so ln Z moves by
        ln 10 / 20 per dB.

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1 (the roughness level 20 lg Z).
    """
    return (sd_db * LN_PER_DB) ** 2


def band_level_jacobian(log_components: np.ndarray, growth: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A band's ln r.m.s. and its derivative with respect to scaling each friction state's growth.

    d ln Z_b / d delta_f = sum_p w_bp G_f,bp, for growth G already in the components and the
    components' energy shares w.

    Parameters
    ----------
    log_components : ndarray
        ln Z of the components [ln m] (B, P).
    growth : ndarray
        Their log growth per friction state [-] (4, B, P).

    Returns
    -------
    tuple of ndarray
        ln r.m.s. per band [ln m] (B,), the derivative [-] (B, 4) and the energy shares w [-] (B, P).

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eqs. 1-2 (the growth scaled).
    """
    level = cstate.band_log_amplitude(log_components)
    weight = np.exp(2.0 * (log_components - level[:, None]))
    return level, np.einsum("bp,fbp->bf", weight, growth), weight


def _scaled(start: np.ndarray, growth: np.ndarray, scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The growth scaled per friction state (4, B, P) and the components after it (B, P)."""
    scaled = growth * scale[:, None, None]
    return scaled, start + scaled.sum(axis=0)


def _curvature(scaled: np.ndarray, weight: np.ndarray, jac: np.ndarray) -> np.ndarray:
    """Second derivatives of the band ln Z in delta (B, 4, 4): with a_fp = exp(delta_f) G_fp, the
    energy shares w_p and abar_f = sum_p w_p a_fp (the Jacobian),
    d2 yhat / d delta_f d delta_g = [f = g] abar_f + 2 (sum_p w_p a_fp a_gp - abar_f abar_g)."""
    second = 2.0 * (np.einsum("bp,fbp,gbp->bfg", weight, scaled, scaled) - jac[:, :, None] * jac[:, None, :])
    return second + jac[:, :, None] * np.eye(jac.shape[1])


@dataclass(frozen=True)
class SurveyFit:
    """A survey's joint posterior: of u (posterior, its change delta (4,)), of the bands' levels at
    the last survey (their change shift (B,) [-]), and of the levels after it (level_cov (B, B)
    and their covariance with u, cross (B, 4))."""

    posterior: KbPosterior
    delta: np.ndarray
    shift: np.ndarray
    level_cov: np.ndarray
    cross: np.ndarray


def joint_cov(level_cov: np.ndarray, cross: np.ndarray, u_cov: np.ndarray) -> np.ndarray:
    """The covariance of (the bands' levels, u), (B + 4, B + 4), from its blocks.

    Parameters
    ----------
    level_cov : ndarray
        Covariance of the bands' ln Z [-] (B, B).
    cross : ndarray
        Their covariance with u [-] (B, 4).
    u_cov : ndarray
        Covariance of u [-] (4, 4).

    Returns
    -------
    ndarray
        The joint covariance [-], levels first.

    References
    ----------
    .. [1] A. Gelb (ed.), *Applied Optimal Estimation*, MIT Press, Cambridge MA, 1974, section 9.2
       (parameters as augmented states).
    """
    return np.block([[level_cov, cross], [cross.T, u_cov]])


def joint_update(post: KbPosterior, level_cov: np.ndarray, cross: np.ndarray, start: np.ndarray,
                 growth: np.ndarray, matched: np.ndarray, measured: np.ndarray, noise_var: np.ndarray | float
                 ) -> SurveyFit:
    """The joint posterior of the bands' levels and u after one survey (the module's z = (a, delta)).

    Parameters
    ----------
    post : KbPosterior
        The posterior of u so far [-], whose median K_b the growth was computed with.
    level_cov : ndarray
        Covariance of every band's ln Z at the last survey or grinding [-] (B, B).
    cross : ndarray
        Their covariance with u [-] (B, 4).
    start : ndarray
        ln Z of the components at the last survey or grinding [ln m] (B, P).
    growth : ndarray
        Their log growth since then per friction state [-] (4, B, P).
    matched : ndarray
        The bands the survey measured [-] (B,), bool.
    measured : ndarray
        Their surveyed ln Z [ln m] (M,).
    noise_var : ndarray or float
        Variance of each measured band's ln Z [-] (M,) or scalar.

    Returns
    -------
    SurveyFit
        The posterior of u, the change of u and of the levels at the last survey, and the
        covariance of the levels after the survey, with each other and with u.

    References
    ----------
    .. [1] A. Gelman, J. B. Carlin, H. S. Stern, D. B. Dunson, A. Vehtari and D. B. Rubin, *Bayesian
       Data Analysis*, 3rd ed., CRC Press, Boca Raton, 2013, sections 4.1 and 13.3 (the normal
       approximation at the mode).
    .. [2] A. Gelb (ed.), *Applied Optimal Estimation*, MIT Press, Cambridge MA, 1974, sections 6.1
       and 9.2 (the iterated extended Kalman filter; parameters as augmented states).
    .. [3] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eqs. 1-2.
    """
    bands, states = start.shape[0], len(post.mean)
    sel = np.flatnonzero(matched)
    p_inv = np.linalg.inv(joint_cov(level_cov, cross, post.cov))
    w = np.broadcast_to(1.0 / np.asarray(noise_var, float), sel.shape)
    h = np.zeros((len(sel), bands + states))
    h[np.arange(len(sel)), sel] = 1.0
    z = np.zeros(bands + states)
    for _ in range(_MAX_ITERATIONS):
        scaled, comp = _scaled(start, growth, np.exp(z[bands:]))
        level, jac, _ = band_level_jacobian(comp, scaled)
        h[:, bands:] = jac[sel]
        info = (h.T * w) @ h + p_inv
        step = np.linalg.solve(info, (h.T * w) @ (measured - level[sel] - z[sel]) - p_inv @ z)
        z = z + step
        if np.max(np.abs(step)) < _STEP_TOLERANCE:
            break
    scaled, comp = _scaled(start, growth, np.exp(z[bands:]))
    level, jac, weight = band_level_jacobian(comp, scaled)
    h[:, bands:] = jac[sel]
    info = (h.T * w) @ h + p_inv
    hessian = info.copy()
    residual = w * (measured - level[sel] - z[sel])
    hessian[bands:, bands:] -= np.einsum("b,bfg->fg", residual, _curvature(scaled, weight, jac)[sel])
    try:
        np.linalg.cholesky(hessian)
        cov = np.linalg.inv(hessian)
    except np.linalg.LinAlgError:  # not positive definite (far from a mode): Gauss-Newton's
        cov = np.linalg.inv(info)
    cov = 0.5 * (cov + cov.T)
    after = np.hstack([np.eye(bands), jac])  # d(level after)/dz: a + yhat(delta)
    level_cov = after @ cov @ after.T
    return SurveyFit(KbPosterior(post.mean + z[bands:], cov[bands:, bands:], post.fits + 1), z[bands:], z[:bands],
                     0.5 * (level_cov + level_cov.T), after @ cov[:, bands:])
