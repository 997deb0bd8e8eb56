"""CNOSSOS-EU's roughness (no rclpy): the rail and wheel roughness of Appendix G, the contact filter,
the impact roughness of joints and the total effective roughness L_R,TOT (Commission Directive (EU)
2015/996, Annex II, section 2.3.2, eqs. 2.3.6 and 2.3.10-2.3.11, as amended by Commission Delegated
Directive (EU) 2021/1226). The source model that uses them is :mod:`rail_monitor.models.cnossos`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from rail_monitor.models.cnossos import FloatArray
from rail_monitor.models.cnossos_tables import (
    DEFAULT_EDITION,
    Tables,
    as_tables,
    check_rule_edition,
    noisemodelling_wheel_roughness,
)
from rail_monitor.models.levels import level, power

RAIL_ROUGHNESS_CLASSES = ("E", "M")


BRAKE_TYPES = ("cast_iron", "composite", "disc")   # Table G-1a columns


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
