"""Frequency weighting A of IEC 61672-1:2013 (Electroacoustics - Sound level meters - Part 1).

A(f) = 20 lg[ f4^2 f^4 / ((f^2 + f1^2) (f^2 + f2^2)^(1/2) (f^2 + f3^2)^(1/2) (f^2 + f4^2)) ] - A1000

with the pole frequencies and the normalisation of Annex E (eqs. E.1-E.6): f1 = 20.598997 Hz,
f2 = 107.65265 Hz, f3 = 737.86223 Hz, f4 = 12194.217 Hz, A1000 = -2.000 dB, so that A(1 kHz) = 0.

References
----------
.. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, International
   Electrotechnical Commission, Geneva, 2013, Annex E.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

F1_HZ, F2_HZ, F3_HZ, F4_HZ = 20.598997, 107.65265, 737.86223, 12194.217
A1000_DB = -2.000


def a_weighting_db(frequency: ArrayLike) -> NDArray[np.float64]:
    """A-weighting [dB] at frequency [Hz] (IEC 61672-1:2013, eq. E.6); -inf at 0 Hz."""
    f2 = np.asarray(frequency, float) ** 2
    with np.errstate(divide="ignore"):
        ratio = (F4_HZ**2 * f2**2) / (
            (f2 + F1_HZ**2) * np.sqrt(f2 + F2_HZ**2) * np.sqrt(f2 + F3_HZ**2) * (f2 + F4_HZ**2)
        )
        return 20.0 * np.log10(ratio) - A1000_DB
