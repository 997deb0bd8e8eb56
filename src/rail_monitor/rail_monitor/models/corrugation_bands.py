"""The wavelength bands of the corrugation state and the grinding limits per band (no rclpy):
1/3-octave wavelength bands, base ten, the components spread across each, and the acceptance
limits of Grassie, Saxon & Smith (J. Sound Vib. 227 (1999) 949-964) shared by the bands of each
wavelength range.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models.corrugation import FloatArray


def wavelength_bands(shortest_m: float = 0.01, longest_m: float = 1.0) -> FloatArray:
    """1/3-octave wavelength band centres covering a range, base ten.

    The centres are 10^(n/10) m, as IEC 61260-1's exact mid-band frequencies are 10^(n/10) Hz.

    Parameters
    ----------
    shortest_m : float
        Shortest wavelength to cover [m].
    longest_m : float
        Longest wavelength to cover [m].

    Returns
    -------
    ndarray
        Band centres [m], ascending.

    References
    ----------
    .. [1] IEC 61260-1:2014, Electroacoustics - Octave-band and fractional-octave-band filters, 5.2-5.4.
    """
    lo = int(np.floor(10 * np.log10(shortest_m) + 1e-9))
    hi = int(np.ceil(10 * np.log10(longest_m) - 1e-9))
    return 10.0 ** (np.arange(lo, hi + 1) / 10.0)


def band_sub_wavelengths(centres: ArrayLike, per_band: int = 5) -> FloatArray:
    """Wavelengths spread evenly in log across each 1/3-octave band.

    Band edges are centre x 10^(+-1/20); the points are the centres of per_band equal log slices,
    so a resonance between band centres is not missed.

    Parameters
    ----------
    centres : array_like
        Band centres [m].
    per_band : int
        Components per band [-].

    Returns
    -------
    ndarray
        Wavelengths [m], shape (bands, per_band).

    References
    ----------
    .. [1] IEC 61260-1:2014, Electroacoustics - Octave-band and fractional-octave-band filters, 5.2-5.4 (band edges).
    """
    c = np.asarray(centres, float)[:, None]
    u = (np.arange(per_band) + 0.5) / per_band - 0.5
    return c * 10.0 ** (u[None, :] / 10.0)


# Post-grinding acceptance limits of Grassie, Saxon & Smith (1999), r.m.s. roughness per
# wavelength range: ((shortest [m], longest [m]), limit [m]).
GRASSIE_1999_LIMITS: tuple[tuple[tuple[float, float], float], ...] = (
    ((0.01, 0.03), 3e-6),
    ((0.03, 0.10), 7e-6),
    ((0.10, 0.30), 7e-6),
    ((0.30, 1.00), 45e-6),
    ((1.00, 3.00), 100e-6),
)


def band_limits(centres: ArrayLike, ranges=GRASSIE_1999_LIMITS) -> FloatArray:
    """Per-band r.m.s. limit from range limits (default Grassie et al. 1999).

    A range's limit is shared equally by the energy of its 1/3-octave bands: a band gets
    limit / sqrt(n), n the number of base-10 band centres in [shortest, longest), so a range whose
    bands all sit at their limit has exactly the range's r.m.s. Bands outside every range get NaN.

    Parameters
    ----------
    centres : array_like
        Band centres [m].
    ranges : sequence of ((float, float), float)
        ((shortest [m], longest [m]), r.m.s. limit [m]) per wavelength range.

    Returns
    -------
    ndarray
        Limit per band [m] (NaN outside every range).

    References
    ----------
    .. [1] S. L. Grassie, M. J. Saxon and J. D. Smith, "Measurement of longitudinal rail irregularities
       and criteria for acceptable grinding", *Journal of Sound and Vibration* 227(5) (1999) 949-964.
    """
    c = np.asarray(centres, float)
    out = np.full(c.shape, np.nan)
    def inside(x: FloatArray, lo: float, hi: float) -> NDArray[np.bool_]:
        return (x >= lo * (1 - 1e-9)) & (x < hi * (1 - 1e-9))

    for (lo, hi), limit in ranges:
        n = int(inside(wavelength_bands(lo, hi), lo, hi).sum())
        out[inside(c, lo, hi)] = limit / np.sqrt(n)
    return out
