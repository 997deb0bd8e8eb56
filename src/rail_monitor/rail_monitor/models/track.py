"""Vertical track receptance: rail as an Euler or Timoshenko beam on a two-layer support.

The one track model of the project (corrugation growth and rolling noise both use it).
Support per rail seat: rail pad k_p (1 + i eta_p), half-sleeper mass m_s, ballast
k_b (1 + i eta_b), at spacing d. Its dynamic stiffness is

    K(w) = k_p* (k_b* - m_s w^2) / (k_p* + k_b* - m_s w^2)                                  [N/m]

*Continuous support* smears it to s = K / d per metre. Fourier-transforming the beam equations
(Timoshenko: shear stiffness kappa G A, rotary inertia rho I) gives the displacement
spectrum W(xi) / F = (EI xi^2 + g) / (a xi^4 + b xi^2 + c) with g = kappa G A - rho I w^2,
a = EI kappa G A, b = (s - m' w^2) EI - kappa G A rho I w^2, c = (s - m' w^2) g. With the roots
u1, u2 of a u^2 + b u + c = 0 and k_j = sqrt(u_j) in the upper half plane, residues give the
transfer receptance at distance x

    alpha(x) = (i / 2) sum_j A_j exp(i k_j |x|) / k_j,    A_j = (EI u_j + g) / (a (u_j - u_other))

(Euler: EI xi^4 + s - m' w^2, A_j = +-1 / (EI (u1 - u2))). The static limit is the Winkler
result 1 / alpha = 2 s / beta, beta = (s / 4EI)^(1/4) (Hetenyi 1946; Knothe & Grassie, Vehicle
System Dynamics 22 (1993) 209-262, for the track models and their resonances).

*Discrete supports* use the free rail's Green's function G(x) (s = 0) and the support forces
-K w_n at x_n = n d, n = -N..N: (I + K G(x_m - x_n)) w = G(x_m - x_F) F, then
w_F = G(0) F - sum_n G(x_F - x_n) K w_n. This resolves the pinned-pinned resonance (peak at
mid-span, dip above a sleeper, near 1 kHz for UIC60 on 0.6 m bays).

Loss factors enter as complex moduli: E (1 + i eta_r), G (1 + i eta_r). Time dependence
exp(+i w t); a receptance is displacement over force in the force's direction (static > 0).

References
----------
.. [1] K. Knothe and S. L. Grassie, "Modelling of railway track and vehicle/track interaction at high
   frequencies", *Vehicle System Dynamics* 22(3-4) (1993) 209-262.
.. [2] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
   Elsevier, Oxford, 2009, chapter 3 (track vibration).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

ComplexArray = NDArray[np.complex128]

BEAMS = ("timoshenko", "euler")


@dataclass(frozen=True)
class Track:
    """Track parameters (SI). Defaults: UIC60 rail on a typical ballasted track (docs/models.md
    section 2: E = 210 GPa, A = 7.69e-3 m2, I = 30.55e-6 m4, m' = 60.4 kg/m, kappa = 0.4,
    eta_r = 0.02; pad 350 MN/m, eta 0.25; half sleeper 150 kg; ballast 50 MN/m, eta 1.0; d = 0.6 m).
    """

    young_modulus_pa: float = 210e9
    poisson_ratio: float = 0.3
    area_m2: float = 7.69e-3
    second_moment_m4: float = 30.55e-6
    mass_per_length_kgpm: float = 60.4
    shear_coefficient: float = 0.4
    rail_loss_factor: float = 0.02
    pad_stiffness_npm: float = 350e6
    pad_loss_factor: float = 0.25
    sleeper_mass_kg: float = 150.0
    ballast_stiffness_npm: float = 50e6
    ballast_loss_factor: float = 1.0
    sleeper_spacing_m: float = 0.6

    def with_(self, **changes: float) -> Track:
        return replace(self, **changes)

    @property
    def bending_stiffness(self) -> complex:
        """E* I [N m2] with the rail's loss factor."""
        return self.young_modulus_pa * (1 + 1j * self.rail_loss_factor) * self.second_moment_m4

    @property
    def shear_stiffness(self) -> complex:
        """kappa G* A [N] with the rail's loss factor."""
        g = self.young_modulus_pa / (2 * (1 + self.poisson_ratio))
        return self.shear_coefficient * g * (1 + 1j * self.rail_loss_factor) * self.area_m2

    @property
    def rotary_inertia(self) -> float:
        """rho I [kg m] (rho = m' / A)."""
        return self.mass_per_length_kgpm / self.area_m2 * self.second_moment_m4


def support_stiffness(frequency: ArrayLike, track: Track) -> ComplexArray:
    """Dynamic stiffness of one rail seat: K = k_p* (k_b* - m_s w^2) / (k_p* + k_b* - m_s w^2).

    Parameters
    ----------
    frequency : array_like
        Frequency [Hz].
    track : Track
        Rail, pad, half-sleeper and ballast parameters (SI: [m], [kg], [N/m], [Pa], loss factors [-]).

    Returns
    -------
    ndarray of complex
        K [N/m]; the pad's and the ballast's loss factors give its imaginary part.

    References
    ----------
    .. [1] K. Knothe and S. L. Grassie, "Modelling of railway track and vehicle/track interaction at
       high frequencies", *Vehicle System Dynamics* 22(3-4) (1993) 209-262.
    """
    kp, lower = _seat(frequency, track)
    return kp * lower / (kp + lower)


