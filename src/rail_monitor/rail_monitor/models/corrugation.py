"""Wear-type corrugation growth per wheel pass (seed section 2.1, eqs. 1-2; MODELS.md section 2).

A rail roughness harmonic of wavelength lambda [m], passed at speed V [m/s] (frequency
f = V / lambda), grows per wheel pass by

    Z_{n+1} / Z_n = 1 + K_b H(f),      H = 1 / (1 + k_c (R_r(f) + R_w(f)))

with k_c the linearised Hertz contact stiffness [N/m] (models.hertz), R_r and R_w the complex
vertical receptances of rail and wheel [m/N] (models.track) and K_b the wear sensitivity [-]
(order 1e-5 per pass; the field-tuning parameter). Over a distribution p(V) of pass speeds the
expected log growth per pass is (seed eq. 2, kept in its ln|.| form, not linearised)

    g(lambda) = integral ln|1 + K_b H(V / lambda)| p(V) dV,      Z_n ~ Z_0 exp(n g).

The seed's eq. (1) is a single-mode approximation, G_r = K_b (1 + K_c / (4 zeta (1 + zeta))),
valid only as K_c -> 0; :func:`single_mode_growth_max` is the exact maximum of K_b Re H for one
mode (MODELS.md), and the tests check both against the full kernel.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def wavelength_bands(shortest_m: float = 0.01, longest_m: float = 1.0) -> FloatArray:
    """1/3-octave wavelength band centres [m], base ten (10^(n/10) m, as IEC 61260-1's exact
    mid-band frequencies), covering [shortest_m, longest_m]."""
    lo = int(np.floor(10 * np.log10(shortest_m) + 1e-9))
    hi = int(np.ceil(10 * np.log10(longest_m) - 1e-9))
    return 10.0 ** (np.arange(lo, hi + 1) / 10.0)


def growth_kernel(contact_stiffness: ArrayLike, receptance_sum: ArrayLike) -> ComplexArray:
    """H = 1 / (1 + k_c (R_r + R_w)) [-] from k_c [N/m] and R_r + R_w [m/N] (seed eq. 2)."""
    return 1.0 / (1.0 + np.asarray(contact_stiffness) * np.asarray(receptance_sum))


def log_growth_per_pass(wear_sensitivity: ArrayLike, kernel: ArrayLike) -> FloatArray:
    """ln|1 + K_b H| [-]: the log amplitude growth of one wheel pass."""
    return np.log(np.abs(1.0 + np.asarray(wear_sensitivity) * np.asarray(kernel)))


def expected_log_growth(
    wear_sensitivity: float,
    kernel_at: Callable[[FloatArray], ComplexArray],
    wavelengths: ArrayLike,
    speeds: ArrayLike,
    weights: ArrayLike,
) -> FloatArray:
    """g(lambda) [-/pass] (seed eq. 2) for a discrete speed distribution.

    kernel_at(f) returns H at frequencies f [Hz] (any shape); speeds [m/s] with weights (summing
    to 1) stand for p(V). Returns one value per wavelength [m].
    """
    lam = np.asarray(wavelengths, float)[:, None]
    v = np.asarray(speeds, float)[None, :]
    w = np.asarray(weights, float)
    if not np.isclose(w.sum(), 1.0):
        raise ValueError("speed weights must sum to 1")
    return log_growth_per_pass(wear_sensitivity, kernel_at(v / lam)) @ w


def single_mode_kernel(frequency_ratio: ArrayLike, contact_ratio: ArrayLike, damping_ratio: ArrayLike) -> ComplexArray:
    """H for one combined wheel/rail mode: R = 1 / (k (1 - r^2 + 2 i zeta r)), K_c = k_c / k.

    frequency_ratio r = f / f_n [-], contact_ratio K_c [-], damping_ratio zeta [-].
    """
    r = np.asarray(frequency_ratio, float)
    return 1.0 / (1.0 + np.asarray(contact_ratio) / (1.0 - r * r + 2j * np.asarray(damping_ratio) * r))


def single_mode_growth_seed(wear_sensitivity: ArrayLike, contact_ratio: ArrayLike,
                            damping_ratio: ArrayLike) -> FloatArray:
    """The seed's eq. (1): G_r = K_b (1 + K_c / (4 zeta (1 + zeta))), the K_c -> 0 limit."""
    z = np.asarray(damping_ratio, float)
    return np.asarray(wear_sensitivity) * (1.0 + np.asarray(contact_ratio) / (4.0 * z * (1.0 + z)))


def single_mode_growth_max(wear_sensitivity: ArrayLike, contact_ratio: ArrayLike,
                           damping_ratio: ArrayLike) -> FloatArray:
    """Exact maximum over frequency of K_b Re H for one mode (MODELS.md section 2):
    K_b [1 + K_c / (4 z (1 + z) (1 + K_c))], z = zeta / sqrt(1 + K_c)."""
    kc = np.asarray(contact_ratio, float)
    z = np.asarray(damping_ratio, float) / np.sqrt(1.0 + kc)
    return np.asarray(wear_sensitivity) * (1.0 + kc / (4.0 * z * (1.0 + z) * (1.0 + kc)))
