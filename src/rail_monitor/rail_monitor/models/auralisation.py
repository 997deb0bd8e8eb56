"""A predicted pass-by made audible: the pressure at the receiver [Pa], sampled, from the rolling
noise's band spectra per source path and the squeal's tone.

Rolling noise: the train is a line source of length L moving at v (models.passby's line), its front
at x_f = v t past the receiver's perpendicular; the time shape of each band's mean square pressure is
the kernel's, S(t) = G(x_f) - G(x_f - L) (models.passby_kernel: spherical spreading and CNOSSOS-EU's
horizontal directivity, on the direct path R), scaled so that its mean over the pass time L / v is the
predicted band level LpZeq,Tp:

    p_b^2(t) = p0^2 10^(L_b / 10) S(t) / mean over Tp of S

(the ground image and an elevated source line differ from the direct path by a few per cent in R:
their shapes are taken as the direct path's). Each band is Gaussian noise of flat density between
the band's exact edges, scaled sample by sample to that envelope. The broadband noise is not
Doppler-shifted (at 100 km/h a shift of 8 %, a third of a band, moves little energy across band
edges).

Squeal: a tone of the predicted frequency f0 [Hz] from a point at the train's middle, of level L at
the receiver's distance d (the squeal model's level) and spherical spreading p^2 ~ d^2 / r^2, heard at
t as emitted at the retarded time tau (t = tau + r(tau) / c), its phase 2 pi f0 tau: the Doppler
shift follows, f0 / (1 - v cos(theta) / c) with theta the angle at emission between the track ahead
and the line to the receiver.

The record holds ``pre_s`` before the front reaches the perpendicular and ``post_s`` after the rear
has passed it; the pass is the window [pre_s, pre_s + L / v].
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import fft

from rail_monitor.models.iec61260 import band_edges
from rail_monitor.models.passby_kernel import kernel_antiderivative, kernel_window_mean

P0_PA = 20e-6
SOUND_SPEED_MPS = 343.0


def line_band_envelope(lp_db: ArrayLike, distance_m: float, path_m: float, length_m: float, speed_mps: float,
                       t_s: ArrayLike) -> NDArray[np.float64]:
    """The time shape of each band's mean square pressure from a moving line source.

    S(t) = G(x_f) - G(x_f - L), the kernel's (spherical spreading and CNOSSOS-EU's horizontal
    directivity on the direct path), scaled so that its mean over the pass time L / v is the band's
    predicted level.

    Parameters
    ----------
    lp_db : array_like
        Band levels over the pass time [dB re 20 uPa].
    distance_m : float
        Horizontal distance to the track [m].
    path_m : float
        Perpendicular distance of the path [m].
    length_m : float
        Train length L [m].
    speed_mps : float
        Speed v [m/s].
    t_s : array_like
        Times, 0 when the front passes the perpendicular [s].

    Returns
    -------
    ndarray
        p_b^2(t) / p0^2 [-], bands x times.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, eq. 2.3.15 (the horizontal directivity).
    """
    x = speed_mps * np.asarray(t_s, float)
    shape = kernel_antiderivative(x, distance_m, path_m) - kernel_antiderivative(x - length_m, distance_m, path_m)
    scale = 10.0 ** (np.asarray(lp_db, float) / 10.0) / float(kernel_window_mean(length_m, distance_m, path_m))
    return scale[:, None] * shape[None, :]


def band_noise(band: ArrayLike, envelope: ArrayLike, fs_hz: float, rng: np.random.Generator) -> NDArray[np.float64]:
    """Band-limited noise shaped by an envelope: per band Gaussian noise of flat density between its
    exact edges and unit mean square, times p0 sqrt(envelope), summed over the bands.

    Parameters
    ----------
    band : array_like
        Band numbers [-].
    envelope : array_like
        p_b^2 / p0^2 [-], bands x samples.
    fs_hz : float
        Sampling rate [Hz].
    rng : numpy.random.Generator
        The noise's generator [-].

    Returns
    -------
    ndarray
        Pressure [Pa], the bands summed, one value per sample.

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, eqs. 4-5 (the band edges).
    """
    env = np.asarray(envelope, float)
    n = env.shape[1]
    f = fft.rfftfreq(n, 1.0 / fs_hz)
    out = np.zeros(n)
    for b, e in zip(np.atleast_1d(band), env, strict=True):
        lo, hi = band_edges(b)
        spectrum = fft.rfft(rng.standard_normal(n))
        spectrum[(f < lo) | (f >= hi)] = 0.0
        noise = fft.irfft(spectrum, n)
        rms = np.sqrt(np.mean(noise**2))
        if rms > 0:
            out += noise / rms * P0_PA * np.sqrt(e)
    return out


def moving_tone(frequency_hz: float, level_db: float, distance_m: float, length_m: float, speed_mps: float,
                t_s: ArrayLike) -> NDArray[np.float64]:
    """The pressure of a tone from a point moving with the train, heard with its Doppler shift.

    The point is the train's middle (front at the perpendicular at t = 0); spherical spreading; heard
    at t as emitted at the retarded time tau, t = tau + r(tau) / c (a quadratic in t - tau, solved
    exactly).

    Parameters
    ----------
    frequency_hz : float
        The emitted frequency [Hz].
    level_db : float
        Level at distance_m [dB re 20 uPa].
    distance_m : float
        Distance of the level and of the receiver from the track [m].
    length_m : float
        Train length [m].
    speed_mps : float
        Speed [m/s].
    t_s : array_like
        Times [s].

    Returns
    -------
    ndarray
        The tone's pressure at the receiver [Pa].

    References
    ----------
    .. [1] P. M. Morse and K. U. Ingard, *Theoretical Acoustics*, McGraw-Hill, New York, 1968
       (the field of a moving source, retarded time).
    """
    t = np.asarray(t_s, float)
    c, v = SOUND_SPEED_MPS, speed_mps
    x_now = v * t - length_m / 2.0  # the source's position at the time of hearing
    u = (-x_now * v + np.sqrt((x_now * v) ** 2 + (c * c - v * v) * (distance_m**2 + x_now**2))) / (c * c - v * v)
    amplitude = np.sqrt(2.0) * P0_PA * 10.0 ** (level_db / 20.0) * distance_m / (c * u)
    return amplitude * np.sin(2.0 * np.pi * frequency_hz * (t - u))


def passby_pressure(band: ArrayLike, lp_db: ArrayLike, distance_m: float, path_m: float, length_m: float,
                    speed_mps: float, fs_hz: float = 48_000.0, pre_s: float = 5.0, post_s: float = 5.0,
                    tone: tuple[float, float] | None = None, seed: int = 0) -> NDArray[np.float64]:
    """The sampled pressure of a predicted pass: rolling noise by band and, where given, squeal's tone.

    Parameters
    ----------
    band : array_like
        Band numbers [-].
    lp_db : array_like
        Band levels over the pass time [dB re 20 uPa].
    distance_m, path_m : float
        Horizontal distance and perpendicular path length to the track [m].
    length_m : float
        Train length [m].
    speed_mps : float
        Speed [m/s].
    fs_hz : float
        Sampling rate [Hz].
    pre_s, post_s : float
        Record before the front reaches the perpendicular and after the rear has passed it [s].
    tone : (float, float), optional
        Squeal's (frequency [Hz], level at distance_m [dB re 20 uPa]).
    seed : int
        Seed of the noise [-].

    Returns
    -------
    ndarray
        Pressure [Pa]; the pass is the window [pre_s, pre_s + length_m / speed_mps].

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles* (the pass's window).
    .. [2] P. M. Morse and K. U. Ingard, *Theoretical Acoustics*, McGraw-Hill, New York, 1968.
    """
    t = np.arange(-pre_s, length_m / speed_mps + post_s, 1.0 / fs_hz)
    env = line_band_envelope(lp_db, distance_m, path_m, length_m, speed_mps, t)
    p = band_noise(band, env, fs_hz, np.random.default_rng(seed))
    if tone is not None:
        p = p + moving_tone(tone[0], tone[1], distance_m, length_m, speed_mps, t)
    return p