def _seat(frequency: ArrayLike, track: Track) -> tuple[complex, ComplexArray]:
    """Pad stiffness k_p* and the stiffness under it, k_b* - m_s w^2 [N/m], of one rail seat."""
    w2 = (2 * np.pi * np.asarray(frequency, float)) ** 2
    kp = track.pad_stiffness_npm * (1 + 1j * track.pad_loss_factor)
    kb = track.ballast_stiffness_npm * (1 + 1j * track.ballast_loss_factor)
    return kp, kb - track.sleeper_mass_kg * w2


def _poles(w: NDArray[np.float64], s: ComplexArray, track: Track, beam: str) -> tuple[ComplexArray, ...]:
    """Upper-half-plane wavenumbers k1, k2 [1/m] and residue weights A1, A2 of the beam on support s [N/m2]."""
    ei, mass = track.bending_stiffness, track.mass_per_length_kgpm
    dyn = s - mass * w**2
    if beam == "euler":
        root = np.sqrt(-dyn / ei + 0j)
        u1, u2 = root, -root
        a1 = 1.0 / (ei * (u1 - u2))
        a2 = -a1
    elif beam == "timoshenko":
        kga, rho_i = track.shear_stiffness, track.rotary_inertia
        g = kga - rho_i * w**2
        a = ei * kga
        b = dyn * ei - kga * rho_i * w**2
        c = dyn * g
        disc = np.sqrt(b * b - 4 * a * c + 0j)
        u1, u2 = (-b + disc) / (2 * a), (-b - disc) / (2 * a)
        a1 = (ei * u1 + g) / (a * (u1 - u2))
        a2 = (ei * u2 + g) / (a * (u2 - u1))
    else:
        raise ValueError(f"unknown beam {beam!r}; use one of {BEAMS}")
    k1, k2 = np.sqrt(u1 + 0j), np.sqrt(u2 + 0j)
    k1 = np.where(k1.imag < 0, -k1, k1)  # the pole closing the upper half plane decays along +x
    k2 = np.where(k2.imag < 0, -k2, k2)
    return k1, k2, a1, a2


def _green(x: ArrayLike, poles: tuple[ComplexArray, ...]) -> ComplexArray:
    """Transfer receptance alpha(x) [m/N] of an infinite beam from its poles (broadcast x against them)."""
    k1, k2, a1, a2 = poles
    ax = np.abs(np.asarray(x, float))
    return 0.5j * (a1 * np.exp(1j * k1 * ax) / k1 + a2 * np.exp(1j * k2 * ax) / k2)


def continuous_receptance(frequency: ArrayLike, track: Track, beam: str = "timoshenko",
                          distance: ArrayLike = 0.0) -> ComplexArray:
    """Rail receptance on the smeared support s = K / d, at a distance from the force.

    Parameters
    ----------
    frequency, track : array_like, Track
        As for :func:`support_stiffness`: frequency [Hz] and the track (SI) [-].
    beam : str
        'timoshenko' or 'euler' [-].
    distance : array_like
        From the force along the rail [m].

    Returns
    -------
    ndarray of complex
        Receptance [m/N]: the rail's displacement over the force, in magnitude and phase.

    References
    ----------
    .. [1] K. Knothe and S. L. Grassie, "Modelling of railway track and vehicle/track interaction at
       high frequencies", *Vehicle System Dynamics* 22(3-4) (1993) 209-262.
    .. [2] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, chapter 3.
    """
    f = np.asarray(frequency, float)
    w = 2 * np.pi * f
    s = support_stiffness(f, track) / track.sleeper_spacing_m
    return _green(distance, _poles(w, s, track, beam))


def decay_rate(frequency: ArrayLike, track: Track, beam: str = "timoshenko") -> NDArray[np.float64]:
    """Track decay rate of the continuous model, 20 lg(e) Im(k) of its propagating wave.

    Of the two wavenumbers, the propagating one has the smaller Im(k) (the other is the near field
    or, above the cut-on, the second wave). The squared vibration of a rail excited at x = 0 falls
    as exp(-2 Im(k) |x|), so its integral along the rail is |v0|^2 / Im(k): the rail's effective
    radiating length is 2 x 4.343 / decay rate.

    Parameters
    ----------
    frequency, track, beam : array_like, Track, str
        As for :func:`continuous_receptance`: frequency [Hz], the track (SI), the beam theory [-].

    Returns
    -------
    ndarray
        Decay rate [dB/m].

    References
    ----------
    .. [1] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, section 5.6.
    """
    f = np.asarray(frequency, float)
    s = support_stiffness(f, track) / track.sleeper_spacing_m
    k1, k2, _, _ = _poles(2 * np.pi * f, s, track, beam)
    return 20.0 * np.log10(np.e) * np.minimum(k1.imag, k2.imag)


