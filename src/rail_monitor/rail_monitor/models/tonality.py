"""Tonal components of a sound and their audibility, by the method of ISO/PAS 20065:2016 (the
engineering method that DIN 45681:2005 introduced; ISO 1996-2:2017 Annex J points to it).

A narrow-band spectrum (Welch's average of Hann-windowed periodograms, a power spectral density
[Pa^2/Hz]) is searched for lines that stand out of their critical band. For a tone at f [Hz]:

- the critical band around it (Zwicker's width): delta_f_c = 25 + 75 (1 + 1.4 (f / 1 kHz)^2)^0.69 Hz;
- the tone level L_T: the power of the lines of the tone (the peak and its Hann main lobe,
  two lines either side) [dB re (20 uPa)^2];
- the masking noise level L_G: the mean density of the critical band's other lines (every line of
  every tone left out) times delta_f_c [dB];
- the masking index a_v = -2 - lg(1 + (f / 502 Hz)^2.5) dB;
- the audibility delta_L = L_T - L_G - a_v: positive when the tone is audible over its noise.

A line is a candidate where it is a local maximum at least 6 dB above the mean level (in dB) of the
densities of its critical band. Candidates closer than a critical band to a stronger one are merged into it (the
standard's treatment of several tones in one critical band is simplified to the strongest).

References
----------
.. [1] ISO/PAS 20065:2016, *Acoustics - Objective method for assessing the audibility of tones in
   noise - Engineering method*, International Organization for Standardization, Geneva, 2016.
.. [2] E. Zwicker and H. Fastl, *Psychoacoustics: Facts and Models*, 2nd ed., Springer, 1999,
   section 6.2 (critical bandwidth).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import signal

P0_PA = 20e-6
PROMINENCE_DB = 6.0     # a candidate line stands this far above its critical band's mean level
LOBE_LINES = 2          # lines either side of a peak that belong to a Hann-windowed tone
DYNAMIC_RANGE_DB = 100.0  # lines further below the strongest one are the record's numerical floor


@dataclass(frozen=True)
class Tone:
    frequency_hz: float
    level_db: float         # L_T [dB re 20 uPa]
    masking_db: float       # L_G, the masking noise in the critical band [dB re 20 uPa]
    audibility_db: float    # delta_L = L_T - L_G - a_v [dB]


def critical_bandwidth_hz(frequency_hz: ArrayLike) -> NDArray[np.float64]:
    """Width of the critical band around a frequency (Zwicker's), 25 + 75 (1 + 1.4 (f / 1 kHz)^2)^0.69.

    Parameters
    ----------
    frequency_hz : array_like
        Frequency f [Hz].

    Returns
    -------
    ndarray
        Critical bandwidth [Hz].

    References
    ----------
    .. [1] ISO/PAS 20065:2016, *Acoustics - Objective method for assessing the audibility of tones in
       noise - Engineering method*, eq. 3.
    .. [2] E. Zwicker and H. Fastl, *Psychoacoustics: Facts and Models*, 2nd ed., Springer, 1999,
       section 6.2.
    """
    f = np.asarray(frequency_hz, float)
    return 25.0 + 75.0 * (1.0 + 1.4 * (f / 1000.0) ** 2) ** 0.69


def masking_index_db(frequency_hz: ArrayLike) -> NDArray[np.float64]:
    """The masking index a_v of a tone at a frequency.

    Parameters
    ----------
    frequency_hz : array_like
        Frequency [Hz].

    Returns
    -------
    ndarray
        a_v [dB].

    References
    ----------
    .. [1] ISO/PAS 20065:2016, *Acoustics - Objective method for assessing the audibility of tones in
       noise - Engineering method*, eq. 9.
    """
    return -2.0 - np.log10(1.0 + (np.asarray(frequency_hz, float) / 502.0) ** 2.5)


def density(pressure_pa: ArrayLike, fs_hz: float, resolution_hz: float = 2.0) -> tuple[NDArray, NDArray]:
    """Power spectral density of a pressure record by Welch's method.

    Hann-windowed segments of 1 / resolution_hz seconds, half overlapping, averaged (one segment,
    zero-padded, when the record is shorter).

    Parameters
    ----------
    pressure_pa, fs_hz : array_like, float
        The record [Pa], sampled at fs_hz [Hz].
    resolution_hz : float
        Line spacing [Hz].

    Returns
    -------
    tuple of ndarray
        Frequencies [Hz] and the density [Pa^2/Hz].

    References
    ----------
    .. [1] ISO/PAS 20065:2016, *Acoustics - Objective method for assessing the audibility of tones in
       noise - Engineering method* (the narrow-band spectrum).
    .. [2] P. D. Welch, "The use of fast Fourier transform for the estimation of power spectra",
       *IEEE Transactions on Audio and Electroacoustics* 15(2) (1967) 70-73.
    """
    p = np.asarray(pressure_pa, float)
    n = round(fs_hz / resolution_hz)
    return signal.welch(p, fs_hz, window="hann", nperseg=min(n, len(p)), nfft=n, noverlap=None,
                        detrend=False, scaling="density")


def tones(pressure_pa: ArrayLike, fs_hz: float, low_hz: float = 50.0, high_hz: float = 10_000.0,
          resolution_hz: float = 2.0) -> list[Tone]:
    """The audible tonal components of a pressure record, strongest audibility first (module docstring).

    Only those with a positive audibility.

    Parameters
    ----------
    pressure_pa : array_like
        A calibrated record [Pa].
    fs_hz : float
        Its sampling rate [Hz].
    low_hz, high_hz : float
        The range searched [Hz].
    resolution_hz : float
        The spectrum's line spacing [Hz].

    Returns
    -------
    list of Tone
        Frequency [Hz], tone level L_T and masking level L_G [dB re 20 uPa], audibility [dB].

    References
    ----------
    .. [1] ISO/PAS 20065:2016, *Acoustics - Objective method for assessing the audibility of tones in
       noise - Engineering method*.
    """
    f, psd = density(pressure_pa, fs_hz, resolution_hz)
    df = f[1] - f[0]
    with np.errstate(divide="ignore"):
        db = 10.0 * np.log10(np.maximum(psd, 1e-300))
    band = critical_bandwidth_hz(f)
    lo = np.searchsorted(f, f - band / 2.0)
    hi = np.searchsorted(f, f + band / 2.0, side="right")
    peak = np.zeros(len(f), bool)
    peak[1:-1] = (psd[1:-1] > psd[:-2]) & (psd[1:-1] >= psd[2:])
    inside = (f >= low_hz) & (f <= high_hz)
    cum = np.concatenate([[0.0], np.cumsum(db)])
    mean_db = (cum[hi] - cum[lo]) / np.maximum(hi - lo, 1)
    floor = db.max() - DYNAMIC_RANGE_DB
    candidates = np.flatnonzero(peak & inside & (db - mean_db >= PROMINENCE_DB) & (db >= floor))
    tone_lines = np.zeros(len(f), bool)
    for c in candidates:
        tone_lines[max(c - LOBE_LINES, 0): c + LOBE_LINES + 1] = True
    out: list[Tone] = []
    taken: list[tuple[float, float]] = []  # a stronger tone's frequency and half its critical band [Hz]
    for c in candidates[np.argsort(-psd[candidates])]:
        fc = float(f[c])
        if any(abs(fc - t) < half for t, half in taken):
            continue  # within the critical band of a stronger tone: merged into it
        lines = slice(max(c - LOBE_LINES, 0), c + LOBE_LINES + 1)
        level_t = 10.0 * np.log10(np.sum(psd[lines]) * df / P0_PA**2)
        noise = psd[lo[c]:hi[c]][~tone_lines[lo[c]:hi[c]]]
        if not len(noise):
            continue
        level_g = 10.0 * np.log10(np.mean(noise) * band[c] / P0_PA**2)
        audibility = level_t - level_g - float(masking_index_db(f[c]))
        taken.append((fc, float(critical_bandwidth_hz(fc)) / 2.0))
        if audibility > 0.0:
            out.append(Tone(float(f[c]), float(level_t), float(level_g), float(audibility)))
    return sorted(out, key=lambda t: -t.audibility_db)
