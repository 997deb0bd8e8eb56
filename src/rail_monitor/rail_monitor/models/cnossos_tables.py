"""CNOSSOS-EU Appendix G as data: the tables of each edition read once from the package's data files
(wavelength tables on an ascending grid, frequency tables on the 24 nominal bands), with their
citations in the files (no rclpy). The source model that reads them is :mod:`rail_monitor.models.cnossos`.

References
----------
.. [1] Commission Directive (EU) 2015/996 of 19 May 2015 establishing common noise assessment methods
   according to Directive 2002/49/EC, *Official Journal of the European Union* L 168, 1.7.2015,
   Annex II, Appendix G.
.. [2] Commission Delegated Directive (EU) 2021/1226 of 21 December 2020 amending Annex II to Directive
   2002/49/EC, *Official Journal of the European Union* L 269, 28.7.2021 (Tables G-1b, G-2, G-3a,
   G-4 and G-7).
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np
from numpy.typing import NDArray

from rail_monitor.models.iec61260 import band_index

FloatArray = NDArray[np.float64]

EDITIONS = ("2015", "2021")
DEFAULT_EDITION = "2021"


def table_rows(text: str) -> list[list[str]]:
    """The rows of a table file's text: CSV, lines starting with # are comments.

    Parameters
    ----------
    text : str
        The file's text [-].

    Returns
    -------
    list of list of str
        Rows of cells.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, Appendix G (the tables the files hold).
    """
    return [[cell.strip() for cell in r] for r in csv.reader(io.StringIO(text)) if r and not r[0].startswith("#")]


def _read(name: str) -> tuple[list[str], FloatArray]:
    rows = table_rows(resources.files("rail_monitor").joinpath("data", name).read_text(encoding="utf-8"))
    return rows[0], np.array(rows[1:], float)


@dataclass(frozen=True)
class Tables:
    """Appendix G of one edition. Wavelength tables on an ascending wavelength grid [m];
    frequency tables on the 24 nominal band centres (band numbers x of IEC 61260-1)."""

    edition: str
    wavelength_m: FloatArray
    by_wavelength: dict[str, FloatArray]
    band: NDArray[np.int64]
    band_hz: FloatArray
    by_frequency: dict[str, FloatArray]

    @property
    def contact_filters(self) -> dict[tuple[float, float], FloatArray]:
        """A_3 [dB] by (wheel load [N], wheel diameter [m]) (Table G-2)."""
        out = {}
        for name, col in self.by_wavelength.items():
            if name.startswith("contact_filter_"):
                load, dia = name.removeprefix("contact_filter_").split("_")
                out[(float(load.removesuffix("kN")) * 1e3, float(dia.removesuffix("mm")) / 1e3)] = col
        return out

    @property
    def vehicle_transfers(self) -> dict[float, FloatArray]:
        """L_H,VEH [dB] by wheel diameter [m] (Table G-3b)."""
        return {float(n.removeprefix("vehicle_wheel_").removesuffix("mm")) / 1e3: c
                for n, c in self.by_frequency.items() if n.startswith("vehicle_wheel_")}

    @property
    def traction_types(self) -> tuple[str, ...]:
        """The vehicle types of Table G-5 in this edition."""
        names = (n.removeprefix("traction_").rsplit("_", 2)[0] for n in self.by_frequency if n.startswith("traction_"))
        return tuple(dict.fromkeys(names))

    def column(self, name: str, what: str) -> FloatArray:
        """A table column by name; a one-line error naming the edition where it has none."""
        found = self.by_frequency.get(name, self.by_wavelength.get(name))
        if found is None:
            raise ValueError(f"CNOSSOS-EU edition {self.edition} has no {what}")
        return found


def as_tables(edition: str | Tables) -> Tables:
    """The tables themselves, or an edition's.

    Parameters
    ----------
    edition : str or Tables
        '2021' (in force) or '2015', or a site's own tables (models.cnossos_catalogue) [-]: its tables.

    Returns
    -------
    Tables
        Appendix G of the edition (wavelength grid [m], band centres [Hz], levels [dB]).

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, Appendix G.
    """
    return edition if isinstance(edition, Tables) else tables(edition)


def check_edition(edition: str) -> str:
    """The edition, or a ValueError naming the known ones.

    An edition is one text of Appendix G: 2015's, or 2021's as amended.

    Parameters
    ----------
    edition : str
        '2021' or '2015' [-]: its name, to be checked.

    Returns
    -------
    str
        The edition [-], '2021' or '2015' (a ValueError names them for any other).

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, Appendix G (edition 2015).
    .. [2] Commission Delegated Directive (EU) 2021/1226 (OJ L 269, 28.7.2021), Annex (edition 2021).
    """
    if edition not in EDITIONS:
        raise ValueError(f"unknown CNOSSOS-EU edition {edition!r}; use one of {EDITIONS}")
    return edition


def check_rule_edition(rule: str, edition: str) -> str:
    """The interpolation rule, refused where its implementation has no tables of the edition.

    Parameters
    ----------
    rule : str
        'reference' or 'noisemodelling' [-].
    edition : str
        '2021' or '2015' [-]: its tables the rule needs.

    Returns
    -------
    str
        The rule [-].

    References
    ----------
    .. [1] NoiseModelling (Universite Gustave Eiffel, CNRS), noisemodelling-emission, railway/cnossos
       (its tables' edition).
    """
    if rule == "noisemodelling" and check_edition(edition) != "2021":
        raise ValueError("the noisemodelling interpolation rule reads the 2021 edition's tables only")
    return rule


@lru_cache(maxsize=len(EDITIONS))
def tables(edition: str = DEFAULT_EDITION) -> Tables:
    """The Appendix G tables of an edition, read once from the package's data files.

    Parameters
    ----------
    edition : str
        '2021' or '2015' [-]: its tables to read.

    Returns
    -------
    Tables
        Wavelength tables on an ascending grid [m], frequency tables on the 24 nominal bands [Hz],
        levels [dB].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, Appendix G.
    .. [2] Commission Delegated Directive (EU) 2021/1226 (OJ L 269, 28.7.2021), Annex, Tables G-1b, G-2, G-3a, G-4
       and G-7.
    """
    check_edition(edition)
    head, data = _read(f"cnossos_eu_{edition}_wavelength.csv")
    order = np.argsort(data[:, 0])
    by_wl = {h: data[order, j] for j, h in enumerate(head) if j}
    fhead, fdata = _read(f"cnossos_eu_{edition}_frequency.csv")
    return Tables(edition=edition, wavelength_m=data[order, 0] / 1e3, by_wavelength=by_wl,
                  band=band_index(fdata[:, 0]), band_hz=fdata[:, 0],
                  by_frequency={h: fdata[:, j] for j, h in enumerate(fhead) if j})


def printed_wheel_roughness() -> tuple[FloatArray, dict[str, FloatArray]]:
    """Table G-1a as printed (rounded): its wavelength labels and its levels by column.

    Returns
    -------
    tuple
        Wavelength labels [m] and {brake type: levels [dB re 1 um]}.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, Table G-1a.
    """
    head, data = _read("cnossos_eu_2021_g1a_printed.csv")
    return data[:, 0] / 1e3, {h: data[:, j] for j, h in enumerate(head) if j}


@lru_cache(maxsize=1)
def noisemodelling_wheel_roughness() -> dict[str, FloatArray]:
    """Table G-1a's wheel roughness at the full precision of NoiseModelling's data, on the tables' grid.

    From data/noisemodelling_wheel_roughness.csv.

    Returns
    -------
    dict
        {brake type: levels [dB re 1 um]}.

    References
    ----------
    .. [1] NoiseModelling (Universite Gustave Eiffel, CNRS), noisemodelling-emission, railway/cnossos.
    """
    head, data = _read("noisemodelling_wheel_roughness.csv")
    order = np.argsort(data[:, 0])
    if not np.array_equal(data[order, 0] / 1e3, tables().wavelength_m):
        raise ValueError("noisemodelling_wheel_roughness.csv: its wavelengths are not the tables' grid")
    return {h: data[order, j] for j, h in enumerate(head) if j}
