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

from rail_monitor.models.cnossos_tables import (
    DEFAULT_EDITION,
    Tables,
    as_tables,
    check_edition,
    check_rule_edition,
    noisemodelling_wheel_roughness,
)
from rail_monitor.models.levels import level, power

FloatArray = NDArray[np.float64]

RAIL_ROUGHNESS_CLASSES = ("E", "M")
BRAKE_TYPES = ("cast_iron", "composite", "disc")   # Table G-1a columns
SLEEPER_TYPES = ("monoblock", "biblock", "wooden", "direct_fastening")
PAD_CLASSES = ("soft", "medium", "hard")
BRIDGE_TYPES = ("none", "concrete", "steel")
# Table G-3a pad classes by dynamic stiffness [N/m]: soft 150-250, medium 250-800, hard 800-1000 MN/m.
PAD_CLASS_UPPER_NPM = (250e6, 800e6)
SOURCE_HEIGHTS = {"A": 0.5, "B": 4.0}   # above the rail head [m], Annex II 2.3.1 (h = 1 and h = 2)
RUNNING_CONDITIONS = ("constant", "idling")
# Table G-5's vehicle types over the editions (each edition's own: Tables.traction_types).
TRACTION_TYPES = ("diesel_loco_800kw", "diesel_loco_2200kw", "diesel_loco_1180kw", "diesel_loco_2200kw_class66",
                  "dmu", "electric_loco", "emu")
AERODYNAMIC_ONSET_KMH = 200.0           # aerodynamic noise is taken into account above this speed (2.3.2)


# -- roughness and contact filter (wavelength domain) --------------------------------------------
def rail_roughness(roughness_class: str, edition: str | Tables = DEFAULT_EDITION) -> FloatArray:
    """Rail roughness of a CNOSSOS-EU class on the tables' wavelength grid.

    Class E is EN ISO 3095:2013's limit, M the average network's.

    Parameters
    ----------
    roughness_class : str
        'E' or 'M' [-].
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its rail roughness table.

    Returns
    -------
    ndarray
        The class's rail roughness L_r,TR [dB re 1 um] per wavelength of the grid.

    References
    ----------
    .. [1] Commission Delegated Directive (EU) 2021/1226 (OJ L 269, 28.7.2021), Annex, Table G-1b.
    .. [2] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, Table G-1 (the 2015 edition).
    """
    names = {"E": "rail_roughness_E_iso3095", "M": "rail_roughness_M_average_network"}
    if roughness_class not in names:
        raise ValueError(f"rail roughness class must be one of {RAIL_ROUGHNESS_CLASSES}")
    return as_tables(edition).by_wavelength[names[roughness_class]]


def wheel_roughness(brake_type: str, rule: str = "reference", edition: str | Tables = DEFAULT_EDITION) -> FloatArray:
    """Wheel roughness by brake type on the tables' grid, as an interpolation rule's implementation holds it.

    ``reference``: the unrounded values to 0.01 dB; ``noisemodelling``: at the full precision of
    NoiseModelling's data (data/noisemodelling_wheel_roughness.csv); they differ by at most 0.005 dB.

    Parameters
    ----------
    brake_type : str
        'cast_iron', 'composite' or 'disc' [-].
    rule : str
        'reference' or 'noisemodelling' [-].
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its wheel roughness table.

    Returns
    -------
    ndarray
        The brake type's wheel roughness L_r,VEH [dB re 1 um] per wavelength of the grid.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, Table G-1a.
    .. [2] NoiseModelling (Universite Gustave Eiffel, CNRS), noisemodelling-emission, railway/cnossos.
    """
    if brake_type not in BRAKE_TYPES:
        raise ValueError(f"brake type must be one of {BRAKE_TYPES}")
    t = as_tables(edition)
    if check_rule_edition(rule, t.edition) == "noisemodelling":
        return noisemodelling_wheel_roughness()[brake_type]
    return t.by_wavelength[f"wheel_roughness_{brake_type}_unrounded"]


