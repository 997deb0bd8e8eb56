"""CNOSSOS-EU's directivity of railway sources and the line source's power (no rclpy): the
horizontal and vertical directivity of sources A and B (Commission Directive (EU) 2015/996,
Annex II, eqs. 2.3.15-2.3.16) and the directional power per metre of a steady flow or an idling
vehicle (eq. 2.3.1). The source powers are :mod:`rail_monitor.models.cnossos`'s.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models.cnossos_tables import (
    DEFAULT_EDITION,
    check_edition,
)

FloatArray = NDArray[np.float64]
SOURCE_HEIGHTS = {"A": 0.5, "B": 4.0}   # above the rail head [m], Annex II 2.3.1 (h = 1 and h = 2)


def check_source(source: str) -> str:
    """The source height's name, or a ValueError naming the known ones.

    Parameters
    ----------
    source : str
        'A' (h = 1, 0.5 m above the rail head) or 'B' (h = 2, 4 m) [-].

    Returns
    -------
    str
        The source [-].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.1.
    """
    if source not in SOURCE_HEIGHTS:
        raise ValueError(f"source height must be one of {tuple(SOURCE_HEIGHTS)}")
    return source


def horizontal_directivity_db(phi_rad: ArrayLike) -> FloatArray:
    """Horizontal directivity Delta L_W,dir,hor = 10 lg(0.01 + 0.99 sin^2 phi).

    Parameters
    ----------
    phi_rad : array_like
        Angle to the track's direction in the horizontal plane [rad].

    Returns
    -------
    ndarray
        Delta L_W,dir,hor [dB].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, eq. 2.3.15.
    """
    return 10.0 * np.log10(0.01 + 0.99 * np.sin(np.asarray(phi_rad, float)) ** 2)


def vertical_directivity_a_db(psi_rad: ArrayLike, frequency_hz: ArrayLike,
                              edition: str = DEFAULT_EDITION) -> FloatArray:
    """Vertical directivity of source A, 40/3 [2/3 sin(2 psi) - sin psi] lg((f + 600) / 200).

    2021: as printed above the source (psi > 0), 0 at or below it: slightly positive up to
    psi = acos(3/4) = 41 degrees, negative above (the vehicle body shields steep paths);
    NoiseModelling reads it the same way. 2015: its absolute value at every psi, as the reference
    module computes it (the emission test workbook's rows at psi = +-45 degrees differ from the signed
    form by up to 1.7 dB).

    Parameters
    ----------
    psi_rad : array_like
        Angle above the horizontal [rad].
    frequency_hz : array_like
        Band frequency [Hz].
    edition : str
        '2021' or '2015' [-]: its reading of eq. 2.3.16.

    Returns
    -------
    ndarray
        Delta L_W,dir,ver [dB]; in the 2021 reading 0 at or below the source, negative on steep
        paths above it.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, eq. 2.3.16.
    .. [2] NoiseModelling (Universite Gustave Eiffel, CNRS), noisemodelling-emission, railway/cnossos.
    """
    psi = np.asarray(psi_rad, float)
    f = np.asarray(frequency_hz, float)
    shape = 40.0 / 3.0 * (2.0 / 3.0 * np.sin(2.0 * psi) - np.sin(psi)) * np.log10((f + 600.0) / 200.0)
    if check_edition(edition) == "2015":
        return np.abs(shape)
    return np.where(psi > 0.0, shape, 0.0)


def directivity_db(source: str, phi_rad: ArrayLike, psi_rad: ArrayLike, frequency_hz: ArrayLike,
                   edition: str = DEFAULT_EDITION) -> FloatArray:
    """Horizontal plus vertical directivity of source A or B.

    Source B has no vertical term (the workbook's rows at psi = 45 degrees carry none).

    Parameters
    ----------
    source : str
        'A' (h = 1) or 'B' (h = 2) [-].
    phi_rad, psi_rad : array_like
        Horizontal and vertical angles [rad] (:func:`horizontal_directivity_db`,
        :func:`vertical_directivity_a_db`).
    frequency_hz : array_like
        Band frequency of the vertical term [Hz].
    edition : str
        '2021' or '2015' [-]: its reading of eq. 2.3.16.

    Returns
    -------
    ndarray
        Delta L_W,dir,hor + Delta L_W,dir,ver [dB].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, eqs. 2.3.15-2.3.16.
    """
    hor = horizontal_directivity_db(phi_rad)[..., None]
    if check_source(source) == "B":
        return hor + np.zeros_like(np.asarray(frequency_hz, float))
    return hor + vertical_directivity_a_db(np.asarray(psi_rad, float)[..., None], frequency_hz, edition)


def line_sound_power_db(lw0_dir_db: ArrayLike, vehicles_per_hour: float, speed_kmh: float) -> FloatArray:
    """Line source power of a steady flow: L_W,0,dir + 10 lg(Q / (1000 v)).

    Parameters
    ----------
    lw0_dir_db : array_like
        Directional power per vehicle [dB re 1 pW].
    vehicles_per_hour : float
        Q [1/h].
    speed_kmh : float
        v [km/h].

    Returns
    -------
    ndarray
        L_W',eq,line [dB re 1 pW/m].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, eq. 2.3.1.
    """
    return np.asarray(lw0_dir_db, float) + 10.0 * np.log10(vehicles_per_hour / (1000.0 * speed_kmh))


def idling_line_sound_power_db(lw0_dir_db: ArrayLike, idle_fraction: float, line_length_m: float) -> FloatArray:
    """Line source power of an idling vehicle: L_W,0,dir + 10 lg(T_idle / T_ref) - 10 lg(l / 1 m).

    Its power spread over a line of length l; the reference module's workbook spreads it over 1200 m.

    Parameters
    ----------
    lw0_dir_db : array_like
        Directional power of the idling vehicle [dB re 1 pW].
    idle_fraction : float
        T_idle / T_ref [-].
    line_length_m : float
        l [m].

    Returns
    -------
    ndarray
        L_W',eq,line [dB re 1 pW/m] of the idling vehicle over the line.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.1.
    """
    return np.asarray(lw0_dir_db, float) + 10.0 * np.log10(idle_fraction / line_length_m)
