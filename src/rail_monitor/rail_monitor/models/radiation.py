"""Radiation efficiencies of simple radiators, and the radiated power of a vibrating surface.

W = rho0 c0 sigma S <v^2>: sound power [W] of a surface of area S [m2] whose normal velocity has
the mean square <v^2> [m2/s2] (spatial and time average), with radiation efficiency sigma [-].
Air: rho0 c0 = 1.204 kg/m3 x 343.2 m/s = 413 rayl at 20 degC and 101.325 kPa (ISO 9613-1:1993).

References
----------
.. [1] ISO 9613-1:1993, *Acoustics - Attenuation of sound during propagation outdoors - Part 1:
   Calculation of the absorption of sound by the atmosphere*, International Organization for
   Standardization, Geneva, 1993.
.. [2] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
   Elsevier, Oxford, 2009, chapter 2 (radiation efficiency).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import h1vp, j1

FloatArray = NDArray[np.float64]

AIR_DENSITY = 1.204        # [kg/m3], 20 degC, 101.325 kPa
SOUND_SPEED = 343.2        # [m/s], 20 degC
RHO_C = AIR_DENSITY * SOUND_SPEED


def wavenumber(frequency_hz: ArrayLike) -> FloatArray:
    """Acoustic wavenumber k = 2 pi f / c0 in air at 20 degC.

    Parameters
    ----------
    frequency_hz : array_like
        Frequency f [Hz], any shape.

    Returns
    -------
    ndarray
        k [1/m].

    References
    ----------
    .. [1] ISO 9613-1:1993, *Acoustics - Attenuation of sound during propagation outdoors - Part 1:
       Calculation of the absorption of sound by the atmosphere* (the reference atmosphere's speed of sound).
    """
    return 2.0 * np.pi * np.asarray(frequency_hz, float) / SOUND_SPEED


def oscillating_cylinder(ka: ArrayLike) -> FloatArray:
    """Radiation efficiency of an infinitely long rigid cylinder oscillating across its axis.

    The n = 1 circumferential mode: sigma_1 = 2 / (pi ka |H_1'(ka)|^2), the power normalised by the
    surface-averaged normal velocity, <v_n^2> = v^2 / 2. Limits: (pi / 2) (ka)^3 for ka << 1 (a line
    dipole), 1 for ka >> 1.

    Parameters
    ----------
    ka : array_like
        Wavenumber times radius [-].

    Returns
    -------
    ndarray
        sigma [-] of the n = 1 mode, the rigid cross-section's motion (a rail's vertical or
        lateral vibration below its cross-section's own modes).

    References
    ----------
    .. [1] M. C. Junger and D. Feit, *Sound, Structures and Their Interaction*, 2nd ed., MIT Press,
       Cambridge MA, 1986, section 4.7.
    .. [2] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, chapter 2 (the rail as a radiating cylinder).
    """
    return cylinder_mode(1, ka)


def cylinder_mode(order: ArrayLike, ka: ArrayLike) -> FloatArray:
    """Radiation efficiency of an infinitely long cylinder whose normal velocity varies as cos(n theta).

    2 / (pi ka |H_n'(ka)|^2), normalised by the surface-averaged mean square normal velocity (the
    theta average of cos^2 enters power and normalisation alike). Tends to 1 above ka of about n,
    and falls as (ka)^(2n+1) below (n >= 1).

    Parameters
    ----------
    order : array_like
        Circumferential order n [-].
    ka : array_like
        Wavenumber times radius [-].

    Returns
    -------
    ndarray
        sigma [-]: the power over rho0 c0 S <v_n^2>.

    References
    ----------
    .. [1] M. C. Junger and D. Feit, *Sound, Structures and Their Interaction*, 2nd ed., MIT Press,
       Cambridge MA, 1986, section 4.7.
    """
    x = np.asarray(ka, float)
    return 2.0 / (np.pi * x * np.abs(h1vp(np.asarray(order), x)) ** 2)


def baffled_piston(ka: ArrayLike) -> FloatArray:
    """Radiation efficiency of a rigid circular piston in an infinite baffle, 1 - J1(2 ka) / (ka).

    Limits: (ka)^2 / 2 for ka << 1, 1 for ka >> 1.

    Parameters
    ----------
    ka : array_like
        Wavenumber times piston radius [-].

    Returns
    -------
    ndarray
        sigma [-].

    References
    ----------
    .. [1] L. E. Kinsler, A. R. Frey, A. B. Coppens and J. V. Sanders, *Fundamentals of Acoustics*,
       4th ed., Wiley, New York, 2000, eq. 7.5.11.
    """
    x = np.asarray(ka, float)
    return 1.0 - j1(2.0 * x) / x


def radiated_power(mean_square_velocity: ArrayLike, area_m2: ArrayLike, efficiency: ArrayLike) -> FloatArray:
    """Sound power of a vibrating surface, W = rho0 c0 sigma S <v^2>.

    Parameters
    ----------
    mean_square_velocity : array_like
        Spatial and time average of the squared normal velocity <v^2> [m2/s2].
    area_m2 : array_like
        Radiating area S [m2].
    efficiency : array_like
        Radiation efficiency sigma [-].

    Returns
    -------
    ndarray
        W [W].

    References
    ----------
    .. [1] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, chapter 2 (radiation efficiency).
    .. [2] ISO 9613-1:1993, *Acoustics - Attenuation of sound during propagation outdoors - Part 1:
       Calculation of the absorption of sound by the atmosphere* (rho0 c0 = 413 rayl at 20 degC, 101.325 kPa).
    """
    return RHO_C * np.asarray(efficiency, float) * np.asarray(area_m2, float) * np.asarray(mean_square_velocity,
                                                                                          float)
