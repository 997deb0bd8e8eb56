"""Level arithmetic: decibels and energy, energy sums, A-weighted totals, octave aggregation.

Levels are 10 lg of a power-like quantity over its reference (sound power re 1 pW, squared
pressure re (20 uPa)^2, squared roughness re (1 um)^2). Band levels are 1/3-octave bands named
by their IEC 61260-1 band number x (models.iec61260); the A-weighting is IEC 61672-1's at the
exact mid-band frequency (models.iec61672).

References
----------
.. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters - Part 1:
   Specifications*, International Electrotechnical Commission, Geneva, 2014.
.. [2] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, International
   Electrotechnical Commission, Geneva, 2013.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models.iec61260 import exact_centre
from rail_monitor.models.iec61672 import a_weighting_db

FloatArray = NDArray[np.float64]


def power(level_db: ArrayLike) -> FloatArray:
    """The power ratio of a level, 10^(L/10).

    Parameters
    ----------
    level_db : array_like
        Level L [dB].

    Returns
    -------
    ndarray
        Power ratio [-].

    References
    ----------
    .. [1] ISO 80000-8:2020, *Quantities and units - Part 8: Acoustics* (levels as 10 lg of a
       power-like ratio).
    """
    return 10.0 ** (np.asarray(level_db, float) / 10.0)


def level(power_ratio: ArrayLike) -> FloatArray:
    """The level of a power ratio, 10 lg(ratio).

    Parameters
    ----------
    power_ratio : array_like
        Power ratio [-].

    Returns
    -------
    ndarray
        Level [dB]; -inf for zero.

    References
    ----------
    .. [1] ISO 80000-8:2020, *Quantities and units - Part 8: Acoustics* (levels as 10 lg of a
       power-like ratio).
    """
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(np.asarray(power_ratio, float))


def energy_sum(level_db: ArrayLike, axis: int | None = -1) -> FloatArray:
    """Energy sum of levels, 10 lg(sum 10^(L/10)), along an axis (-inf levels add nothing).

    Parameters
    ----------
    level_db : array_like
        Levels [dB].
    axis : int or None
        Axis summed over [-] (None: all).

    Returns
    -------
    ndarray
        Total level [dB].

    References
    ----------
    .. [1] ISO 80000-8:2020, *Quantities and units - Part 8: Acoustics* (levels as 10 lg of a
       power-like ratio).
    """
    return level(np.sum(power(level_db), axis=axis))


def a_weighted(level_db: ArrayLike, band: ArrayLike) -> FloatArray:
    """Band levels plus the A weighting of their bands at the exact mid-band frequencies.

    Parameters
    ----------
    level_db : array_like
        1/3-octave band levels [dB], bands on the last axis.
    band : array_like
        Band numbers x [-] (mid-band 1000 x 10^(x/10) Hz).

    Returns
    -------
    ndarray
        A-weighted band levels [dB(A)].

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, Annex E.
    .. [2] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, 5.2-5.4 (band numbers and exact mid-band frequencies).
    """
    return np.asarray(level_db, float) + a_weighting_db(exact_centre(band))


def a_weighted_total(level_db: ArrayLike, band: ArrayLike) -> FloatArray:
    """Overall A-weighted level of 1/3-octave band levels, bands on the last axis.

    Parameters
    ----------
    level_db : array_like
        Band levels [dB].
    band : array_like
        Their band numbers x [-].

    Returns
    -------
    ndarray
        Total [dB(A)].

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, Annex E.
    """
    return energy_sum(a_weighted(level_db, band), axis=-1)


def octave_levels(level_db: ArrayLike, band: ArrayLike) -> tuple[NDArray[np.int64], FloatArray]:
    """Octave-band levels from 1/3-octave band levels, each the energy sum of its three thirds.

    An octave has x divisible by 3; octaves with a third missing are left out.

    Parameters
    ----------
    level_db : array_like
        1/3-octave levels [dB], bands on the last axis.
    band : array_like
        Their band numbers x [-].

    Returns
    -------
    tuple of ndarray
        The octaves' band numbers [-] and levels [dB].

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*, 5.2-5.4.
    """
    band = np.asarray(band, np.int64)
    lv = np.asarray(level_db, float)
    octaves = [x for x in range(int(band.min()) + 1, int(band.max())) if x % 3 == 0
               and {x - 1, x, x + 1} <= set(band.tolist())]
    cols = [energy_sum(lv[..., np.isin(band, (x - 1, x, x + 1))], axis=-1) for x in octaves]
    return np.asarray(octaves, np.int64), np.stack(cols, axis=-1) if cols else np.empty((*lv.shape[:-1], 0))