def contact_filter(wheel_load_n: float, wheel_diameter_m: float,
                   edition: str | Tables = DEFAULT_EDITION) -> tuple[tuple[float, float], FloatArray]:
    """The contact filter A_3 of the nearest tabulated (load, diameter) entry, in lg(load) and lg(diameter).

    The 2021 table gives five cases; the nearest is taken, diameter first (the filter scales with the
    contact length, which grows with both). Edition 2015 here holds the 920 mm / 50 kN entry only.

    Parameters
    ----------
    wheel_load_n : float
        Wheel load [N].
    wheel_diameter_m : float
        Wheel diameter [m].
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its contact filter table.

    Returns
    -------
    tuple
        The entry (wheel load [N], wheel diameter [m]) and its A_3 [dB] per wavelength.

    References
    ----------
    .. [1] Commission Delegated Directive (EU) 2021/1226 (OJ L 269, 28.7.2021), Annex, Table G-2.
    """
    entries = as_tables(edition).contact_filters
    key = min(entries, key=lambda k: (abs(np.log(k[1] / wheel_diameter_m)), abs(np.log(k[0] / wheel_load_n))))
    return key, entries[key]


def impact_roughness(joints_per_m: float, edition: str | Tables = DEFAULT_EDITION) -> FloatArray:
    """Impact roughness L_R,IMPACT for a joint density, from the table for one joint per 100 m.

    Parameters
    ----------
    joints_per_m : float
        Joint density n_l [1/m].
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its impact roughness table.

    Returns
    -------
    ndarray
        L_R,IMPACT [dB re 1 um] per wavelength.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.2, eq. 2.3.11.
    .. [2] Commission Delegated Directive (EU) 2021/1226 (OJ L 269, 28.7.2021), Annex, Table G-4.
    """
    return as_tables(edition).by_wavelength["impact_single_joint_per_100m"] + 10.0 * np.log10(joints_per_m / 0.01)


def total_roughness(rail_db: ArrayLike, wheel_db: ArrayLike, contact_filter_db: ArrayLike,
                    impact_db: ArrayLike | None = None) -> FloatArray:
    """Total effective roughness L_R,TOT = 10 lg(10^(L_r,TR/10) + 10^(L_r,VEH/10)) + A_3.

    The impact roughness, where given, is added in energy.

    Parameters
    ----------
    rail_db : array_like
        Rail roughness [dB re 1 um].
    wheel_db : array_like
        Wheel roughness [dB re 1 um].
    contact_filter_db : array_like
        A_3 [dB].
    impact_db : array_like, optional
        Impact roughness [dB re 1 um].

    Returns
    -------
    ndarray
        L_R,TOT [dB re 1 um].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, section 2.3.2, eqs. 2.3.6 and 2.3.10.
    """
    total = level(power(rail_db) + power(wheel_db)) + np.asarray(contact_filter_db, float)
    if impact_db is not None:
        total = level(power(total) + power(impact_db))
    return total


# -- transfer functions (frequency domain) ---------------------------------------------------------
def pad_class(pad_stiffness_npm: float) -> str:
    """The pad class of Table G-3a for a dynamic pad stiffness.

    Soft below 250 MN/m, medium up to 800 MN/m, hard above (the table's classes: soft 150-250,
    medium 250-800, hard 800-1000 MN/m).

    Parameters
    ----------
    pad_stiffness_npm : float
        Dynamic pad stiffness [N/m].

    Returns
    -------
    str
        'soft', 'medium' or 'hard' [-].

    References
    ----------
    .. [1] Commission Delegated Directive (EU) 2021/1226 (OJ L 269, 28.7.2021), Annex, Table G-3a.
    """
    soft, medium = PAD_CLASS_UPPER_NPM
    return "soft" if pad_stiffness_npm < soft else "medium" if pad_stiffness_npm <= medium else "hard"


