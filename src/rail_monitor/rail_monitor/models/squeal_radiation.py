"""What a squealing wheel radiates (no rclpy): the squeal's tone frequency, the sound power of the
wheel vibrating at the limit cycle's velocity amplitude, the level at a receiver and the level
change with amplitude (UQ seminar paper, section 3.3, Figure 7a; D. J. Thompson, Railway Noise and
Vibration, Elsevier 2009, sections 5.2 and 13). The amplitude is :mod:`rail_monitor.models.squeal`'s.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from rail_monitor.models.iec61672 import a_weighting_db
from rail_monitor.models.squeal import FloatArray

# Air at 20 degC, 101.325 kPa: rho0 c0 [kg/(m2 s)] (ISO 9613-1 reference atmosphere).
RHO0_C0 = 1.204 * 343.2


REFERENCE_POWER_W = 1e-12


REFERENCE_PRESSURE_PA = 20e-6


REFERENCE_VELOCITY_MPS = 1.0  # 20 lg(A w / 1 m/s) when no other reference is chosen


def squeal_frequency(mass: ArrayLike, stiffness: ArrayLike) -> FloatArray:
    """Natural frequency of the squealing mode, sqrt(k / m) / (2 pi).

    Parameters
    ----------
    mass : array_like
        Modal mass m [kg].
    stiffness : array_like
        Modal stiffness k [N/m].

    Returns
    -------
    ndarray
        Frequency [Hz] of the squeal's tone: the mode's undamped natural frequency (a damping
        ratio zeta would scale it by sqrt(1 - zeta^2)).

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.3, eq. 3 (the one-mode wheel).
    """
    return np.sqrt(np.asarray(stiffness, float) / np.asarray(mass, float)) / (2.0 * np.pi)


class RadiatedLevel(NamedTuple):
    """Sound power level Lw [dB re 1 pW], level at the receiver Lp [dB re 20 uPa], Lp A-weighted [dB(A)]."""

    power_db: FloatArray
    level_db: FloatArray
    level_dba: FloatArray


def radiated_level(
    amplitude: ArrayLike,
    frequency: ArrayLike,
    *,
    radiating_area: ArrayLike = 0.9,
    radiation_efficiency: ArrayLike = 1.0,
    spatial_average: ArrayLike = 0.5,
    distance: ArrayLike = 7.5,
    solid_angle: float = 2.0 * np.pi,
) -> RadiatedLevel:
    """Sound levels at a receiver from a wheel vibrating at a velocity amplitude A w at one frequency.

    Sound power W = rho0 c0 sigma S <v^2> with <v^2> = spatial_average (A w)^2 / 2 the surface- and
    time-averaged squared velocity: radiation efficiency sigma ~ 1 for wheel axial modes above about
    1 kHz, and a mode with nodal diameters averages cos^2 to 1/2 around the circumference, hence
    spatial_average 0.5 relative to the contact point [2]_. The wheel is a compact source radiating
    into solid_angle (2 pi: a hemisphere above a reflecting ground): p^2 = rho0 c0 W / (solid_angle
    r^2), so Lp = Lw - 10 lg(solid_angle r^2 / 1 m2) + 10 lg(rho0 c0 / 400), the last term 0.14 dB.
    The squeal is a tone at the mode's frequency; the A-weighted level adds A(f) (IEC 61672-1).
    Level changes follow 20 lg(A w / A w_ref), as in the UQ paper's Figure 7a.

    Parameters
    ----------
    amplitude : array_like
        Velocity amplitude A w [m/s].
    frequency : array_like
        Frequency of the tone [Hz].
    radiating_area : array_like
        Radiating area S [m2] (both sides of a 0.84 m wheel's web and tread, about 0.9 m2).
    radiation_efficiency : array_like
        sigma [-].
    spatial_average : array_like
        Surface average of the squared velocity relative to the contact point's [-].
    distance : array_like
        Source to receiver r [m].
    solid_angle : float
        Solid angle the wheel radiates into [sr].

    Returns
    -------
    RadiatedLevel
        Lw [dB re 1 pW], Lp [dB re 20 uPa], Lp A-weighted [dB(A)].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 3.3, Figure 7a.
    .. [2] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of
       Control*, Elsevier, Oxford, 2009, sections 5.2 and 13.
    """
    amp = np.asarray(amplitude, float)
    mean_square = np.asarray(spatial_average, float) * amp**2 / 2.0
    power = RHO0_C0 * np.asarray(radiation_efficiency, float) * np.asarray(radiating_area, float) * mean_square
    pressure_sq = RHO0_C0 * power / (solid_angle * np.asarray(distance, float) ** 2)  # far field, I = p^2 / (rho0 c0)
    with np.errstate(divide="ignore"):
        lw = 10.0 * np.log10(power / REFERENCE_POWER_W)
        lp = 10.0 * np.log10(pressure_sq / REFERENCE_PRESSURE_PA**2)
    return RadiatedLevel(lw, lp, lp + a_weighting_db(frequency))


def relative_level(amplitude: ArrayLike, reference: ArrayLike = REFERENCE_VELOCITY_MPS) -> FloatArray:
    """Level change of a squeal amplitude against a reference, 20 lg(A w / A w_ref).

    Sound power goes with the velocity squared, so the level changes by 20 lg of the amplitude ratio.

    Parameters
    ----------
    amplitude : array_like
        Velocity amplitude A w [m/s].
    reference : array_like
        Reference amplitude A w_ref [m/s].

    Returns
    -------
    ndarray
        Level change [dB] (-inf for a zero amplitude).

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 3.3, Figure 7a.
    """
    with np.errstate(divide="ignore"):
        return 20.0 * np.log10(np.asarray(amplitude, float) / np.asarray(reference, float))
