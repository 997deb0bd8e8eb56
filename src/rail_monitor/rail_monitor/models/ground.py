"""Reflection of a point source's sound by a porous ground: Delany-Bazley impedance and the
spherical-wave reflection coefficient.

Time convention exp(-i w t). The ground's normalised characteristic impedance, with X = rho0 f / s
(s the flow resistivity [Pa s/m2]; Delany & Bazley, Applied Acoustics 3 (1970) 105-116):

    Z = 1 + 0.0571 X^-0.754 + i 0.087 X^-0.732,

taken as the surface impedance (a locally reacting, semi-infinite ground). For a source and
receiver whose image path has length r2 and grazing angle psi (Attenborough, Li & Horoshenkov,
Predicting Outdoor Sound, Taylor & Francis 2007, chapter 2):

    R_p = (Z sin psi - 1) / (Z sin psi + 1),  beta = 1 / Z,
    w = (1 + i) / 2 sqrt(k r2) (sin psi + beta),  F(w) = 1 + i sqrt(pi) w e^(-w^2) erfc(-i w),
    Q = R_p + (1 - R_p) F(w),

F through the Faddeeva function w(z) = e^(-z^2) erfc(-i z) (scipy.special.wofz). The pass-by adds
the image path in energy with |Q|^2 per band (the bands are wide against the interference
pattern's fringes at 7.5 m). Flow resistivities [kPa s/m2]: about 200 for grass-covered soil, 20-80
for a loose, porous surface such as fresh ballast (Embleton, Piercy & Daigle, J. Acoust. Soc. Am.
74 (1983) 1239-1244, for grass; ballast values vary with its state).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import wofz

from rail_monitor.models.radiation import AIR_DENSITY, wavenumber

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def delany_bazley_impedance(frequency_hz: ArrayLike, flow_resistivity_pa_s_m2: float) -> ComplexArray:
    """Normalised characteristic impedance of a porous ground, Z = 1 + 0.0571 X^-0.754 + i 0.087 X^-0.732.

    X = rho0 f / s; taken as the surface impedance of a locally reacting, semi-infinite ground.

    Parameters
    ----------
    frequency_hz : array_like
        Frequency f [Hz].
    flow_resistivity_pa_s_m2 : float
        Flow resistivity s [Pa s/m2].

    Returns
    -------
    ndarray of complex
        Z [-] (time convention exp(-i w t)).

    References
    ----------
    .. [1] M. E. Delany and E. N. Bazley, "Acoustical properties of fibrous absorbent materials",
       *Applied Acoustics* 3 (1970) 105-116.
    """
    x = AIR_DENSITY * np.asarray(frequency_hz, float) / flow_resistivity_pa_s_m2
    return 1.0 + 0.0571 * x**-0.754 + 1j * 0.087 * x**-0.732


def ground_wave_function(w: ArrayLike) -> ComplexArray:
    """The ground wave's boundary loss function F(w) = 1 + i sqrt(pi) w e^(-w^2) erfc(-i w).

    Evaluated through the Faddeeva function e^(-w^2) erfc(-i w) (scipy.special.wofz).

    Parameters
    ----------
    w : array_like
        Numerical distance [-] (complex).

    Returns
    -------
    ndarray of complex
        F [-].

    References
    ----------
    .. [1] K. Attenborough, K. M. Li and K. Horoshenkov, *Predicting Outdoor Sound*, Taylor &
       Francis, London, 2007, chapter 2 (the spherical-wave reflection coefficient).
    """
    w = np.asarray(w, complex)
    return 1.0 + 1j * np.sqrt(np.pi) * w * wofz(w)


def spherical_reflection(frequency_hz: ArrayLike, flow_resistivity_pa_s_m2: float, image_path_m: float,
                         grazing_rad: float) -> ComplexArray:
    """Spherical-wave reflection coefficient Q of a porous ground for one image path.

    Q = R_p + (1 - R_p) F(w), R_p the plane-wave coefficient at the grazing angle (module docstring).

    Parameters
    ----------
    frequency_hz : array_like
        Frequency [Hz].
    flow_resistivity_pa_s_m2 : float
        Flow resistivity [Pa s/m2].
    image_path_m : float
        Length of the image path r2 [m].
    grazing_rad : float
        Grazing angle psi [rad].

    Returns
    -------
    ndarray of complex
        Q [-]: the image source's pressure relative to that of a perfect reflector
        (|Q| = 1) over the same path.

    References
    ----------
    .. [1] K. Attenborough, K. M. Li and K. Horoshenkov, *Predicting Outdoor Sound*, Taylor &
       Francis, London, 2007, chapter 2.
    .. [2] M. E. Delany and E. N. Bazley, *Applied Acoustics* 3 (1970) 105-116 (the impedance).
    """
    z = delany_bazley_impedance(frequency_hz, flow_resistivity_pa_s_m2)
    s = np.sin(grazing_rad)
    rp = (z * s - 1.0) / (z * s + 1.0)
    w = 0.5 * (1.0 + 1j) * np.sqrt(wavenumber(frequency_hz) * image_path_m) * (s + 1.0 / z)
    return rp + (1.0 - rp) * ground_wave_function(w)