def track_transfer(sleeper_type: str, pad_stiffness_npm: float,
                   edition: str | Tables = DEFAULT_EDITION) -> tuple[str, FloatArray]:
    """The track transfer function L_H,TR for a sleeper type and pad stiffness.

    Parameters
    ----------
    sleeper_type : str
        Sleeper type as the tables name it [-].
    pad_stiffness_npm : float
        Dynamic pad stiffness [N/m] (its class: :func:`pad_class`).
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its track transfer table.

    Returns
    -------
    tuple
        The table's column [-] and L_H,TR [dB per axle] on the 24 bands.

    References
    ----------
    .. [1] Commission Delegated Directive (EU) 2021/1226 (OJ L 269, 28.7.2021), Annex, Table G-3a.
    """
    t = as_tables(edition)
    if sleeper_type == "wooden":
        name = "track_wooden_sleepers"
    elif sleeper_type == "direct_fastening":
        name = "track_direct_fastening_bridge"
    elif sleeper_type in ("monoblock", "biblock"):
        name = f"track_{sleeper_type}_{pad_class(pad_stiffness_npm)}_pad"
    else:
        raise ValueError(f"sleeper type must be one of {SLEEPER_TYPES}")
    return name, t.column(name, f"track transfer for sleeper type {sleeper_type}")


def vehicle_transfer(wheel_diameter_m: float, edition: str | Tables = DEFAULT_EDITION) -> tuple[float, FloatArray]:
    """The vehicle transfer function L_H,VEH of the nearest tabulated wheel diameter.

    Parameters
    ----------
    wheel_diameter_m : float
        Wheel diameter [m].
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its vehicle transfer table.

    Returns
    -------
    tuple
        The diameter used [m] and L_H,VEH [dB per axle] on the 24 bands.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, Table G-3b.
    """
    entries = as_tables(edition).vehicle_transfers
    key = min(entries, key=lambda dia: abs(np.log(dia / wheel_diameter_m)))
    return key, entries[key]


def bridge_transfer(bridge_type: str, edition: str | Tables = DEFAULT_EDITION) -> FloatArray | None:
    """The bridge transfer function L_H,BRIDGE of a bridge type, or None without a bridge.

    The 2015 text has a scalar bridge constant instead (:func:`rolling_sound_power`'s
    bridge_constant_db).

    Parameters
    ----------
    bridge_type : str
        Bridge type as Table G-7 names it, or 'none' [-].
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its bridge transfer table.

    Returns
    -------
    ndarray or None
        L_H,BRIDGE [dB per axle] on the 24 bands.

    References
    ----------
    .. [1] Commission Delegated Directive (EU) 2021/1226 (OJ L 269, 28.7.2021), Annex, Table G-7.
    """
    columns = {"concrete": "bridge_concrete_plus10dBA", "steel": "bridge_steel_ballasted_plus15dBA"}
    if bridge_type == "none":
        return None
    if bridge_type not in columns:
        raise ValueError(f"bridge type must be one of {BRIDGE_TYPES}")
    return as_tables(edition).column(columns[bridge_type], "bridge transfer table (the 2015 text adds a constant)")


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
    if _check_source(source) == "B":
        return hor + np.zeros_like(np.asarray(frequency_hz, float))
    return hor + vertical_directivity_a_db(np.asarray(psi_rad, float)[..., None], frequency_hz, edition)


def _check_source(source: str) -> str:
    if source not in SOURCE_HEIGHTS:
        raise ValueError(f"source height must be one of {tuple(SOURCE_HEIGHTS)}")
    return source


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
    name = f"traction_{traction_type}_{condition}_{_check_source(source)}"
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
    spectrum = as_tables(edition).by_frequency[f"aerodynamic_{_check_source(source)}_300kmh"]
    with np.errstate(divide="ignore"):
        return np.where(v > AERODYNAMIC_ONSET_KMH, spectrum + alpha * np.log10(v / v0_kmh), -np.inf)


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
