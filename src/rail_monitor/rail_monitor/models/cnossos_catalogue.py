"""A user's own CNOSSOS-EU tables, added to an edition's in the package's CSV format (a site's
``noise.cnossos_catalogue``): what they may add, and every fault refused with one line."""

from __future__ import annotations

import csv
import re
from dataclasses import replace

import numpy as np

from rail_monitor.models.cnossos_directivity import SOURCE_HEIGHTS
from rail_monitor.models.cnossos_tables import Tables, table_rows

# A user's catalogue (with_catalogue): what its columns may add, by the table's first column.
CATALOGUE_COLUMNS = {
    "frequency_hz": (r"track_[a-z0-9_]+", r"vehicle_wheel_[0-9]+(\.[0-9]+)?mm",
                     r"traction_[a-z0-9_]+_(constant|idling)_[AB]"),
    "wavelength_mm": (r"contact_filter_[0-9]+(\.[0-9]+)?kN_[0-9]+(\.[0-9]+)?mm",),
}
CATALOGUE_LEVEL_RANGE_DB = (-100.0, 250.0)
CATALOGUE_MAX_COLUMNS = 200
CATALOGUE_MAX_CHARS = 1_000_000   # far above any real catalogue; a larger text is refused before it is parsed


def with_catalogue(base: Tables, text: str) -> Tables:
    """An edition's tables with a user's own added, in the package's CSV format.

    ``text`` holds one or more tables (lines starting with # are comments; each table starts with its
    header, a first column ``frequency_hz`` on the 24 nominal bands 50 Hz - 10 kHz or
    ``wavelength_mm`` on the edition's grid), whose columns are named as the package's are: track
    transfers ``track_<name>`` [dB per axle], vehicle transfers ``vehicle_wheel_<d>mm`` [dB per
    axle], traction ``traction_<type>_<constant|idling>_<A|B>`` [dB re 1 pW per vehicle; constant at
    both heights required], contact filters ``contact_filter_<load>kN_<d>mm`` [dB]. A column may not
    replace one the edition has. ValueError, one line, for the first fault.

    Parameters
    ----------
    base : Tables
        The edition's tables [-].
    text : str
        The user's tables [-].

    Returns
    -------
    Tables
        Both, the user's columns added.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, Appendix G
       (the tables' meaning and units).
    """
    if not text.strip():
        return base
    if len(text) > CATALOGUE_MAX_CHARS:
        raise ValueError(f"catalogue: {len(text)} characters, more than {CATALOGUE_MAX_CHARS}")
    by_f, by_wl = dict(base.by_frequency), dict(base.by_wavelength)
    grids = {"frequency_hz": (base.band_hz, by_f), "wavelength_mm": (base.wavelength_m * 1e3, by_wl)}
    tables_seen = 0
    try:
        rows = table_rows(text)
    except csv.Error as exc:
        raise ValueError(f"catalogue: not CSV text: {exc}") from None
    while rows:
        head = rows.pop(0)
        tables_seen += 1
        where = f"catalogue table {tables_seen}"
        if head[0] not in grids:
            raise ValueError(f"{where}: the first column must be one of {tuple(grids)}, not {head[0]!r}")
        end = next((i for i, r in enumerate(rows) if r[0] in grids), len(rows))
        body, rows = rows[:end], rows[end:]
        grid, into = grids[head[0]]
        if len(head) < 2 or len(head) > CATALOGUE_MAX_COLUMNS or any(len(r) != len(head) for r in body):
            raise ValueError(f"{where}: every row needs the header's {len(head)} cells, 2 to "
                             f"{CATALOGUE_MAX_COLUMNS}")
        try:
            data = np.array(body, float).reshape(len(body), len(head))
        except ValueError:
            raise ValueError(f"{where}: a cell is not a number") from None
        order = np.argsort(data[:, 0])
        if len(data) != len(grid) or not np.array_equal(data[order, 0], grid):
            raise ValueError(f"{where}: {head[0]} must be the edition {base.edition} grid's {len(grid)} values")
        lo, hi = CATALOGUE_LEVEL_RANGE_DB
        for j, name in enumerate(head[1:], start=1):
            if not any(re.fullmatch(p, name) for p in CATALOGUE_COLUMNS[head[0]]):
                raise ValueError(f"{where}: column {name!r} is none of {CATALOGUE_COLUMNS[head[0]]}")
            if name in by_f or name in by_wl:
                raise ValueError(f"{where}: column {name!r} is already a table of edition {base.edition} or of the "
                                 "catalogue")
            if not np.all(np.isfinite(data[:, j])) or np.any((data[:, j] < lo) | (data[:, j] > hi)):
                raise ValueError(f"{where}: column {name!r} must be finite, within [{lo:g}, {hi:g}] dB")
            into[name] = data[order, j]
    out = replace(base, by_wavelength=by_wl, by_frequency=by_f)
    for kind in out.traction_types:
        if not all(f"traction_{kind}_constant_{h}" in by_f for h in SOURCE_HEIGHTS):
            raise ValueError(f"catalogue: traction type {kind!r} needs its constant-speed spectrum at A and B")
    return out
