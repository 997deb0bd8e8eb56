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

from rail_monitor.models import radiation, track
from rail_monitor.models import wheel_modes as wm
from rail_monitor.models.contact_filter import hertzian_line_filter
from rail_monitor.models.iec61260 import G, exact_centre

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]
COMPONENTS = ("rail", "sleeper", "wheel")
NEPER_DB = 20.0 * np.log10(np.e)   # 8.686 dB per neper: decay rate [dB/m] = 8.686 Im(k)


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
    alpha_rigid = track.wheel_receptance(f, unsprung_mass_kg)
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
