"""A roughness trolley's displacement trace as CSV: a column ``distance_m`` [m] and a column
``displacement_um`` [um] or ``displacement_m`` [m]; lines starting with '#' are comments. The samples
must be evenly spaced (to 1 % of the spacing), as a trolley's encoder gives them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rail_monitor.bagio.csv_io import csv_cells, csv_lines
from rail_monitor.core.errors import InputError

_UNITS = {"displacement_um": 1e-6, "displacement_m": 1.0}


def read_trace(path: str | Path) -> tuple[float, NDArray[np.float64]]:
    """The spacing [m] and the displacements [m] of a trace CSV (InputError, one line, otherwise)."""
    path = Path(path)
    header_line, header, lines = csv_lines(path, "distance_m,displacement_um")
    unit = next((c for c in header if c in _UNITS), None)
    if "distance_m" not in header or unit is None:
        raise InputError(f"{path}: line {header_line}: expected the columns distance_m and displacement_um "
                         "(or displacement_m)")
    i, j = header.index("distance_m"), header.index(unit)
    x, z = np.empty(len(lines)), np.empty(len(lines))
    for k, (n, line) in enumerate(lines):
        try:
            cells = csv_cells(line, header)
            x[k], z[k] = float(cells[i]), float(cells[j]) * _UNITS[unit]
        except ValueError as exc:
            raise InputError(f"{path}: line {n}: {exc}") from None
    if len(x) < 16 or not (np.all(np.isfinite(x)) and np.all(np.isfinite(z))):
        raise InputError(f"{path}: needs at least 16 rows of finite numbers")
    step = np.diff(x)
    dx = float(np.median(step))
    if not dx > 0 or np.any(np.abs(step - dx) > 0.01 * dx):
        raise InputError(f"{path}: the distances are not evenly spaced and increasing (median spacing {dx:g} m)")
    return dx, z
