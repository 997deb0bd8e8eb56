"""CNOSSOS-EU wavelength tables read at the band frequencies: the two interpolation rules.

The Directive (2015/996, Annex II 2.3.2, with the corrigendum of OJ L 5, 10.1.2018) reads the
wavelength spectra at lambda = v / f_i and says only that they are "averaged energetically and
proportionally". Two public implementations read it differently, and each rule here reproduces
one of them (tests/models/test_cnossos_bands.py):

* ``reference`` (default), the European Commission's reference module: each table (rail
  roughness, wheel roughness, contact filter A_3, impact roughness) is mapped to the nominal band
  centres on its own, its dB values interpolated linearly in wavelength with the end values held
  outside the table, and the mapped tables are combined per band (eqs. 2.3.6 and 2.3.10);
* ``noisemodelling``, NoiseModelling's (Universite Gustave Eiffel, the open CNOSSOS-EU
  implementation, class RailwayCnossos): rail, wheel and impact roughness are added in energy on
  the wavelength grid, the contact filter added, and the energy 10^(L/10) interpolated linearly
  in lg f. Its grid puts the table's row m (m = 33 for the 2000 mm row down to -1 for 0.8 mm) at
  exactly 10^(m/10) mm, and it reads the bands at the exact base-ten centres 10^(x/10) kHz of
  IEC 61260-1 (50.12 Hz, not 50 Hz). Bands below the grid's lowest frequency v / 1.995 m (above
  100 m/s at 50 Hz) take the value of the second band that has one, as NoiseModelling fills them.
  Bands above the grid's highest frequency v / 0.794 mm (below 7.94 m/s at 10 kHz), where
  NoiseModelling has no value (NaN), hold the highest band that has one (our choice).

The rules differ by up to about 1.6 dB per band where the contact filter falls steeply between
grid points (1.25 kHz at 80 km/h), and up to 1.9 dB where the joints' roughness meets the filter,
which NoiseModelling applies to the joints and the reference module does not (docs/models.md has
the figure).

References
----------
.. [1] Commission Directive (EU) 2015/996 of 19 May 2015 establishing common noise assessment methods
   according to Directive 2002/49/EC, *Official Journal of the European Union* L 168, 1.7.2015,
   Annex II section 2.3; corrigendum, OJ L 5, 10.1.2018.
.. [2] NoiseModelling, Universite Gustave Eiffel and CNRS, https://github.com/Universite-Gustave-Eiffel/
   NoiseModelling (module noisemodelling-emission, railway/cnossos).
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models.cnossos_tables import DEFAULT_EDITION, check_rule_edition, tables
from rail_monitor.models.iec61260 import band_index, exact_centre
from rail_monitor.models.levels import level, power

FloatArray = NDArray[np.float64]

INTERPOLATION_RULES = ("reference", "noisemodelling")

# NoiseModelling's wavelengths of the tables' rows, ascending as the tables are: 10^(m/10) mm, m = -1 ... 33.
NOISEMODELLING_WAVELENGTH_M = 10.0 ** (np.arange(-1, 34) / 10.0) / 1e3


def check_rule(rule: str, edition: str = DEFAULT_EDITION) -> str:
    """The interpolation rule, or a ValueError naming the known ones (or the edition it lacks).

    Parameters
    ----------
    rule : str
        'reference' or 'noisemodelling' [-].
    edition : str
        '2021' or '2015' [-]: its tables the rule's implementation must hold.

    Returns
    -------
    str
        The rule, checked [-].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.2 (the spectra
       "averaged energetically and proportionally").
    """
    if rule not in INTERPOLATION_RULES:
        raise ValueError(f"unknown interpolation rule {rule!r}; use one of {INTERPOLATION_RULES}")
    return check_rule_edition(rule, edition)


def band_roughness(rail_db: ArrayLike, wheel_db: ArrayLike, contact_filter_db: ArrayLike, speed_mps: ArrayLike,
                   band_hz: ArrayLike | None = None, rule: str = "reference",
                   impact_db: ArrayLike | None = None, edition: str = DEFAULT_EDITION) -> FloatArray:
    """L_R,TOT per band at lambda = v / f_i, in the rule's order of operations (module docstring).

    The tables are on the edition's grid (the rail roughness may carry a leading axis per pass).

    Parameters
    ----------
    rail_db, wheel_db : array_like
        Rail and wheel roughness [dB re 1 um] on the grid.
    contact_filter_db : array_like
        A_3 [dB] on the grid.
    speed_mps : array_like
        Speed v [m/s].
    band_hz : array_like, optional
        Nominal band centres [Hz] (default the tables').
    rule : str
        'reference' or 'noisemodelling' [-].
    impact_db : array_like, optional
        Impact roughness [dB re 1 um] on the grid.
    edition : str
        '2021' or '2015' [-]: its wavelength grid.

    Returns
    -------
    ndarray
        L_R,TOT [dB re 1 um], shape speed.shape + (bands,).

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.2, eqs. 2.3.6 and
       2.3.10; corrigendum, OJ L 5, 10.1.2018.
    .. [2] NoiseModelling (Universite Gustave Eiffel, CNRS), noisemodelling-emission, railway/cnossos.
    """
    if check_rule(rule, edition) == "noisemodelling":
        rough = power(rail_db) + power(wheel_db)
        if impact_db is not None:
            rough = rough + power(impact_db)
        return at_band_frequencies(level(rough) + np.asarray(contact_filter_db, float), speed_mps, band_hz, rule)

    return level(band_roughness_power(rail_db, wheel_db, contact_filter_db, speed_mps, band_hz, rule, impact_db,
                                      edition))


def band_roughness_power(rail_db: ArrayLike, wheel_db: ArrayLike, contact_filter_db: ArrayLike,
                         speed_mps: ArrayLike, band_hz: ArrayLike | None = None, rule: str = "reference",
                         impact_db: ArrayLike | None = None, edition: str = DEFAULT_EDITION,
                         rail_power: FloatArray | None = None) -> FloatArray:
    """:func:`band_roughness` as a power ratio re (1 um)^2, summed in energy without decibels between.

    The ``noisemodelling`` rule's is 10^(L/10) of its level.

    Parameters
    ----------
    rail_db, wheel_db, contact_filter_db, speed_mps, band_hz, rule, impact_db, edition : various
        As for :func:`band_roughness` ([dB], [m/s], [Hz], [-]).
    rail_power : ndarray, optional
        The rail's :func:`power_at_bands` where the caller has it [-] (the reference rule).

    Returns
    -------
    ndarray
        Power ratio [-], shape speed.shape + (bands,).

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.2, eq. 2.3.6.
    """
    if check_rule(rule, edition) == "noisemodelling":
        return power(band_roughness(rail_db, wheel_db, contact_filter_db, speed_mps, band_hz, rule, impact_db,
                                    edition))

    def at(table: ArrayLike) -> FloatArray:
        return power_at_bands(table, speed_mps, band_hz, edition)

    rail = at(rail_db) if rail_power is None else rail_power
    filtered = (rail + at(wheel_db)) * (power(contact_filter_db) if np.ndim(contact_filter_db) == 0
                                        else at(contact_filter_db))
    return filtered if impact_db is None else filtered + at(impact_db)


def power_at_bands(table: ArrayLike, speed_mps: ArrayLike, band_hz: ArrayLike | None = None,
                   edition: str = DEFAULT_EDITION) -> FloatArray:
    """10^(L/10) of a spectrum on the edition's grid, read at lambda = v / f_i by the reference rule.

    One spectrum (a class's or the site's) is cached, being read at the same passes' speeds by every
    model and the baseline; one per pass is not.

    Parameters
    ----------
    table : array_like
        Spectrum [dB] on the grid.
    speed_mps : array_like
        Speed [m/s].
    band_hz : array_like, optional
        Nominal band centres [Hz].
    edition : str
        '2021' or '2015' [-]: its wavelength grid.

    Returns
    -------
    ndarray
        The spectrum's power ratio 10^(L/10) at the bands [-], shape speed.shape + (bands,).

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.2.
    """
    if np.ndim(table) == 1:
        speed, f = np.asarray(speed_mps, float), tables(edition).band_hz if band_hz is None else band_hz
        return _power_at(np.asarray(table, float).tobytes(), speed.tobytes(), speed.shape,
                         np.asarray(f, float).tobytes(), edition)
    return power(at_band_frequencies(table, speed_mps, band_hz, "reference", edition))


def contact_filter_at_patch(filter_db: ArrayLike, speed_mps: ArrayLike, table_patch_m: float,
                            patch_m: ArrayLike, band_hz: ArrayLike | None = None, rule: str = "reference",
                            edition: str = DEFAULT_EDITION) -> FloatArray:
    """A contact filter tabulated for one contact read for another of different length.

    A contact filter is a function of the wavenumber times the contact length, H(k a), so the table
    (for a patch of semi-length a_0) is read at lambda a_0 / a, that is at the speed v a_0 / a.
    Patches of one shape (aspect ratio) assumed.

    Parameters
    ----------
    filter_db : array_like
        A_3 [dB] on the grid (Table G-2).
    speed_mps : array_like
        Speed [m/s].
    table_patch_m : float
        a_0, the table's patch semi-length along the rail [m].
    patch_m : array_like
        a, the pass's [m].
    band_hz : array_like, optional
        Nominal band centres [Hz].
    rule : str
        'reference' or 'noisemodelling' [-].
    edition : str
        '2021' or '2015' [-]: its wavelength grid of the filter.

    Returns
    -------
    ndarray
        A_3 at the bands [dB], shape speed.shape + (bands,).

    References
    ----------
    .. [1] P. J. Remington, "Wheel/rail rolling noise, I: Theoretical analysis", *Journal of the
       Acoustical Society of America* 81(6) (1987) 1805-1823 (a filter of the wavenumber times the
       contact length).
    .. [2] R. A. J. Ford and D. J. Thompson, *Journal of Sound and Vibration* 293(3-5) (2006) 807-818.
    .. [3] Commission Delegated Directive (EU) 2021/1226 (OJ L 269, 28.7.2021), Annex, Table G-2.
    """
    speed = np.asarray(speed_mps, float) * table_patch_m / np.asarray(patch_m, float)
    return at_band_frequencies(filter_db, speed, band_hz, rule, edition)


def at_band_frequencies(level_db: ArrayLike, speed_mps: ArrayLike, band_hz: ArrayLike | None = None,
                        rule: str = "reference", edition: str = DEFAULT_EDITION) -> FloatArray:
    """A spectrum on the tables' wavelength grid read at lambda = v / f_i by the rule.

    The spectrum's last axis is the grid; it may carry leading axes matching speed (one spectrum per
    pass).

    Parameters
    ----------
    level_db : array_like
        Spectrum [dB].
    speed_mps : array_like
        Speed [m/s].
    band_hz : array_like, optional
        Nominal band centres [Hz] (default the tables').
    rule : str
        'reference' or 'noisemodelling' [-].
    edition : str
        '2021' or '2015' [-]: its wavelength grid of the spectrum.

    Returns
    -------
    ndarray
        Levels [dB], shape speed.shape + (bands,).

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.2; corrigendum, OJ L 5,
       10.1.2018 (f = v / lambda, v in m/s).
    """
    t = tables(edition)
    f = t.band_hz if band_hz is None else np.asarray(band_hz, float)
    speed = np.asarray(speed_mps, float)
    if check_rule(rule, edition) == "reference":
        if np.ndim(level_db) == 0:  # a constant table reads as itself
            return np.full(speed.shape + f.shape, float(level_db))
        return _interp_at(_positions(speed.tobytes(), speed.shape, f.tobytes(), edition), np.asarray(level_db, float))
    lv = np.broadcast_to(np.asarray(level_db, float), speed.shape + t.wavelength_m.shape)
    # In u = lg f - lg v = -lg(lambda) the grid is one for every pass, ascending in frequency.
    u_grid = -np.log10(NOISEMODELLING_WAVELENGTH_M[::-1])
    u = np.log10(exact_centre(band_index(f))) - np.log10(speed)[..., None]
    out = _interp_rows(u, u_grid, power(lv[..., ::-1]))
    return level(_noisemodelling_fill(out, (u >= u_grid[0]) & (u <= u_grid[-1])))


def _noisemodelling_fill(out: FloatArray, inside: NDArray[np.bool_]) -> FloatArray:
    """Bands outside the grid: below it, the value of the second band inside (as NoiseModelling
    fills them); above it, the highest band inside. ``inside`` is contiguous along the bands."""
    if not inside.any(axis=-1).all():
        raise ValueError("no 1/3-octave band falls within the CNOSSOS wavelength grid at this speed")
    k = np.arange(out.shape[-1])
    low = np.argmax(inside, axis=-1)[..., None]
    high = out.shape[-1] - 1 - np.argmax(inside[..., ::-1], axis=-1)[..., None]
    idx = np.where(k < low, np.minimum(low + 1, high), np.minimum(k, high))
    return np.take_along_axis(out, idx, axis=-1)


@functools.lru_cache(maxsize=16)
def _positions(speed: bytes, shape: tuple[int, ...], band_hz: bytes, edition: str) -> tuple[FloatArray, FloatArray]:
    """_grid_positions of lambda = v / f_i on the edition's wavelength grid, per pass and band
    (cached: every table of a prediction, every model and the baseline are read at the same
    passes' speeds)."""
    x = np.frombuffer(speed, float).reshape(shape)[..., None] / np.frombuffer(band_hz, float)
    j, w = _grid_positions(x, tables(edition).wavelength_m)
    j.flags.writeable = w.flags.writeable = False  # shared by every caller
    return j, w


@functools.lru_cache(maxsize=16)
def _power_at(table: bytes, speed: bytes, shape: tuple[int, ...], band_hz: bytes, edition: str) -> FloatArray:
    """10^(L/10) of one spectrum on the edition's grid (table: its dB values) read at lambda = v / f_i
    by the reference rule (cached and read-only: the same wheel, contact filter and baseline spectra
    are read at the same passes' speeds by every model and by the baseline of the increase)."""
    out = power(_interp_at(_positions(speed, shape, band_hz, edition), np.frombuffer(table, float)))
    out.flags.writeable = False
    return out


def _grid_positions(x: FloatArray, xp: FloatArray) -> tuple[NDArray[np.int64], FloatArray]:
    """Where x falls on one ascending grid xp: the interval j and the weight w in it, ends held."""
    j = np.clip(np.searchsorted(xp, x, side="right") - 1, 0, len(xp) - 2)
    return j, np.clip((x - xp[j]) / (xp[j + 1] - xp[j]), 0.0, 1.0)


def _interp_at(at: tuple[NDArray[np.int64], FloatArray], fp: FloatArray) -> FloatArray:
    """Linear interpolation at grid positions (j, w): fp one table (n,) or one per row (..., n)."""
    j, w = at
    if fp.ndim == 1:
        lo, hi = fp[j], fp[j + 1]
    else:
        fp = np.broadcast_to(fp, j.shape[:-1] + fp.shape[-1:])
        lo, hi = np.take_along_axis(fp, j, axis=-1), np.take_along_axis(fp, j + 1, axis=-1)
    return lo + w * (hi - lo)


def _interp_rows(x: FloatArray, xp: FloatArray, fp: FloatArray) -> FloatArray:
    """np.interp per row: x (..., m), fp (..., n) on one ascending xp (n,); ends held."""
    return _interp_at(_grid_positions(x, xp), fp)
