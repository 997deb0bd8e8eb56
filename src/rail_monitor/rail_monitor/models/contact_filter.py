"""Contact filter: the attenuation of short-wavelength roughness by a contact patch of finite length.

A wheel does not follow roughness much shorter than its contact patch: the patch averages it.
For a harmonic of wavenumber k = 2 pi / lambda, averaging over the rolling direction with the
Hertzian weight sqrt(1 - (x / a)^2) on -a <= x <= a (a: semi-length of the patch along the
rail) gives the amplitude ratio

    F(k a) = integral sqrt(1 - u^2) cos(k a u) du / integral sqrt(1 - u^2) du = 2 J1(k a) / (k a)

(the integral of sqrt(1 - u^2) cos(z u) over [-1, 1] is pi J1(z) / z). F -> 1 as k a -> 0, and
F = 0 first at k a = 3.83, i.e. lambda = 1.64 a. This is the one-line form of the contact
filters of rolling-noise prediction (Remington, J. Acoust. Soc. Am. 81 (1987) 1805-1823; Ford &
Thompson, J. Sound Vib. 293 (2006) 807-818, who find a 2-D line model within 3 dB of a
Boussinesq analysis in 1/3-octave bands). The same averaging acts on wear: material removed at a
point is the average of the frictional work over the patch passing it (Hempelmann & Knothe,
Wear 191 (1996) 161-169), so corrugation growth sees the filter twice (models.corrugation).

References
----------
.. [1] P. J. Remington, "Wheel/rail rolling noise, I: Theoretical analysis", *Journal of the Acoustical
   Society of America* 81(6) (1987) 1805-1823.
.. [2] R. A. J. Ford and D. J. Thompson, "Simplified contact filters in wheel/rail noise prediction",
   *Journal of Sound and Vibration* 293(3-5) (2006) 807-818.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import j1


def hertzian_line_filter(wavelength: ArrayLike, semi_length: ArrayLike) -> NDArray[np.float64]:
    """The contact filter of a Hertzian patch, F = 2 J1(k a) / (k a), k = 2 pi / wavelength.

    Signed: F < 0 between its first and second zeros (k a = 3.83 to 7.02), where the patch sees
    the harmonic in antiphase.

    Parameters
    ----------
    wavelength : array_like
        Roughness wavelength [m].
    semi_length : array_like
        Patch semi-length a along the rail [m].

    Returns
    -------
    ndarray
        F [-].

    References
    ----------
    .. [1] P. J. Remington, "Wheel/rail rolling noise, I: Theoretical analysis", *Journal of the
       Acoustical Society of America* 81(6) (1987) 1805-1823.
    .. [2] R. A. J. Ford and D. J. Thompson, "Simplified contact filters in wheel/rail noise
       prediction", *Journal of Sound and Vibration* 293(3-5) (2006) 807-818.
    """
    ka = 2.0 * np.pi * np.asarray(semi_length, float) / np.asarray(wavelength, float)
    small = np.abs(ka) < 1e-6
    safe = np.where(small, 1.0, ka)
    return np.where(small, 1.0 - ka * ka / 8.0, 2.0 * j1(safe) / safe)
