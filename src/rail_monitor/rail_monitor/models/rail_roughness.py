"""Acoustic rail roughness from a trolley's displacement trace, processed as EN 15610 describes the
steps: spikes removed, the trace seen by a wheel (curvature processing), then the r.m.s. roughness
in one-third-octave wavelength bands.

- **Spikes** (dirt, a drop-out) are samples that stand further from the median of their neighbourhood
  (3 samples either side) than ``SPIKE_SIGMAS`` robust standard deviations (1.4826 x the median
  absolute deviation) of all such departures, and at least ``SPIKE_FLOOR_M``; each, with one
  neighbour either side, is replaced by a straight line between the samples around it.
- **Curvature processing**: a wheel of radius R cannot follow a dip narrower than its curvature
  allows. The trace it sees is the height of its lowest point when it rests on the rail above each
  sample, h(x) = max over |s| <= reach of [z(x + s) - s^2 / (2 R)] (the circle's parabola, to 0.01 %
  over the reach of 20 mm). Where the trace's curvature stays below 1/R the wheel rests on the
  rail beside the sample on a slope z', raising the trace by R z'^2 / 2 (0.4 um on a 10 um
  sinusoid of 50 mm); a dip narrower than the wheel's parabola is bridged.
- **Spectrum**: the processed trace, its mean and slope removed, Hann-windowed (its power restored by
  the window's mean square), as a periodogram in wavenumber; the power between the band edges of each
  wavelength band (centres 10^(n/10) m, base ten, edges a sixth of an octave either side, as the
  corrugation state's bands) is the band's mean square r^2 [m^2]; its level is 10 lg(r^2 / r0^2),
  r0 = 1 um. A band is given only where the trace holds at least three of its longest wavelengths
  and four samples of its shortest.

The thresholds of the spike removal and the reach are choices made here (EN 15610's own text was not
at hand); the band definition and the level's reference are the standard's.

References
----------
.. [1] EN 15610:2019, *Railway applications - Acoustics - Rail and wheel roughness measurement related
   to noise generation*, CEN, Brussels, 2019.
.. [2] D. J. Thompson, *Railway Noise and Vibration*, Elsevier, 2009, section 5.2 (roughness spectra,
   the contact filter, a wheel's curvature bridging short dips).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

R0_M = 1e-6
SPIKE_SIGMAS = 6.0
SPIKE_FLOOR_M = 20e-6
SPIKE_HALF_WINDOW = 3
WHEEL_RADIUS_M = 0.46
REACH_M = 0.02
HALF_BAND = 10.0 ** (1.0 / 20.0)  # a sixth of an octave, base ten


@dataclass(frozen=True)
class RoughnessSpectrum:
    wavelength_m: NDArray     # band centres [m], longest first
    rms_m: NDArray            # r.m.s. roughness per band [m]
    level_db: NDArray         # 10 lg(r^2 / r0^2) [dB re 1 um]
    spikes: int               # samples replaced by the spike removal
    length_m: float           # length of the trace [m]


def remove_spikes(z_m: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """A trolley's trace with its spikes replaced (module docstring), and which samples were replaced.

    Parameters
    ----------
    z_m : array_like
        Displacement trace [m].

    Returns
    -------
    tuple of ndarray
        The trace [m] and the mask of replaced samples [-].

    References
    ----------
    .. [1] EN 15610:2019, *Railway applications - Acoustics - Rail and wheel roughness measurement
       related to noise generation*, CEN, Brussels, 2019 (spike removal).
    """
    z = np.asarray(z_m, float)
    h = SPIKE_HALF_WINDOW
    padded = np.pad(z, h, mode="edge")
    windows = np.lib.stride_tricks.sliding_window_view(padded, 2 * h + 1)
    departure = z - np.median(windows, axis=1)
    spread = 1.4826 * np.median(np.abs(departure - np.median(departure)))
    spike = np.abs(departure) > max(SPIKE_SIGMAS * spread, SPIKE_FLOOR_M)
    replaced = spike | np.roll(spike, 1) | np.roll(spike, -1)
    replaced[[0, -1]] |= spike[[0, -1]]
    out = z.copy()
    if replaced.any() and not replaced.all():
        x = np.arange(len(z))
        out[replaced] = np.interp(x[replaced], x[~replaced], z[~replaced])
    return out, replaced


def wheel_trace(z_m: ArrayLike, dx_m: float, wheel_radius_m: float = WHEEL_RADIUS_M,
                reach_m: float = REACH_M) -> NDArray[np.float64]:
    """The trace a wheel resting on the rail sees: the rail's trace bridged by the wheel's curvature.

    Parameters
    ----------
    z_m : array_like
        The rail's trace [m].
    dx_m : float
        Sampling interval along the rail [m].
    wheel_radius_m : float
        Wheel radius [m].
    reach_m : float
        How far either side of a point the wheel's contact is looked for [m].

    Returns
    -------
    ndarray
        The wheel's trace [m].

    References
    ----------
    .. [1] EN 15610:2019, *Railway applications - Acoustics - Rail and wheel roughness measurement
       related to noise generation*, CEN, Brussels, 2019 (curvature processing).
    .. [2] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, section 5.2.
    """
    z = np.asarray(z_m, float)
    k = int(reach_m / dx_m)
    padded = np.pad(z, k, constant_values=-np.inf)
    out = z.copy()
    for s in range(-k, k + 1):
        if s:
            np.maximum(out, padded[k + s: k + s + len(z)] - (s * dx_m) ** 2 / (2.0 * wheel_radius_m), out=out)
    return out


def band_mean_squares(z_m: ArrayLike, dx_m: float, centres_m: ArrayLike) -> NDArray[np.float64]:
    """Mean square of a trace in each 1/3-octave wavelength band, its mean and slope removed.

    A Hann window is applied and its power restored.

    Parameters
    ----------
    z_m : array_like
        Trace [m].
    dx_m : float
        Sampling interval [m].
    centres_m : array_like
        Wavelength band centres [m].

    Returns
    -------
    ndarray
        Mean square roughness per band [m^2]; its root is the band's r.m.s. roughness.

    References
    ----------
    .. [1] EN 15610:2019, *Railway applications - Acoustics - Rail and wheel roughness measurement
       related to noise generation*, CEN, Brussels, 2019 (the one-third-octave wavelength spectrum).
    """
    z = np.asarray(z_m, float)
    n = len(z)
    x = np.arange(n)
    z = z - np.polyval(np.polyfit(x, z, 1), x)
    w = np.hanning(n)
    power = np.abs(np.fft.rfft(z * w)) ** 2 / np.mean(w**2) / n**2
    power[1:(n + 1) // 2] *= 2.0
    k = np.fft.rfftfreq(n, dx_m)  # wavenumber [1/m]
    c = np.asarray(centres_m, float)
    return np.array([power[(k >= 1.0 / (lam * HALF_BAND)) & (k < HALF_BAND / lam)].sum() for lam in c])


def roughness_spectrum(z_m: ArrayLike, dx_m: float, wheel_radius_m: float = WHEEL_RADIUS_M) -> RoughnessSpectrum:
    """The roughness spectrum of a trolley's trace: spikes removed, the wheel's trace, its band spectrum.

    Every band the trace resolves (module docstring). ValueError for a trace too short or not finite.

    Parameters
    ----------
    z_m, dx_m : array_like, float
        The trolley's trace [m] and its sampling interval [m].
    wheel_radius_m : float
        Wheel radius of the curvature processing [m].

    Returns
    -------
    RoughnessSpectrum
        Band centres [m], r.m.s. [m] and level [dB re 1 um] per band, spikes replaced [-] and the
        trace's length [m].

    References
    ----------
    .. [1] EN 15610:2019, *Railway applications - Acoustics - Rail and wheel roughness measurement
       related to noise generation*, CEN, Brussels, 2019.
    """
    z = np.asarray(z_m, float)
    if z.ndim != 1 or len(z) < 16 or not np.all(np.isfinite(z)) or not dx_m > 0:
        raise ValueError("a trace needs at least 16 finite samples at a positive spacing")
    clean, replaced = remove_spikes(z)
    seen = wheel_trace(clean, dx_m, wheel_radius_m)
    length = len(z) * dx_m
    shortest = int(np.ceil(10 * np.log10(4 * dx_m * HALF_BAND)))
    n = np.arange(shortest, int(np.floor(10 * np.log10(length / 3 / HALF_BAND))) + 1)
    centres = 10.0 ** (n[::-1] / 10.0)
    if not len(centres):
        raise ValueError(f"a trace of {length:g} m at {dx_m:g} m spacing resolves no wavelength band")
    ms = band_mean_squares(seen, dx_m, centres)
    with np.errstate(divide="ignore"):
        level = 10.0 * np.log10(ms / R0_M**2)
    return RoughnessSpectrum(centres, np.sqrt(ms), level, int(replaced.sum()), length)
