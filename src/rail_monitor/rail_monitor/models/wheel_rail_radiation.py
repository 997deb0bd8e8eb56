"""The sound power a wheel and a track radiate (no rclpy): the rail under one contact with its
vibration decaying along it, the half-sleepers under it, the wheel in rigid motion and its flexible
modes with their damping (D. J. Thompson, Wheel-rail noise generation, parts I-V, J. Sound Vib. 161
(1993) 387-482; Railway Noise and Vibration, Elsevier 2009). The velocities they radiate are
:mod:`rail_monitor.models.wheel_rail_noise`'s.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models import radiation
from rail_monitor.models import wheel_modes as wm

ComplexArray = NDArray[np.complex128]
FloatArray = NDArray[np.float64]


NEPER_DB = 20.0 * np.log10(np.e)   # 8.686 dB per neper: decay rate [dB/m] = 8.686 Im(k)


def rail_power(v2: ArrayLike, frequency: ArrayLike, decay_db_per_m: ArrayLike, radius_m: float) -> FloatArray:
    """Power radiated by one rail under one contact, its vibration decaying along the rail.

    W = rho0 c0 sigma (2 pi a) <v^2> L_eff, <v^2> = v2 / 2 and the effective length
    L_eff = 2 x 4.343 / decay rate [m].

    Parameters
    ----------
    v2 : array_like
        Squared velocity at the contact [m2/s2].
    frequency : array_like
        Frequency [Hz].
    decay_db_per_m : array_like
        Track decay rate [dB/m].
    radius_m : float
        Radius of the rail's equivalent cylinder [m].

    Returns
    -------
    ndarray
        Power [W] of the rail's vibration over its whole length.

    References
    ----------
    .. [1] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, section 5.6.
    """
    sigma = radiation.oscillating_cylinder(radiation.wavenumber(frequency) * radius_m)
    length = NEPER_DB / np.asarray(decay_db_per_m, float)   # integral of exp(-2 beta |x|) dx = 1 / beta
    return radiation.radiated_power(np.asarray(v2) / 2.0, 2.0 * np.pi * radius_m, sigma) * length


def sleeper_power(v2: ArrayLike, frequency: ArrayLike, decay_db_per_m: ArrayLike, transmissibility: ArrayLike,
                  spacing_m: float, area_m2: float) -> FloatArray:
    """Power radiated by the half-sleepers under one rail's decaying field of vibration.

    Parameters
    ----------
    v2 : array_like
        The rail's squared velocity at the contact [m2/s2].
    frequency : array_like
        Frequency [Hz].
    decay_db_per_m : array_like
        Track decay rate [dB/m].
    transmissibility : array_like
        Half-sleeper over rail displacement [-] (complex).
    spacing_m : float
        Sleeper spacing [m].
    area_m2 : float
        Radiating top face of a half-sleeper [m2].

    Returns
    -------
    ndarray
        Power [W] of every half-sleeper under the decaying field.

    References
    ----------
    .. [1] D. J. Thompson, "Wheel-rail noise generation, parts I-V", *Journal of Sound and Vibration*
       161(3) (1993) 387-482 (part IV, the sleepers' radiation).
    """
    sigma = radiation.baffled_piston(radiation.wavenumber(frequency) * np.sqrt(area_m2 / np.pi))
    seats = NEPER_DB / np.asarray(decay_db_per_m, float) / spacing_m      # sum over seats of exp(-2 beta |x_n|)
    return radiation.radiated_power(np.abs(transmissibility) ** 2 * np.asarray(v2) * seats, area_m2, sigma)


def wheel_power(v2: ArrayLike, frequency: ArrayLike, diameter_m: float, rim_width_m: float) -> FloatArray:
    """Power radiated by a wheel in rigid vertical motion, its rim as a short oscillating cylinder.

    Parameters
    ----------
    v2 : array_like
        Squared velocity [m2/s2].
    frequency : array_like
        Frequency [Hz].
    diameter_m : float
        Wheel diameter [m].
    rim_width_m : float
        Rim width [m].

    Returns
    -------
    ndarray
        Power [W] of the rigid wheel's vertical motion.

    References
    ----------
    .. [1] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, chapter 2 (radiation efficiency of a cylinder).
    """
    radius = diameter_m / 2.0
    sigma = radiation.oscillating_cylinder(radiation.wavenumber(frequency) * radius)
    return radiation.radiated_power(np.asarray(v2) / 2.0, 2.0 * np.pi * radius * rim_width_m, sigma)


def modal_damping(nodal_diameters: ArrayLike, ratio_n2: float = 1.0e-4) -> FloatArray:
    """Damping ratio per wheel mode: 1e-2 for n = 0, 1e-3 for n = 1, ratio_n2 for n >= 2.

    The modes of zero and one nodal diameter couple to the axle; 1e-4 is an untreated solid wheel's
    and a wheel damper raises it; the values used with TWINS.

    Parameters
    ----------
    nodal_diameters : array_like
        n per mode [-].
    ratio_n2 : float
        Damping ratio of the modes with two or more nodal diameters [-].

    Returns
    -------
    ndarray
        zeta per mode [-].

    References
    ----------
    .. [1] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, section 5.2.
    """
    n = np.asarray(nodal_diameters)
    return np.select([n == 0, n == 1], [max(1.0e-2, ratio_n2), max(1.0e-3, ratio_n2)], ratio_n2)


def modal_terms(frequency: ArrayLike, modes: wm.WheelModes, damping: ArrayLike) -> ComplexArray:
    """Each mode's coordinate per unit contact force, phi_c / (w_n^2 - w^2 + 2 i zeta_n w_n w).

    Times phi_c and summed over the modes, the receptance.

    Parameters
    ----------
    frequency : array_like
        Frequency [Hz].
    modes : WheelModes
        The wheel's modes: frequencies [Hz] and contact displacements [kg^-1/2].
    damping : array_like
        zeta per mode [-].

    Returns
    -------
    ndarray of complex
        Modal coordinates per unit force [kg^-1/2 s^2], shape frequency.shape + (modes,).

    References
    ----------
    .. [1] D. J. Thompson, "Wheel-rail noise generation, parts I-V", *Journal of Sound and Vibration*
       161(3) (1993) 387-482 (part II, the wheel's modal receptance).
    """
    w = 2.0 * np.pi * np.asarray(frequency, float)[..., None]
    wn = 2.0 * np.pi * modes.frequency_hz
    return modes.contact_radial / (wn**2 - w**2 + 2j * np.asarray(damping) * wn * w)


def modal_wheel_power(force2: ArrayLike, frequency: ArrayLike, modes: wm.WheelModes, terms: ComplexArray
                      ) -> FloatArray:
    """Power radiated by the wheel's flexible modes under a contact force.

    Per mode rho0 c0 w^2 |q_n|^2 / 2 (sigma_ax A_ax + sigma_rad A_rad), with the modal coordinate
    q_n = terms F, A the mode's squared axial and radial displacements integrated over the wheel's
    exterior (models.wheel_modes), and sigma the radiation efficiency of a cylinder of the wheel's
    radius with the far field's order: n + 1 for axial motion (a disc moving axially is a dipole at
    n = 0) and n for radial motion (n = 1 is the rigid wheel's cross motion). Modes add in power
    (cross terms between modes of one n neglected: resonances 1e-4 wide).

    Parameters
    ----------
    force2 : array_like
        Squared contact force amplitude [N2].
    frequency : array_like
        Frequency [Hz].
    modes : WheelModes
        Surface integrals [m2/kg] and frequencies [Hz] of the modes.
    terms : ndarray
        :func:`modal_terms` [kg^-1/2 s^2].

    Returns
    -------
    ndarray
        Power [W] of the flexible modes, added in power.

    References
    ----------
    .. [1] D. J. Thompson, "Wheel-rail noise generation, parts I-V", *Journal of Sound and Vibration*
       161(3) (1993) 387-482 (part IV, the wheel's radiation).
    .. [2] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, chapter 6.
    """
    f = np.asarray(frequency, float)[..., None]
    n = modes.nodal_diameters
    sigma = radiation.cylinder_mode(np.arange(n.max() + 2), radiation.wavenumber(f) * modes.rolling_radius_m)
    surface = sigma[..., n + 1] * modes.axial_surface + sigma[..., n] * modes.radial_surface
    w2 = (2.0 * np.pi * f) ** 2
    return radiation.RHO_C * np.asarray(force2) * np.sum(w2 * np.abs(terms) ** 2 * surface, axis=-1) / 2.0
