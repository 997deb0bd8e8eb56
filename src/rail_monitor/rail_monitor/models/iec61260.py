"""One-third-octave bands of IEC 61260-1:2014 (Electroacoustics - Octave-band and fractional-octave-band
filters - Part 1), base ten.

Exact mid-band frequencies f_m = f_r G^(x/3), G = 10^(3/10), f_r = 1000 Hz, x integer (eq. 2,
b = 3); band edges f_m G^(-1/6) and f_m G^(1/6) (eqs. 4-5). Nominal mid-band frequencies are the
labels of Annex E (they name the bands; calculations use the exact values).

The filter of band x (band_power_response) is a Butterworth band-pass of order 3 (six poles) with
its -3 dB points at the band edges, applied to a record's spectrum: |H|^2 = 1 / (1 + q^6),
q = (f/f_m - f_m/f) / (G^(1/6) - G^(-1/6)). It meets the class 1 acceptance limits of Table 1
(class1_attenuation_limits) at every breakpoint; its effective bandwidth is pi/6 / sin(pi/6) =
1.047 times the nominal one, so broadband noise reads 0.20 dB above its exact band power.

References
----------
.. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters - Part 1:
   Specifications*, International Electrotechnical Commission, Geneva, 2014.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

G = 10.0 ** 0.3          # octave frequency ratio, base ten
REFERENCE_HZ = 1000.0

# Annex E nominal mid-band frequencies, 1/3 octave, one decade (repeat by powers of ten).
_NOMINAL_DECADE = (10.0, 12.5, 16.0, 20.0, 25.0, 31.5, 40.0, 50.0, 63.0, 80.0)


def band_index(nominal_hz: ArrayLike) -> NDArray[np.int64]:
    """Band numbers x of nominal mid-band frequencies (1 kHz is band 0).

    Parameters
    ----------
    nominal_hz : array_like
        Nominal mid-band frequencies [Hz].

    Returns
    -------
    ndarray of int
        x [-].

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, Annex E (the nominal labels).
    """
    return np.rint(10.0 * np.log10(np.asarray(nominal_hz, float) / REFERENCE_HZ)).astype(np.int64)


def exact_centre(x: ArrayLike) -> FloatArray:
    """Exact mid-band frequency of band x, f_m = 1000 G^(x/3) Hz, G = 10^(3/10).

    Parameters
    ----------
    x : array_like
        Band number [-] (1 kHz is 0; any integer).

    Returns
    -------
    ndarray
        f_m [Hz].

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, eq. 2 (base ten, b = 3).
    """
    return REFERENCE_HZ * G ** (np.asarray(x, float) / 3.0)


def nominal_centre(x: ArrayLike) -> FloatArray:
    """Nominal mid-band frequency (the band's label) of band x.

    Parameters
    ----------
    x : array_like
        Band number [-] within Annex E's labelled range.

    Returns
    -------
    ndarray
        Nominal frequency [Hz], as Annex E prints it.

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, Annex E.
    """
    x = np.asarray(x, np.int64)
    decade, step = np.divmod(x + 30, 10)
    return np.asarray(_NOMINAL_DECADE, float)[step] * 10.0 ** (decade - 1)


def band_edges(x: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Lower and upper band-edge frequencies of band x, f_m G^(-1/6) and f_m G^(1/6).

    Parameters
    ----------
    x : array_like
        Band number [-]; the edges follow from its exact centre.

    Returns
    -------
    tuple of ndarray
        The lower and upper edges [Hz].

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, eqs. 4-5.
    """
    fm = exact_centre(x)
    return fm * G ** (-1.0 / 6.0), fm * G ** (1.0 / 6.0)


def third_octave_bands(lowest_hz: float, highest_hz: float) -> NDArray[np.int64]:
    """Band numbers from the band named lowest_hz to the band named highest_hz, inclusive.

    Parameters
    ----------
    lowest_hz, highest_hz : float
        Nominal frequencies of the first and last band [Hz].

    Returns
    -------
    ndarray of int
        x [-], ascending.

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, Annex E.
    """
    return np.arange(int(band_index(lowest_hz)), int(band_index(highest_hz)) + 1)


ORDER = 3  # Butterworth order of the band filters


def band_power_response(frequency_hz: ArrayLike, x: ArrayLike) -> FloatArray:
    """|H(f)|^2 of the filters of bands x: Butterworth band-passes of order ORDER, -3 dB at the edges.

    0 at 0 Hz. Class 1 attenuation limits are met (tests).

    Parameters
    ----------
    frequency_hz : array_like
        Frequency f [Hz].
    x : array_like
        Band numbers [-].

    Returns
    -------
    ndarray
        |H|^2 [-], shape x.shape + f.shape.

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, 5.10 (the relative attenuation limits it meets).
    """
    f = np.asarray(frequency_hz, float)
    fm = exact_centre(np.asarray(x))[..., None] if np.ndim(x) else exact_centre(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        q2 = ((f / fm - fm / f) / (G ** (1.0 / 6.0) - G ** (-1.0 / 6.0))) ** 2
        out = 1.0 / (1.0 + q2 * q2 * q2)  # ORDER 3: q^6 by products (a float power is slow)
    return np.where(f > 0, out, 0.0)


# Table 1 of IEC 61260-1:2014, class 1: at the octave-band breakpoint G^k (k >= 0) the relative
# attenuation lies within (min, max) [dB] (the numbers as transcribed in the ASCEE LASP limit lines;
# at the band edge k = 1/2 the limits outside the band are taken, 2.0 to 5.0 dB).
_CLASS1_OCTAVE = ((0.0, -0.3, 0.3), (1 / 8, -0.3, 0.4), (1 / 4, -0.3, 0.6), (3 / 8, -0.3, 1.3),
                  (1 / 2, 2.0, 5.0), (1.0, 17.5, np.inf), (2.0, 42.0, np.inf), (3.0, 61.0, np.inf),
                  (4.0, 70.0, np.inf))


def class1_attenuation_limits(b: int = 3) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The class 1 breakpoints of a 1/b-octave filter and the relative attenuation allowed there.

    The octave breakpoints G^k map to 1 + (G^(1/(2b)) - 1) / (G^(1/2) - 1) (G^k - 1) above the band
    centre, and to their reciprocals below.

    Parameters
    ----------
    b : int
        Bandwidth designator (3: one-third octave) [-].

    Returns
    -------
    tuple of ndarray
        Normalised frequencies f / f_m [-] (both sides of the band) and the minimum and maximum
        relative attenuation [dB] there.

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, 5.10 and Table 1.
    """
    k, lo, hi = (np.array(c, float) for c in zip(*_CLASS1_OCTAVE, strict=True))
    above = 1.0 + (G ** (1.0 / (2 * b)) - 1.0) / (G ** 0.5 - 1.0) * (G ** k - 1.0)
    omega = np.concatenate([1.0 / above[:0:-1], above])
    return omega, np.concatenate([lo[:0:-1], lo]), np.concatenate([hi[:0:-1], hi])
