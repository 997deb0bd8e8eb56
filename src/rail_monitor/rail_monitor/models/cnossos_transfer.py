"""CNOSSOS-EU's transfer functions (no rclpy): track (by sleeper type and rail-pad class), vehicle
(by wheel diameter) and bridge, per axle on the 24 bands (Commission Directive (EU) 2015/996,
Annex II, Tables G-3a, G-3b and G-7, as amended by Commission Delegated Directive (EU) 2021/1226).
The source model that uses them is :mod:`rail_monitor.models.cnossos`.
"""

from __future__ import annotations

import numpy as np

from rail_monitor.models.cnossos import FloatArray
from rail_monitor.models.cnossos_tables import (
    DEFAULT_EDITION,
    Tables,
    as_tables,
)

SLEEPER_TYPES = ("monoblock", "biblock", "wooden", "direct_fastening")


PAD_CLASSES = ("soft", "medium", "hard")


BRIDGE_TYPES = ("none", "concrete", "steel")


# Table G-3a pad classes by dynamic stiffness [N/m]: soft 150-250, medium 250-800, hard 800-1000 MN/m.
PAD_CLASS_UPPER_NPM = (250e6, 800e6)


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