def sleeper_transmissibility(frequency: ArrayLike, track: Track) -> ComplexArray:
    """Half-sleeper displacement over rail displacement at a seat, k_p* / (k_p* + k_b* - m_s w^2).

    Parameters
    ----------
    frequency, track : array_like, Track
        As for :func:`support_stiffness`: frequency [Hz] and the track (SI) [-].

    Returns
    -------
    ndarray of complex
        The ratio [-].

    References
    ----------
    .. [1] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, chapter 3 (the two-layer support).
    """
    kp, lower = _seat(frequency, track)
    return kp / (kp + lower)


_FREQUENCIES_AT_ONCE = 50  # 50 x 121 x 121 complex: 12 MB per array


def discrete_receptance(frequency: ArrayLike, track: Track, beam: str = "timoshenko", position: ArrayLike = 0.5,
                        supports: int = 121) -> ComplexArray:
    """Rail point receptance on discrete supports, the force at a position within a bay.

    Several positions share one factorisation per frequency.

    Parameters
    ----------
    frequency, track, beam : array_like, Track, str
        As for :func:`continuous_receptance`: frequency [Hz], the track (SI), the beam theory [-].
    position : array_like
        Fraction of the sleeper spacing from a support [-] (0 above a sleeper, 0.5 mid-span).
    supports : int
        Rail seats modelled (odd, at least 3) [-].

    Returns
    -------
    ndarray of complex
        Receptance [m/N], shape frequency.shape + position.shape.

    References
    ----------
    .. [1] K. Knothe and S. L. Grassie, "Modelling of railway track and vehicle/track interaction at
       high frequencies", *Vehicle System Dynamics* 22(3-4) (1993) 209-262 (periodically supported track).
    """
    if supports < 3 or supports % 2 == 0:
        raise ValueError("supports must be odd and at least 3")
    f = np.atleast_1d(np.asarray(frequency, float)).ravel()
    if f.size > _FREQUENCIES_AT_ONCE:  # each frequency is independent: bound the (F, N, N) arrays' memory
        parts = [discrete_receptance(f[i:i + _FREQUENCIES_AT_ONCE], track, beam, position, supports)
                 for i in range(0, f.size, _FREQUENCIES_AT_ONCE)]
        return np.concatenate(parts).reshape(np.shape(frequency) + np.shape(position))
    xf = np.atleast_1d(np.asarray(position, float)) * track.sleeper_spacing_m
    w = 2 * np.pi * f
    half = supports // 2
    xn = np.arange(-half, half + 1) * track.sleeper_spacing_m
    free = _poles(w, np.zeros_like(w, dtype=complex), track, beam)
    per_f = tuple(p[:, None, None] for p in free)
    g_nn = _green(xn[None, :, None] - xn[None, None, :], per_f)            # (F, N, N)
    g_nf = _green(xn[None, :, None] - xf[None, None, :], per_f)            # (F, N, P)
    k = support_stiffness(f, track)
    # One BLAS thread whatever the process allows: LAPACK's threaded solve rounds differently
    # (5e-10 relative here), and the receptance, cached on disk and shared by every process of a
    # site, must not depend on which process built it.
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        wn = np.linalg.solve(np.eye(supports)[None] + k[:, None, None] * g_nn, g_nf)  # support displacements per unit F
    out = _green(0.0, free)[:, None] - k[:, None] * np.einsum("fnp,fnp->fp", g_nf, wn)
    return out.reshape(np.shape(frequency) + np.shape(position))


def bay_averaged_receptance(frequency: ArrayLike, track: Track, beam: str = "timoshenko", positions: int = 8,
                            supports: int = 121) -> ComplexArray:
    """Discrete-support receptance averaged over equally spaced points of a bay.

    Parameters
    ----------
    frequency, track, beam : array_like, Track, str
        As for :func:`continuous_receptance`: frequency [Hz], the track (SI), the beam theory [-].
    positions : int
        Points of the bay averaged [-].
    supports : int
        Rail seats modelled [-].

    Returns
    -------
    ndarray of complex
        Mean receptance over the bay [m/N].

    References
    ----------
    .. [1] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, chapter 3 (the receptance over a bay).
    """
    xs = (np.arange(positions) + 0.5) / positions
    return discrete_receptance(frequency, track, beam, xs, supports).mean(axis=-1)


def static_stiffness(track: Track) -> float:
    """Winkler static stiffness of the continuous model, 2 s / beta, s = K(0) / d.

    Parameters
    ----------
    track : Track
        The track; its support at 0 Hz and the rail's bending stiffness [N/m, N m2] matter.

    Returns
    -------
    float
        Stiffness [N/m].

    References
    ----------
    .. [1] M. Hetenyi, *Beams on Elastic Foundation*, University of Michigan Press, Ann Arbor, 1946.
    """
    s = 1.0 / (1.0 / track.pad_stiffness_npm + 1.0 / track.ballast_stiffness_npm) / track.sleeper_spacing_m
    beta = (s / (4.0 * track.young_modulus_pa * track.second_moment_m4)) ** 0.25
    return 2.0 * s / beta
