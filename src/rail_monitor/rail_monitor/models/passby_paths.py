"""The paths of a pass-by (no rclpy): what pass-by levels need of the passes, the bands and the
receiver whatever the spectrum (PassGeometry), the direct and ground-image paths of each source
line with their band power per metre, their A-weighted power for the time history, the LpAeq,Tp
weights of a line and the peak of the F-time-weighted squared pressure (Commission Directive (EU)
2015/996, Annex II, sections 2.3 and 2.5; ISO 3095:2013, 3.7-3.9). The levels of a pass are
:mod:`rail_monitor.models.passby`'s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from rail_monitor.models import passby_axles_peak
from rail_monitor.models.axle_layout import AxleLayout
from rail_monitor.models.levels import power
from rail_monitor.models.passby_kernel import (
    FloatArray,
    Paths,
    line_f_weighted_peak,
)


@dataclass(frozen=True)
class PassGeometry:
    """What pass-by levels need of the passes, the bands and the receiver, whatever the spectrum:
    computed once per set of passes and shared by every component and model radiated on them."""

    length: FloatArray   # train length per pass [m]
    speed: FloatArray    # speed per pass [m/s]
    d: float             # horizontal distance [m]
    r1: float            # direct path distance [m]
    r2: float            # image path distance [m]
    k1: FloatArray       # kernel window mean of the direct path per pass (passes, 1) [1/m]
    k2: FloatArray       # the same for the image path [1/m]
    total1: float        # kernel total of the direct path [1/m]
    total2: float        # of the image path [1/m]
    a_weight: FloatArray  # A-weighting of each band as a power ratio [-]
    ground_reflection: float | FloatArray   # energy weight of the image path, scalar or per band
    axles: AxleLayout | None = None  # point sources per axle (models.passby_axles); None: a line source


def lpaeq_weights(g: PassGeometry, direct_gain: ArrayLike = 1.0) -> FloatArray:
    """Per pass and band, the A-weighted window mean of a unit power per metre on the source line.

    Its direct path times direct_gain, and its image path: a spectrum W of power per metre on that
    line gives LpAeq,Tp = 10 lg(sum over bands of W Q). Being linear in W, one Q serves every
    component and every model on the line.

    Parameters
    ----------
    g : PassGeometry
        The passes' geometry [-].
    direct_gain : array_like
        The direct path's power ratio per band [-].

    Returns
    -------
    ndarray
        Q [1/m], passes x bands.

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.9 (LpAeq,Tp).
    """
    return (direct_gain * g.k1 + g.ground_reflection * g.k2) * g.a_weight


# A path per band: (power per metre per pass and band [W/m-like], its kernel window mean [1/m], its
# kernel total [1/m], its perpendicular distance [m]).
BandPaths = list[tuple[FloatArray, FloatArray, float, float]]


def band_paths(lw_per_metre_db: ArrayLike, g: PassGeometry, direct_correction_db: ArrayLike = 0.0,
               elevated: tuple[ArrayLike, PassGeometry] | None = None) -> BandPaths:
    """The direct and image paths of the source line, and of the elevated one, with their band power.

    Parameters
    ----------
    lw_per_metre_db : array_like
        Sound power per metre [dB re 1 pW/m], passes x bands.
    g : PassGeometry
        The passes' geometry [-].
    direct_correction_db : array_like
        Per band, added to the direct path [dB].
    elevated : (array_like, PassGeometry), optional
        The elevated line's power per metre [dB re 1 pW/m] and geometry.

    Returns
    -------
    BandPaths
        Per path: power per metre per pass and band [W/m-like], its kernel window mean [1/m], its
        kernel total [1/m] and its perpendicular distance [m].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.5
       (the direct and the ground-reflected path).
    """
    high = None if elevated is None else (power(np.atleast_2d(np.asarray(elevated[0], float))), elevated[1])
    return power_paths(power(np.atleast_2d(np.asarray(lw_per_metre_db, float))), g, power(direct_correction_db), high)


def power_paths(w: FloatArray, g: PassGeometry, direct_gain: ArrayLike = 1.0,
                elevated: tuple[FloatArray, PassGeometry] | None = None) -> BandPaths:
    """:func:`band_paths` of a power per metre already a ratio, without decibels.

    Parameters
    ----------
    w : ndarray
        Power per metre, ratio re 1 pW/m [-], passes x bands.
    g : PassGeometry
        The passes' geometry [-].
    direct_gain : array_like
        The direct path's power ratio per band [-].
    elevated : (ndarray, PassGeometry), optional
        The elevated line's power per metre (ratio re 1 pW/m) [-] and geometry.

    Returns
    -------
    BandPaths
        As :func:`band_paths` gives them [W/m-like, 1/m, m].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.5.
    """
    out = [(w * direct_gain, g.k1, g.total1, g.r1), (g.ground_reflection * w, g.k2, g.total2, g.r2)]
    if elevated is not None:
        w_b, gb = elevated
        out += [(w_b, gb.k1, gb.total1, gb.r1), (gb.ground_reflection * w_b, gb.k2, gb.total2, gb.r2)]
    return out


def a_weighted_paths(g: PassGeometry, paths: BandPaths) -> Paths:
    """The A-weighted power per metre of each path, summed over bands, for the time history.

    Parameters
    ----------
    g : PassGeometry
        The passes' geometry (its bands) [-].
    paths : BandPaths
        The band paths [W/m-like, 1/m, m].

    Returns
    -------
    Paths
        Per path: A-weighted power per metre per pass [W/m-like] and perpendicular distance [m].

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*,
       Annex E (the A weighting).
    """
    return [(np.sum(w * g.a_weight, axis=-1), r) for w, _, _, r in paths]


def f_weighted_peaks(g: PassGeometry, paths_of: list[Paths], engine: str = "numpy") -> FloatArray:
    """The peak F-time-weighted squared pressure of several sets of paths on the same trains.

    Line or axles; several spectra share the axles' time histories, over windows set by the source
    line's paths, g's, whatever other lines the sets hold.

    Parameters
    ----------
    g : PassGeometry
        The passes' geometry [-].
    paths_of : list of Paths
        Each set's A-weighted power per metre [W/m-like] and distances [m].
    engine : str
        'numpy' or 'numba' [-].

    Returns
    -------
    ndarray
        Peak squared pressure [W/m-like per m, the paths' unit over m], sets x passes.

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, 5.8 (time weighting F).
    .. [2] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.7 (LpAFmax).
    """
    if g.axles is None:
        return np.stack([line_f_weighted_peak(paths, g.length, g.speed, g.d) for paths in paths_of])
    return passby_axles_peak.f_weighted_peaks(paths_of, g.axles, g.length, g.speed, g.d, engine, max(g.r1, g.r2))
