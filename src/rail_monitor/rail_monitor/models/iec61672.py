"""Frequency weighting A and time weighting F of IEC 61672-1:2013 (Electroacoustics - Sound level
meters - Part 1).

A(f) = 20 lg[ f4^2 f^4 / ((f^2 + f1^2) (f^2 + f2^2)^(1/2) (f^2 + f3^2)^(1/2) (f^2 + f4^2)) ] - A1000

with the pole frequencies and the normalisation of Annex E (eqs. E.1-E.6): f1 = 20.598997 Hz,
f2 = 107.65265 Hz, f3 = 737.86223 Hz, f4 = 12194.217 Hz, A1000 = -2.000 dB, so that A(1 kHz) = 0.
A recorded pressure is A-weighted here in the frequency domain with exactly that magnitude (zero
phase: the standard sets the magnitude response and its tolerances, not the phase), so the
weighting has no design error at any sampling rate.

Time weighting (3.8, eq. 3 of the standard's definition of a time-weighted level): the squared
pressure through a first-order low-pass of time constant tau, 125 ms for F (Fast), 1 s for S:

    L_tau(t) = 10 lg[ (1/tau) int_{-inf}^{t} p^2(xi) exp(-(t - xi)/tau) dxi / p0^2 ]

discretised exactly for a squared pressure held over each sample: y[n] = a y[n-1] + (1 - a) x[n],
a = exp(-1 / (fs tau)). A tone burst of duration T_b then reads 10 lg(1 - exp(-T_b / tau)) below
the steady tone, the reference tone-burst responses of Table 4.

References
----------
.. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, International
   Electrotechnical Commission, Geneva, 2013, Annex E.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import fft

F1_HZ, F2_HZ, F3_HZ, F4_HZ = 20.598997, 107.65265, 737.86223, 12194.217
A1000_DB = -2.000
TAU_FAST_S = 0.125  # time constant of time weighting F [s]
TAU_SLOW_S = 1.0    # time constant of time weighting S [s]


def a_weighting_db(frequency: ArrayLike) -> NDArray[np.float64]:
    """The A weighting at a frequency, IEC 61672-1's analytic form (Annex E, eq. E.6).

    Parameters
    ----------
    frequency : array_like
        Frequency [Hz].

    Returns
    -------
    ndarray
        A(f) [dB]; -inf at 0 Hz.

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, Annex E.
    """
    f2 = np.asarray(frequency, float) ** 2
    with np.errstate(divide="ignore"):
        ratio = (F4_HZ**2 * f2**2) / (
            (f2 + F1_HZ**2) * np.sqrt(f2 + F2_HZ**2) * np.sqrt(f2 + F3_HZ**2) * (f2 + F4_HZ**2)
        )
        return 20.0 * np.log10(ratio) - A1000_DB


def a_weighted_pressure(pressure_pa: ArrayLike, fs_hz: float) -> NDArray[np.float64]:
    """A-weighted sound pressure of a sampled pressure: its spectrum times 10^(A(f)/20), zero phase.

    The record is padded with a second of silence, so the weighting's response (its slowest pole,
    20.6 Hz, decays in about 0.1 s) does not wrap around.

    Parameters
    ----------
    pressure_pa : array_like
        Sound pressure [Pa].
    fs_hz : float
        Sampling rate [Hz].

    Returns
    -------
    ndarray
        A-weighted pressure [Pa].

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*,
       5.5 and Annex E (the magnitude response; the phase is not specified).
    """
    p = np.asarray(pressure_pa, float)
    n = fft.next_fast_len(len(p) + int(np.ceil(fs_hz)), real=True)
    spectrum = fft.rfft(p, n)
    gain = np.zeros(len(spectrum))
    f = fft.rfftfreq(n, 1.0 / fs_hz)
    gain[1:] = 10.0 ** (a_weighting_db(f[1:]) / 20.0)
    return fft.irfft(spectrum * gain, n)[: len(p)]


def time_weighted_square(square_pa2: ArrayLike, fs_hz: float, tau_s: float = TAU_FAST_S) -> NDArray[np.float64]:
    """Exponentially time-weighted mean square of a squared pressure, from rest.

    Parameters
    ----------
    square_pa2 : array_like
        Squared (weighted) sound pressure [Pa^2].
    fs_hz : float
        Sampling rate [Hz].
    tau_s : float
        Time constant [s] (F: 0.125 s).

    Returns
    -------
    ndarray
        Time-weighted mean square [Pa^2] (0 before the record).

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*,
       3.8 (exponential time weighting).
    """
    from scipy import signal  # here: importing it costs a node's start-up half a second

    a = np.exp(-1.0 / (fs_hz * tau_s))
    return signal.lfilter([1.0 - a], [1.0, -a], np.asarray(square_pa2, float))
