"""Per-axle-pass growth of every band component, tabulated per vehicle class and friction state.

Each 1/3-octave band is tracked as components at wavelengths spread across it; per axle pass a
component grows by ln Z += ln|1 + K_b F^2 H(V / lambda)| (the paper's eqs. 1-2 with the contact
filter F; docs/models.md), where H uses the site's track (bay-averaged discrete-support
receptance), the class's unsprung mass and the Hertz contact of the class's wheel at its nominal
load. The growths are tabulated once per site on a 0.1 m/s speed grid and interpolated linearly.
"""

from __future__ import annotations

import dataclasses
from functools import lru_cache

import numpy as np

from rail_monitor.core.cache import cached_arrays
from rail_monitor.core.passes import MAX_SPEED_MPS
from rail_monitor.core.site import Site
from rail_monitor.corrugation.config import SPEED_STEP_MPS, CorrugationConfig
from rail_monitor.models import corrugation as cg
from rail_monitor.models import track as tr
from rail_monitor.models.contact_filter import hertzian_line_filter


@lru_cache(maxsize=8)
def _rail_receptance(track: tr.Track) -> tuple[np.ndarray, np.ndarray]:
    """Bay-averaged discrete-support rail receptance [m/N] on a log frequency grid [Hz]: about a
    second to build, so kept on disk per track (rail_monitor.core.cache) and in memory."""
    def build() -> dict[str, np.ndarray]:
        f = np.geomspace(0.05, 2.0e4, 700)
        return {"frequency_hz": f, "receptance_m_per_n": tr.bay_averaged_receptance(f, track)}

    got = cached_arrays("rail_receptance", dataclasses.asdict(track), build)
    return got["frequency_hz"], got["receptance_m_per_n"]


def _interp_log(x: np.ndarray, xp: np.ndarray, yp: np.ndarray) -> np.ndarray:
    """Complex yp(xp) interpolated at x, linearly in ln x (clamped at the ends)."""
    lx, lxp = np.log(np.clip(x, xp[0], xp[-1])), np.log(xp)
    return np.interp(lx, lxp, yp.real) + 1j * np.interp(lx, lxp, yp.imag)


class GrowthTables:
    """Per-axle-pass log growth of each band component, per vehicle class, over the speed grid.

    ``filtered_kernel`` is F^2 H at the components' wavelengths (C, B, V, P); ``set_k_b``
    tabulates ln|1 + K_b F^2 H| (C, 4, B, V, P) for the K_b of each friction state.
    """

    def __init__(self, site: Site, cfg: CorrugationConfig) -> None:
        self.bands = cg.wavelength_bands(cfg.shortest_wavelength_m, cfg.longest_wavelength_m)
        self.classes = list(site.vehicles)
        self.speeds = np.arange(1, round(MAX_SPEED_MPS / SPEED_STEP_MPS) + 1) * SPEED_STEP_MPS
        sub = cg.band_sub_wavelengths(self.bands, cfg.points_per_band)
        f_rail, r_rail = _rail_receptance(site.track)
        kernels = []
        for name in self.classes:
            v = site.vehicle(name)
            patch = site.contact_patch(v.wheel_diameter_m / 2.0, v.wheel_load_n)
            kc, a = float(patch.stiffness), float(patch.a)
            h = cg.growth_kernel(kc, r_rail + tr.wheel_receptance(f_rail, v.unsprung_mass_kg))
            freq = self.speeds[None, :, None] / sub[:, None, :]
            filt = hertzian_line_filter(sub, a)[:, None, :]
            kernels.append(filt * filt * _interp_log(freq, f_rail, h))
        self.filtered_kernel = np.stack(kernels)          # (C, B, V, P)
        self.table = np.empty(0)
        self.k_b = np.full(4, np.nan)

    def set_k_b(self, k_b: np.ndarray) -> None:
        """Tabulate the growth for K_b per friction state (4,) [-/axle pass]."""
        self.k_b = np.asarray(k_b, float).copy()
        self.table = np.stack([cg.filtered_log_growth(kb, self.filtered_kernel, 1.0) for kb in self.k_b], axis=1)

    def class_index(self, names: np.ndarray) -> np.ndarray:
        lookup = {n: i for i, n in enumerate(self.classes)}
        return np.array([lookup[n] for n in names], dtype=np.int64)

    def at(self, class_idx: np.ndarray, friction: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """Per-axle-pass log growth (N, B, P) for passes of class index, friction state (1-4), speed [m/s]."""
        x = np.clip(np.asarray(speed, float) / SPEED_STEP_MPS - 1.0, 0.0, len(self.speeds) - 1.0)
        j = np.minimum(x.astype(np.int64), len(self.speeds) - 2)
        w = (x - j)[:, None, None]
        fi = np.asarray(friction, np.int64) - 1
        return (1.0 - w) * self.table[class_idx, fi, :, j, :] + w * self.table[class_idx, fi, :, j + 1, :]
