"""One-third-octave bands of IEC 61260-1:2014 (Electroacoustics - Octave-band and fractional-octave-band
filters - Part 1), base ten.

Exact mid-band frequencies f_m = f_r G^(x/3), G = 10^(3/10), f_r = 1000 Hz, x integer (eq. 2,
b = 3); band edges f_m G^(-1/6) and f_m G^(1/6) (eqs. 4-5). Nominal mid-band frequencies are the
labels of Annex E (they name the bands; calculations use the exact values).

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
    """Band number x (1 kHz is 0) of nominal mid-band frequencies [Hz]."""
    return np.rint(10.0 * np.log10(np.asarray(nominal_hz, float) / REFERENCE_HZ)).astype(np.int64)


def exact_centre(x: ArrayLike) -> FloatArray:
    """Exact mid-band frequency [Hz] of band number x (IEC 61260-1 eq. 2, base ten, b = 3)."""
    return REFERENCE_HZ * G ** (np.asarray(x, float) / 3.0)


def nominal_centre(x: ArrayLike) -> FloatArray:
    """Nominal mid-band frequency [Hz] of band number x (Annex E labels)."""
    x = np.asarray(x, np.int64)
    decade, step = np.divmod(x + 30, 10)
    return np.asarray(_NOMINAL_DECADE, float)[step] * 10.0 ** (decade - 1)


def band_edges(x: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Lower and upper band-edge frequencies [Hz] of band number x (eqs. 4-5)."""
    fm = exact_centre(x)
    return fm * G ** (-1.0 / 6.0), fm * G ** (1.0 / 6.0)


def third_octave_bands(lowest_hz: float, highest_hz: float) -> NDArray[np.int64]:
    """Band numbers from the band named lowest_hz to the band named highest_hz (nominal) inclusive."""
    return np.arange(int(band_index(lowest_hz)), int(band_index(highest_hz)) + 1)
