"""The levels of a recorded pass-by, as ISO 3095 defines them, from a calibrated pressure record.

With p_A(t) the A-weighted sound pressure [Pa] (IEC 61672-1, models.iec61672), p0 = 20 uPa, the pass
between t1 (the front of the train at the microphone's plane) and t2 (its rear), Tp = t2 - t1, and T
the whole record (long enough to hold the pass's energy down to 10 dB below its maximum):

- LpAeq,Tp = 10 lg[ (1/Tp) int_{t1}^{t2} p_A^2 dt / p0^2 ]           (ISO 3095:2013, 3.9)
- LpAFmax: the maximum over T of the F-time-weighted level           (ISO 3095:2013, 3.7)
- TEL = 10 lg[ (1/Tp) int_T p_A^2 dt / p0^2 ] = SEL + 10 lg(T0 / Tp)   (transit exposure level)
- SEL = 10 lg[ (1/T0) int_T p_A^2 dt / p0^2 ], T0 = 1 s              (sound exposure level, L_AE)

TEL is defined in ISO 3095:2005 (transit exposure level, with the relations above; the same text is
clause 3.12 of GOST 32203-2013, its modified adoption). Whether the 2013 edition keeps it could not
be checked against that edition's text here; the formula is the one of 2005.

The one-third-octave band levels 50 Hz - 10 kHz are the Leq over Tp of the unweighted pressure
through the class 1 filters of models.iec61260 (applied to the record's spectrum: by Parseval, the
mean square of the filtered record is the spectrum's power weighted by |H|^2). The tonal components
and their audibility are those of models.tonality (ISO/PAS 20065) over Tp.

References
----------
.. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by railbound
   vehicles*, International Organization for Standardization, Geneva, 2013.
.. [2] ISO 3095:2005, *Railway applications - Acoustics - Measurement of noise emitted by railbound
   vehicles*, ISO, Geneva, 2005 (transit exposure level).
.. [3] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*.
.. [4] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters - Part 1*.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import fft

from rail_monitor.models import iec61260, iec61672, tonality

P0_PA = 20e-6
BANDS = iec61260.third_octave_bands(50.0, 10_000.0)  # band numbers of the reported spectrum


@dataclass(frozen=True)
class PassbyLevels:
    lpaeq_tp_db: float            # [dB re 20 uPa]
    lpafmax_db: float
    tel_db: float
    sel_db: float
    tp_s: float                   # the pass-by time Tp [s]
    record_s: float               # the record's length T [s]
    band_centres_hz: NDArray      # nominal centres of BANDS [Hz]
    band_levels_db: NDArray       # Leq over Tp per band [dB re 20 uPa]
    tones: tuple[tonality.Tone, ...]


def sensitivity_pa_per_unit(calibration: ArrayLike, level_db: float = 94.0) -> float:
    """Pascals per unit of a recording channel, from a record of a calibrator on it.

    The calibrator's r.m.s. is taken about its mean: a DC offset of the channel is not sound.

    Parameters
    ----------
    calibration : array_like
        The channel's record of the calibrator [unit].
    level_db : float
        The calibrator's level [dB re 20 uPa].

    Returns
    -------
    float
        Sensitivity [Pa per unit].

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles* (the measuring chain calibrated with a sound calibrator).
    """
    c = np.asarray(calibration, float)
    rms = float(np.sqrt(np.mean((c - c.mean()) ** 2))) if len(c) else 0.0
    if not np.isfinite(rms) or rms <= 0.0:
        raise ValueError("the calibration record is silent: no r.m.s. to scale by")
    return P0_PA * 10.0 ** (level_db / 20.0) / rms


SKIRT = 4.0  # beyond f_m / SKIRT and f_m SKIRT a band's filter attenuates more than 72 dB: left out


def band_mean_squares(pressure_pa: ArrayLike, fs_hz: float, bands: ArrayLike = BANDS) -> NDArray[np.float64]:
    """Mean square of a record through each 1/3-octave band's filter.

    Each band's response is IEC 61260-1's (models.iec61260.band_power_response); beyond a factor
    SKIRT from the band centre, more than 72 dB down where class 1 asks 70, it is taken as zero.

    Parameters
    ----------
    pressure_pa, fs_hz : array_like, float
        A record of sound pressure [Pa] and its sampling rate [Hz].
    bands : array_like
        Band numbers [-] (default BANDS).

    Returns
    -------
    ndarray
        Mean square per band [Pa^2].

    References
    ----------
    .. [1] IEC 61260-1:2014, *Electroacoustics - Octave-band and fractional-octave-band filters -
       Part 1: Specifications*.
    """
    p = np.asarray(pressure_pa, float)
    n = len(p)
    power = np.abs(fft.rfft(p)) ** 2
    power[1:(n + 1) // 2] *= 2.0  # the negative frequencies' share (not at 0 Hz, nor at fs/2 for even n)
    f = fft.rfftfreq(n, 1.0 / fs_hz)
    out = np.empty(len(np.atleast_1d(bands)))
    for k, x in enumerate(np.atleast_1d(bands)):
        fm = float(iec61260.exact_centre(x))
        near = slice(np.searchsorted(f, fm / SKIRT), np.searchsorted(f, fm * SKIRT, side="right"))
        out[k] = iec61260.band_power_response(f[near], x) @ power[near] / n**2
    return out


def _db(mean_square: ArrayLike) -> NDArray[np.float64]:
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(np.asarray(mean_square, float) / P0_PA**2)


def passby_levels(pressure_pa: ArrayLike, fs_hz: float, start_s: float | None = None,
                  end_s: float | None = None) -> PassbyLevels:
    """The ISO 3095 levels of a calibrated pass-by record.

    LpAeq,Tp over the pass, LpAFmax over the record, TEL and SEL, the pass's 1/3-octave spectrum and
    its tones (module docstring). ValueError for a window outside the record or shorter than one
    sample.

    Parameters
    ----------
    pressure_pa : array_like
        The calibrated record of the pass-by [Pa].
    fs_hz : float
        Its sampling rate [Hz].
    start_s, end_s : float, optional
        The train's front and rear at the microphone's plane, from the record's start [s]
        (default: the record's start and end).

    Returns
    -------
    PassbyLevels
        Levels [dB re 20 uPa], Tp and the record's length [s], band levels and tones.

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.7 and 3.9.
    .. [2] ISO 3095:2005, *Railway applications - Acoustics - Measurement of noise emitted by
       railbound vehicles* (transit exposure level).
    """
    p = np.asarray(pressure_pa, float)
    if p.ndim != 1 or not len(p) or not np.all(np.isfinite(p)):
        raise ValueError("the record must be one channel of finite samples")
    t1 = 0.0 if start_s is None else float(start_s)
    t2 = len(p) / fs_hz if end_s is None else float(end_s)
    i1, i2 = round(t1 * fs_hz), round(t2 * fs_hz)
    if not (0 <= i1 < i2 <= len(p)):
        raise ValueError(f"the pass window {t1:g}-{t2:g} s is not inside the record (0-{len(p) / fs_hz:g} s)")
    pa2 = iec61672.a_weighted_pressure(p, fs_hz) ** 2
    tp = (i2 - i1) / fs_hz
    exposure = float(np.sum(pa2)) / fs_hz  # [Pa^2 s]
    window = p[i1:i2]
    return PassbyLevels(
        lpaeq_tp_db=float(_db(np.mean(pa2[i1:i2]))),
        lpafmax_db=float(_db(np.max(iec61672.time_weighted_square(pa2, fs_hz)))),
        tel_db=float(_db(exposure / tp)), sel_db=float(_db(exposure / 1.0)), tp_s=tp, record_s=len(p) / fs_hz,
        band_centres_hz=iec61260.nominal_centre(BANDS), band_levels_db=_db(band_mean_squares(window, fs_hz)),
        tones=tuple(tonality.tones(window, fs_hz)))
