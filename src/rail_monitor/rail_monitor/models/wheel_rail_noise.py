"""Rolling noise from roughness: a mechanics model in the spirit of TWINS and the UQ paper's RRNPS.

Chain per 1/3-octave band (Remington, J. Acoust. Soc. Am. 81 (1987) 1805-1823; Thompson,
J. Sound Vib. 161 (1993) 387-482; Thompson, Railway Noise and Vibration, Elsevier 2009, ch. 5-6):

1. Combined roughness r (rail + wheel, mean square per band) through the contact filter |F|^2
   (models.contact_filter, band-averaged over the band's wavelengths lambda = v / f).
2. Contact force and vertical velocities for a unit roughness between wheel and rail, with the
   wheel, rail and contact-spring receptances alpha_W, alpha_R, alpha_C = 1 / k_H:

       F = r / (alpha_W + alpha_R + alpha_C),  v_R = i w alpha_R F,  v_W = -i w alpha_W F,

   alpha_W = -1 / (M w^2) + sum_n phi_n^2 / (w_n^2 - w^2 + 2 i zeta_n w_n w): the unsprung mass M
   plus the wheel's flexible modes at the contact (models.wheel_modes, unit generalised mass,
   phi_n the radial displacement at the contact).

3. Radiated power per wheel-rail contact, W = rho0 c0 sigma S <v^2> (models.radiation):
   * rail: the vibration decays along the rail at the track decay rate Delta [dB/m]
     (models.track.decay_rate), so the squared velocity integrated over both sides is
     |v_R|^2 x 2 x 4.343 / Delta; radiation of an equivalent rigid cylinder of radius a_R
     oscillating vertically (sigma_1, power rho0 c0 sigma pi a_R v^2 per metre);
   * sleepers: each rail seat moves with the rail times the seat's transmissibility
     (models.track.sleeper_transmissibility), summed over the seats under the decaying field,
     |v_R|^2 x 2 x 4.343 / (Delta d); radiation of a baffled piston of the half-sleeper's top area;
   * wheel: its rigid-body vertical motion (the unsprung mass), radiated by its rim as an
     oscillating cylinder of the wheel's radius and the rim's width, plus each flexible mode's
     axial and radial surface motion with the radiation efficiency of its far field's order
     (modal_wheel_power).

The result per axle (two contacts) is a transfer L_H,mech = 10 lg(W / r^2) [dB re 1 pW per
(1 um)^2 of roughness], so that L_W = L_R,TOT + L_H,mech, the form of CNOSSOS-EU's eqs.
2.3.7-2.3.8 and directly comparable to its tables. Transfers are band averages of the squared
transfer over ``points`` log-spaced frequencies per band (enough to resolve the wheel's
resonances as the rail damps them: 400 per band converge to 0.3 dB).

Not modelled: lateral rail and wheel motion and the lateral contact force (which excite the
axial modes more than the vertical force's offset does: TWINS's wheel is louder, above all
below 2 kHz), the wheel's rotation (which splits each mode in two), and shielding by the
vehicle body.

References
----------
.. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and acoustic
   phenomena", seminar paper, section 2.2.
.. [2] P. J. Remington, "Wheel/rail rolling noise, I: Theoretical analysis", *Journal of the Acoustical
   Society of America* 81(6) (1987) 1805-1823.
.. [3] D. J. Thompson, "Wheel-rail noise generation, parts I-V", *Journal of Sound and Vibration* 161(3)
   (1993) 387-482.
.. [4] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
   Elsevier, Oxford, 2009, chapters 5-6.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models import track
from rail_monitor.models import wheel_modes as wm
from rail_monitor.models.contact_filter import hertzian_line_filter
from rail_monitor.models.iec61260 import G, exact_centre
from rail_monitor.models.wheel_rail_radiation import (
    modal_damping,
    modal_terms,
    modal_wheel_power,
    rail_power,
    sleeper_power,
    wheel_power,
)

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]
COMPONENTS = ("rail", "sleeper", "wheel")


@dataclass(frozen=True)
class Radiators:
    """Radiating geometry [m, m2].

    rail_radius_m: equivalent cylinder for vertical rail motion, pi a = twice the foot width of
    UIC60 (150 mm; EN 13674-1), the high-frequency limit of a rail radiating from its foot's two
    faces. sleeper_area_m2: top face of half a monoblock sleeper (2.6 m x 0.25 m / 2).
    wheel_rim_width_m: 135 mm, the UIC rim width (EN 13715 profile S1002).
    """

    rail_radius_m: float = 0.3 / np.pi
    sleeper_area_m2: float = 0.325
    wheel_rim_width_m: float = 0.135


def band_frequencies(band: ArrayLike, points: int) -> FloatArray:
    """Log-spaced frequencies inside each 1/3-octave band, for band averages.

    Parameters
    ----------
    band : array_like
        Band numbers [-].
    points : int
        Frequencies per band [-].

    Returns
    -------
    ndarray
        Frequencies [Hz], shape band.shape + (points,), evenly spaced in log between each
        band's edges.

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, eqs. 2-5 (the bands' edges).
    """
    offsets = ((np.arange(points) + 0.5) / points - 0.5) / 3.0      # in octaves, within +-1/6
    return exact_centre(band)[..., None] * G ** offsets


def contact_filter_power(speed_mps: ArrayLike, band: ArrayLike, semi_length_m: ArrayLike,
                         points: int = 5) -> FloatArray:
    """Band average of the contact filter's power |F|^2 at lambda = v / f.

    Parameters
    ----------
    speed_mps : array_like
        Speed v [m/s].
    band : array_like
        Band numbers [-].
    semi_length_m : array_like
        Contact semi-axis along the rail [m], broadcast against speed.
    points : int
        Frequencies averaged per band [-].

    Returns
    -------
    ndarray
        Mean |F|^2 [-], shape speed.shape + band.shape.

    References
    ----------
    .. [1] P. J. Remington, "Wheel/rail rolling noise, I: Theoretical analysis", *Journal of the
       Acoustical Society of America* 81(6) (1987) 1805-1823.
    """
    f = band_frequencies(band, points)                                   # (B, P)
    v = np.asarray(speed_mps, float)[..., None, None]
    a = np.asarray(semi_length_m, float)[..., None, None]
    return np.mean(hertzian_line_filter(v / f, a) ** 2, axis=-1)


def contact_velocity_ratios(frequency: ArrayLike, alpha_rail: ArrayLike, alpha_wheel: ArrayLike,
                            contact_stiffness_npm: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Squared rail and wheel velocities per unit roughness displacement between them.

    A unit roughness is taken up by the wheel, the rail and the contact spring in series:
    v_R / r = i w alpha_R / (alpha_R + alpha_W + alpha_C), likewise the wheel with the opposite sign.

    Parameters
    ----------
    frequency : array_like
        Frequency [Hz].
    alpha_rail, alpha_wheel : array_like
        Rail and wheel receptances at the contact [m/N] (complex).
    contact_stiffness_npm : array_like
        Linearised contact stiffness [N/m].

    Returns
    -------
    tuple of ndarray
        |v_R / r|^2 and |v_W / r|^2 [1/s2].

    References
    ----------
    .. [1] P. J. Remington, "Wheel/rail rolling noise, I: Theoretical analysis", *Journal of the
       Acoustical Society of America* 81(6) (1987) 1805-1823.
    .. [2] D. J. Thompson, "Wheel-rail noise generation, parts I-V", *Journal of Sound and Vibration*
       161(3) (1993) 387-482 (part II, the interaction).
    """
    w = 2.0 * np.pi * np.asarray(frequency, float)
    a_r, a_w = np.asarray(alpha_rail), np.asarray(alpha_wheel)
    total = a_r + a_w + 1.0 / np.asarray(contact_stiffness_npm, float)
    return np.abs(w * a_r / total) ** 2, np.abs(w * a_w / total) ** 2


def axle_transfer(band: ArrayLike, trk: track.Track, unsprung_mass_kg: float, contact_stiffness_npm: float,
                  wheel_diameter_m: float, radiators: Radiators = Radiators(), points: int = 5,
                  beam: str = "timoshenko", modes: wm.WheelModes | None = None,
                  wheel_damping_ratio: float = 1.0e-4) -> dict[str, FloatArray]:
    """Transfer from roughness to sound power per component for one axle (two contacts), L_H,mech.

    Speed-independent: with L_R,TOT [dB re 1 um] (filtered), L_W = L_R,TOT + L_H,mech per axle.
    ``points`` per band must resolve the wheel's resonances as the rail couples them (about 400).

    Parameters
    ----------
    band : array_like
        Band numbers [-].
    trk : Track
        The track (SI) [-].
    unsprung_mass_kg : float
        Unsprung mass per wheel [kg].
    contact_stiffness_npm : float
        Linearised contact stiffness [N/m].
    wheel_diameter_m : float
        Wheel diameter [m].
    radiators : Radiators
        Rail, sleeper and wheel radiating geometry [m, m2].
    points : int
        Frequencies averaged per band [-].
    beam : str
        'timoshenko' or 'euler' [-].
    modes : WheelModes, optional
        The wheel's flexible modes (None: a rigid wheel) [-].
    wheel_damping_ratio : float
        zeta of the modes with two or more nodal diameters [-] (:func:`modal_damping`).

    Returns
    -------
    dict
        {component: L_H,mech [dB re 1 pW per (1 um)^2 of roughness], per band}.

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.2 (RRNPS).
    .. [2] P. J. Remington, "Wheel/rail rolling noise, I: Theoretical analysis", *Journal of the
       Acoustical Society of America* 81(6) (1987) 1805-1823.
    .. [3] D. J. Thompson, "Wheel-rail noise generation, parts I-V", *Journal of Sound and Vibration*
       161(3) (1993) 387-482.
    """
    f = band_frequencies(band, points)
    alpha_r = track.continuous_receptance(f, trk, beam)
    alpha_rigid = wheel_receptance(f, unsprung_mass_kg)
    if modes is None:
        terms = None
        alpha_w = alpha_rigid
    else:
        terms = modal_terms(f, modes, modal_damping(modes.nodal_diameters, wheel_damping_ratio))
        alpha_w = alpha_rigid + np.sum(terms * modes.contact_radial, axis=-1)
    vr2, _ = contact_velocity_ratios(f, alpha_r, alpha_w, contact_stiffness_npm)
    force2 = np.abs(1.0 / (alpha_r + alpha_w + 1.0 / contact_stiffness_npm)) ** 2   # |F / r|^2 [N2/m2]
    wheel = wheel_power(force2 * np.abs(2.0 * np.pi * f * alpha_rigid) ** 2, f, wheel_diameter_m,
                        radiators.wheel_rim_width_m)
    if terms is not None:
        wheel = wheel + modal_wheel_power(force2, f, modes, terms)
    decay = np.maximum(track.decay_rate(f, trk, beam), 1e-3)
    per_contact = {
        "rail": rail_power(vr2, f, decay, radiators.rail_radius_m),
        "sleeper": sleeper_power(vr2, f, decay, track.sleeper_transmissibility(f, trk), trk.sleeper_spacing_m,
                                 radiators.sleeper_area_m2),
        "wheel": wheel,
    }
    # W per unit r^2 [W/m2] -> dB: r^2 re (1 um)^2 and W re 1 pW cancel (1e-12 both).
    return {name: 10.0 * np.log10(2.0 * np.mean(w, axis=-1)) for name, w in per_contact.items()}


def wheel_receptance(frequency: ArrayLike, unsprung_mass: float = 600.0,
                     modes: tuple[tuple[float, float, float], ...] = ()) -> ComplexArray:
    """Vertical wheel receptance at the contact: the rigid unsprung mass plus the wheel's modes.

    Each mode adds 1 / (m_n (w_n^2 - w^2 + 2 i zeta_n w_n w)).

    Parameters
    ----------
    frequency : array_like
        Frequency [Hz].
    unsprung_mass : float
        Unsprung mass per wheel [kg].
    modes : tuple of (float, float, float)
        (natural frequency [Hz], modal mass [kg], damping ratio [-]) of each mode seen at the contact.

    Returns
    -------
    ndarray of complex
        Receptance [m/N].

    References
    ----------
    .. [1] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, the chapter on wheel vibration.
    """
    w = 2 * np.pi * np.asarray(frequency, float)
    out = -1.0 / (unsprung_mass * w**2) + 0j
    for fn, mn, zn in modes:
        wn = 2 * np.pi * fn
        out = out + 1.0 / (mn * (wn**2 - w**2 + 2j * zn * wn * w))
    return out
