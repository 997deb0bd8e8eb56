"""Wear-type corrugation growth per wheel pass (UQ paper section 2.1, eqs. 1-2; docs/models.md).

A rail roughness harmonic of wavelength lambda [m], passed at speed V [m/s] (frequency
f = V / lambda), grows per wheel pass by

    Z_{n+1} / Z_n = 1 + K_b H(f),      H = 1 / (1 + k_c (R_r(f) + R_w(f)))

with k_c the linearised Hertz contact stiffness [N/m] (models.hertz), R_r and R_w the complex
vertical receptances of rail and wheel [m/N] (models.track) and K_b the wear sensitivity [-]
(order 1e-5 per pass; the field-tuning parameter). Over a distribution p(V) of pass speeds the
expected log growth per pass is (UQ paper eq. 2, kept in its ln|.| form, not linearised)

    g(lambda) = integral ln|1 + K_b H(V / lambda)| p(V) dV,      Z_n ~ Z_0 exp(n g).

The UQ paper's eq. (1) is a single-mode approximation, G_r = K_b (1 + K_c / (4 zeta (1 + zeta))),
valid only as K_c -> 0; :func:`single_mode_growth_max` is the exact maximum of K_b Re H for one
mode (docs/models.md), and the tests check both against the full kernel.

Two additions to the UQ paper's kernel, both cited where they are defined:
- the contact filter F (models.contact_filter) acts twice, on the roughness the contact sees and
  on the wear it leaves, so the growth term is K_b F^2 H; without it every wavelength shorter than
  the contact patch would grow at K_b at least (H -> 1 as the receptances vanish);
- a band is tracked as components at wavelengths spread across it (:func:`band_sub_wavelengths`),
  each growing at its own rate; the band's r.m.s. is their energy sum (:func:`band_amplitude`)
  and tends to grow at the rate of its fastest component, so a resonance between band centres
  is not missed.

Grinding limits (Grassie, Saxon & Smith, J. Sound Vib. 227 (1999) 949-964) are here too; the
speed plan (a linear programme) is :mod:`rail_monitor.advice.speed_plan`.

References
----------
.. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and acoustic
   phenomena", seminar paper, section 2.1 (eqs. 1-2, Figure 2).
.. [2] S. L. Grassie, M. J. Saxon and J. D. Smith, "Measurement of longitudinal rail irregularities and
   criteria for acceptable grinding", *Journal of Sound and Vibration* 227(5) (1999) 949-964.
.. [3] A. Hempelmann and K. Knothe, "An extended linear model for the prediction of short pitch
   corrugation", *Wear* 191 (1996) 161-169.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def growth_kernel(contact_stiffness: ArrayLike, receptance_sum: ArrayLike) -> ComplexArray:
    """The growth kernel H = 1 / (1 + k_c (R_r + R_w)) of UQ eq. 2.

    Parameters
    ----------
    contact_stiffness : array_like
        Linearised Hertz contact stiffness k_c [N/m].
    receptance_sum : array_like
        Vertical receptance of rail plus wheel, R_r + R_w [m/N] (complex).

    Returns
    -------
    ndarray of complex
        H [-].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    """
    return 1.0 / (1.0 + np.asarray(contact_stiffness) * np.asarray(receptance_sum))


def log_growth_per_pass(wear_sensitivity: ArrayLike, kernel: ArrayLike) -> FloatArray:
    """The log amplitude growth of one wheel pass, ln|1 + K_b H|.

    Parameters
    ----------
    wear_sensitivity : array_like
        K_b [-].
    kernel : array_like
        H [-] (complex; :func:`growth_kernel`).

    Returns
    -------
    ndarray
        ln|1 + K_b H| [-].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    """
    return np.log(np.abs(1.0 + np.asarray(wear_sensitivity) * np.asarray(kernel)))


def expected_log_growth(
    wear_sensitivity: float,
    kernel_at: Callable[[FloatArray], ComplexArray],
    wavelengths: ArrayLike,
    speeds: ArrayLike,
    weights: ArrayLike,
) -> FloatArray:
    """The expected log growth per pass g(lambda) over a discrete speed distribution (UQ eq. 2).

    g(lambda) = sum_i w_i ln|1 + K_b H(V_i / lambda)|, the ln|.| form kept, not linearised.

    Parameters
    ----------
    wear_sensitivity : float
        K_b [-].
    kernel_at : callable
        H [-] at frequencies f [Hz] (any shape).
    wavelengths : array_like
        Wavelengths lambda [m].
    speeds : array_like
        Pass speeds V_i [m/s].
    weights : array_like
        Their probabilities w_i [-] (summing to 1).

    Returns
    -------
    ndarray
        g [1/pass], one value per wavelength.

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    """
    lam = np.asarray(wavelengths, float)[:, None]
    v = np.asarray(speeds, float)[None, :]
    w = np.asarray(weights, float)
    if not np.isclose(w.sum(), 1.0):
        raise ValueError("speed weights must sum to 1")
    return log_growth_per_pass(wear_sensitivity, kernel_at(v / lam)) @ w


def single_mode_kernel(frequency_ratio: ArrayLike, contact_ratio: ArrayLike, damping_ratio: ArrayLike) -> ComplexArray:
    """H for one combined wheel/rail mode: R = 1 / (k (1 - r^2 + 2 i zeta r)), K_c = k_c / k.

    Parameters
    ----------
    frequency_ratio : array_like
        r = f / f_n [-].
    contact_ratio : array_like
        K_c = k_c / k [-].
    damping_ratio : array_like
        zeta [-].

    Returns
    -------
    ndarray of complex
        H of the one mode [-].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eqs. 1-2.
    """
    r = np.asarray(frequency_ratio, float)
    return 1.0 / (1.0 + np.asarray(contact_ratio) / (1.0 - r * r + 2j * np.asarray(damping_ratio) * r))


def single_mode_growth_approx(wear_sensitivity: ArrayLike, contact_ratio: ArrayLike,
                            damping_ratio: ArrayLike) -> FloatArray:
    """The UQ paper's eq. (1): G_r = K_b (1 + K_c / (4 zeta (1 + zeta))), the K_c -> 0 limit.

    Parameters
    ----------
    wear_sensitivity : array_like
        K_b [-].
    contact_ratio : array_like
        K_c [-].
    damping_ratio : array_like
        zeta [-].

    Returns
    -------
    ndarray
        G_r [1/pass].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 1.
    """
    z = np.asarray(damping_ratio, float)
    return np.asarray(wear_sensitivity) * (1.0 + np.asarray(contact_ratio) / (4.0 * z * (1.0 + z)))


def single_mode_growth_max(wear_sensitivity: ArrayLike, contact_ratio: ArrayLike,
                           damping_ratio: ArrayLike) -> FloatArray:
    """Exact maximum over frequency of K_b Re H for one mode (docs/models.md).

    K_b [1 + K_c / (4 z (1 + z) (1 + K_c))], z = zeta / sqrt(1 + K_c): the contact spring raises the
    mode's frequency and lowers its damping ratio; as K_c -> 0 it tends to the UQ paper's eq. (1).

    Parameters
    ----------
    wear_sensitivity, contact_ratio, damping_ratio : array_like
        K_b [-], K_c = k_c / k [-] and the mode's damping ratio zeta [-], as for
        :func:`single_mode_growth_approx`.

    Returns
    -------
    ndarray
        The peak growth rate [1/pass].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 1 (which this corrects for finite K_c).
    """
    kc = np.asarray(contact_ratio, float)
    z = np.asarray(damping_ratio, float) / np.sqrt(1.0 + kc)
    return np.asarray(wear_sensitivity) * (1.0 + kc / (4.0 * z * (1.0 + z) * (1.0 + kc)))


SLIDING_WEAR_EXPONENT = 2.0 / 3.0  # beta = d ln w / d ln N in full sliding (docs/models.md, "Sliding")


def sliding_wear_sensitivity(wear_sensitivity: ArrayLike, wear_ratio: ArrayLike = 1.0) -> FloatArray:
    """K_b in full sliding from K_b in partial slip: -(2/3) K_b w_slide / w_slip.

    Wear proportional to frictional power gives K_b = -beta k_c w / N with beta = d ln w / d ln N
    (w the mean wear per pass at the static load N, k_c the contact stiffness). In partial slip at
    a prescribed tangential force more load means less slip, beta = -1 and K_b = k_c w / N > 0;
    in full sliding the wear depth is mu p times the slip distance, p ~ N / (a b) and a, b ~ N^(1/3)
    [2]_, so w ~ N^(2/3), beta = +2/3 and K_b = -(2/3) k_c w / N.

    Parameters
    ----------
    wear_sensitivity : array_like
        K_b in partial slip [-].
    wear_ratio : array_like
        Mean wear per pass in full sliding over that in partial slip at the same friction state [-].

    Returns
    -------
    ndarray
        K_b in full sliding [-].

    References
    ----------
    .. [1] A. Hempelmann and K. Knothe, "An extended linear model for the prediction of short pitch
       corrugation", *Wear* 191 (1996) 161-169 (wear proportional to frictional power).
    .. [2] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, section 4.2.
    """
    return -SLIDING_WEAR_EXPONENT * np.asarray(wear_ratio, float) * np.asarray(wear_sensitivity, float)


def filtered_log_growth(wear_sensitivity: ArrayLike, kernel: ArrayLike, contact_filter: ArrayLike) -> FloatArray:
    """One wheel pass's log growth with the contact filter, ln|1 + K_b F^2 H|.

    F acts twice: on the roughness the contact sees and on the wear it leaves (models.contact_filter).

    Parameters
    ----------
    wear_sensitivity : array_like
        K_b [-].
    kernel : array_like
        H [-] (complex).
    contact_filter : array_like
        F [-].

    Returns
    -------
    ndarray
        ln|1 + K_b F^2 H| [-].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    .. [2] A. Hempelmann and K. Knothe, "An extended linear model for the prediction of short pitch
       corrugation", *Wear* 191 (1996) 161-169 (the contact filter).
    """
    f = np.asarray(contact_filter)
    return log_growth_per_pass(wear_sensitivity, f * f * np.asarray(kernel))


