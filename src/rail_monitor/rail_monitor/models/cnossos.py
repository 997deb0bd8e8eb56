"""CNOSSOS-EU railway source model: rolling, impact, bridge, curve-squeal, traction and
aerodynamic sound power, directivity and line source power.

Commission Directive (EU) 2015/996, Annex II section 2.3 (the source model for railway
traffic), corrected by the corrigendum of OJ L 5, 10.1.2018 (f = v / lambda with v in m/s), as
amended by Commission Delegated Directive (EU) 2021/1226 (new Tables G-1b, G-2, G-3a, G-4 and
G-7). Two editions of Appendix G are data files of the package, each with its citation:

* ``2021`` (default), ``data/cnossos_eu_2021_*.csv``: the tables in force;
* ``2015``, ``data/cnossos_eu_2015_*.csv``: the tables of Directive 2015/996 at the precision of
  the database they were printed from, the European Commission's CNOSSOS-EU reference source
  module (its catalogues; traction at constant speed and idling apart), with the 2015 text's
  scalar bridge constant, the absolute value of the vertical directivity of source A, and only
  the 920 mm / 50 kN contact filter.

Equation numbers are the Directive's.

Per 1/3-octave band i (24 bands, nominal 50 Hz to 10 kHz), for one vehicle of N_ax axles:

    L_R,TOT(lambda) = 10 lg(10^(L_r,TR/10) + 10^(L_r,VEH/10)) + A_3(lambda)       (2.3.6)
    L_W,0,TR,i      = L_R,TOT,i + L_H,TR,i + 10 lg N_ax                          (2.3.7)
    L_W,0,VEH,i     = L_R,TOT,i + L_H,VEH,i + 10 lg N_ax                         (2.3.8)
    L_W,0,VEH,SUP,i = L_R,TOT,i + L_H,VEH,SUP,i + 10 lg N_ax                     (2.3.9)

L_R,TOT,i is the wavelength spectrum read at lambda = v / f_i (v in m/s). The Directive says only
that the tables are "averaged energetically and proportionally"; the two rules that reproduce the
two public implementations are in :mod:`rail_monitor.models.cnossos_bands`.

Impact noise adds the joint roughness to L_R,TOT in energy: L_R,IMPACT = L_R,IMPACT-SINGLE +
10 lg(n_l / 0.01), n_l joints per metre (2.3.10-2.3.11). A bridge adds L_R,TOT + L_H,BRIDGE +
10 lg N_ax (2.3.14). Curve squeal adds 8 dB to the rolling-noise power for R <= 300 m and 5 dB
for 300 m < R <= 500 m (2.3.2, "squeal"). Directivity: horizontal 10 lg(0.01 + 0.99 sin^2 phi)
(2.3.15); vertical, for source A (h = 1) above the source, 40/3 [2/3 sin(2 psi) - sin psi]
lg((f + 600) / 200) (2.3.16), in the 2015 text its absolute value at every psi; none for
source B. Traction (Table G-5) and aerodynamic noise (Table G-6, above 200 km/h: L_W,0,1 +
alpha lg(v / v0)) are given per vehicle at the source heights A (0.5 m) and B (4 m). Sound power
per metre of line for a flow of Q vehicles per hour at v km/h: L_W',eq,line = L_W,0,dir +
10 lg(Q / (1000 v)) (2.3.1); a vehicle idling T_idle per T_ref, spread over a line of length l:
L_W,0,dir + 10 lg(T_idle / T_ref) - 10 lg(l / 1 m).

The European Commission's emission test workbook for the reference module (CNOSSOS_RAIL_EMISSION_
TEST.xlsx, Stapelfeldt Ingenieurgesellschaft for the JRC, 2014) is reproduced by edition 2015 with
the ``reference`` rule to its printed 0.01 dB (tests/models/test_cnossos_workbook.py); its idling
rows imply l = 1200 m for T_idle = T_ref.

References
----------
.. [1] Commission Directive (EU) 2015/996 of 19 May 2015 establishing common noise assessment methods
   according to Directive 2002/49/EC, *Official Journal of the European Union* L 168, 1.7.2015,
   Annex II section 2.3; corrigendum, OJ L 5, 10.1.2018.
.. [2] Commission Delegated Directive (EU) 2021/1226 of 21 December 2020 amending, for the purposes of
   adapting to scientific and technical progress, Annex II to Directive 2002/49/EC as regards common
   noise assessment methods, *Official Journal of the European Union* L 269, 28.7.2021.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models.cnossos_directivity import check_source
from rail_monitor.models.cnossos_tables import (
    DEFAULT_EDITION,
    Tables,
    as_tables,
)
from rail_monitor.models.levels import level, power

FloatArray = NDArray[np.float64]

RUNNING_CONDITIONS = ("constant", "idling")
# Table G-5's vehicle types over the editions (each edition's own: Tables.traction_types).
TRACTION_TYPES = ("diesel_loco_800kw", "diesel_loco_2200kw", "diesel_loco_1180kw", "diesel_loco_2200kw_class66",
                  "dmu", "electric_loco", "emu")
AERODYNAMIC_ONSET_KMH = 200.0           # aerodynamic noise is taken into account above this speed (2.3.2)


# -- sound power ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class SourcePower:
    """Sound power per vehicle per band [dB re 1 pW], by component (arrays passes x bands)."""

    track: FloatArray
    vehicle: FloatArray
    superstructure: FloatArray
    bridge: FloatArray | None = None

    def components(self) -> dict[str, FloatArray]:
        out = {"track": self.track, "vehicle": self.vehicle, "superstructure": self.superstructure}
        if self.bridge is not None:
            out["bridge"] = self.bridge
        return out

    def total(self) -> FloatArray:
        return level(sum(power(v) for v in self.components().values()))


def curve_squeal_db(curve_radius_m: float) -> float:
    """The curve-squeal correction to rolling-noise power: 8 dB for R <= 300 m, 5 dB up to 500 m, else 0.

    Parameters
    ----------
    curve_radius_m : float
        Curve radius R [m] (inf: straight track).

    Returns
    -------
    float
        Correction [dB].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.2 (squeal).
    """
    return 8.0 if curve_radius_m <= 300.0 else 5.0 if curve_radius_m <= 500.0 else 0.0


def rolling_sound_power(total_roughness_f_db: ArrayLike, axles_per_vehicle: ArrayLike, track_db: ArrayLike,
                        vehicle_db: ArrayLike, superstructure_db: ArrayLike = 0.0, bridge_db: ArrayLike | None = None,
                        squeal_db: float = 0.0, bridge_constant_db: float = 0.0) -> SourcePower:
    """Rolling-noise power per vehicle of track, vehicle and superstructure, and of a bridge.

    From L_R,TOT at the band frequencies. squeal_db (:func:`curve_squeal_db`) is added to the rolling
    components, not to the bridge; so is the 2015 text's scalar bridge constant C_bridge
    (bridge_constant_db), as the reference module adds it.

    Parameters
    ----------
    total_roughness_f_db : array_like
        L_R,TOT at the band frequencies [dB re 1 um] (passes x bands).
    axles_per_vehicle : array_like
        N_a [-] (per pass).
    track_db, vehicle_db, superstructure_db : array_like
        L_H,TR, L_H,VEH and L_H,SUP [dB per axle] on the bands.
    bridge_db : array_like, optional
        L_H,BRIDGE [dB per axle] (None: no bridge).
    squeal_db : float
        Curve-squeal correction [dB].
    bridge_constant_db : float
        The 2015 text's C_bridge [dB].

    Returns
    -------
    SourcePower
        L_W,0 per vehicle [dB re 1 pW] by component (passes x bands).

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.2,
       eqs. 2.3.7-2.3.9 and 2.3.14.
    """
    lr = np.asarray(total_roughness_f_db, float)
    axles = 10.0 * np.log10(np.asarray(axles_per_vehicle, float))[..., None] if np.ndim(axles_per_vehicle) \
        else 10.0 * np.log10(float(axles_per_vehicle))
    base = lr + axles
    excess = squeal_db + bridge_constant_db
    return SourcePower(
        track=base + np.asarray(track_db, float) + excess,
        vehicle=base + np.asarray(vehicle_db, float) + excess,
        superstructure=base + np.asarray(superstructure_db, float) + excess,
        bridge=None if bridge_db is None else base + np.asarray(bridge_db, float),
    )


def vehicle_sound_power(rolling: SourcePower, traction_type: str | None, speed_kmh: ArrayLike,
                        condition: str = "constant",
                        edition: str | Tables = DEFAULT_EDITION) -> dict[str, dict[str, FloatArray]]:
    """Sound power per vehicle by source height and component.

    At A (h = 1) the rolling components (superstructure included, as the reference module places
    it), the bridge, traction and aerodynamic noise; at B (h = 2) traction and aerodynamic noise.
    An idling vehicle has traction noise only; no traction type, no traction noise.

    Parameters
    ----------
    rolling : SourcePower
        The rolling components [dB re 1 pW] (:func:`rolling_sound_power`).
    traction_type : str or None
        Traction type as Table G-5 names it [-] (None: none).
    speed_kmh : array_like
        Speed [km/h] (per pass).
    condition : str
        'constant' or 'idling' [-].
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its sources' tables.

    Returns
    -------
    dict
        {'A' or 'B': {component: L_W,0 [dB re 1 pW], passes x bands}}.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, sections 2.3.1-2.3.2.
    """
    if condition not in RUNNING_CONDITIONS:
        raise ValueError(f"running condition must be one of {RUNNING_CONDITIONS}")
    out: dict[str, dict[str, FloatArray]] = {"A": {}, "B": {}}
    if condition == "constant":
        out["A"].update(rolling.components())
    for source, comps in out.items():
        if traction_type is not None:
            comps["traction"] = np.broadcast_to(traction_sound_power(traction_type, source, condition, edition),
                                                np.shape(rolling.track))
        if condition == "constant":
            comps["aerodynamic"] = np.broadcast_to(aerodynamic_sound_power(speed_kmh, source, edition),
                                                   np.shape(rolling.track))
    return out



def traction_sound_power(traction_type: str, source: str, condition: str = "constant",
                         edition: str | Tables = DEFAULT_EDITION) -> FloatArray:
    """Traction noise power per vehicle on the 24 bands, at source A or B, constant speed or idling.

    The 2021 table gives one spectrum for both conditions.

    Parameters
    ----------
    traction_type : str
        Traction type as Table G-5 names it [-].
    source : str
        'A' or 'B' [-].
    condition : str
        'constant' or 'idling' [-].
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its traction table.

    Returns
    -------
    ndarray
        L_W,0 [dB re 1 pW] per band.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, Table G-5.
    """
    t = as_tables(edition)
    if traction_type not in t.traction_types:
        raise ValueError(f"traction type must be one of {t.traction_types} (edition {edition})")
    if condition not in RUNNING_CONDITIONS:
        raise ValueError(f"running condition must be one of {RUNNING_CONDITIONS}")
    name = f"traction_{traction_type}_{condition}_{check_source(source)}"
    if name not in t.by_frequency:
        name = f"traction_{traction_type}_constant_{source}"
    return t.by_frequency[name]


def aerodynamic_sound_power(speed_kmh: ArrayLike, source: str, edition: str | Tables = DEFAULT_EDITION,
                            v0_kmh: float = 300.0, alpha: float = 50.0) -> FloatArray:
    """Aerodynamic noise power per vehicle: L_W,0,1 + alpha lg(v / v0) above 200 km/h, none at or below.

    Parameters
    ----------
    speed_kmh : array_like
        Speed v [km/h].
    source : str
        'A' or 'B' [-].
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its aerodynamic table.
    v0_kmh : float
        Reference speed of the table [km/h].
    alpha : float
        Speed exponent [dB per decade].

    Returns
    -------
    ndarray
        L_W,0 [dB re 1 pW], shape speed.shape + (24,); -inf (no power) at or below 200 km/h.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.2 and Table G-6.
    """
    v = np.asarray(speed_kmh, float)[..., None]
    spectrum = as_tables(edition).by_frequency[f"aerodynamic_{check_source(source)}_300kmh"]
    with np.errstate(divide="ignore"):
        return np.where(v > AERODYNAMIC_ONSET_KMH, spectrum + alpha * np.log10(v / v0_kmh), -np.inf)


