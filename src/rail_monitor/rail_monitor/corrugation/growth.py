"""Per-axle-pass growth of every band component, tabulated per vehicle class and friction state.

Each 1/3-octave band is tracked as components at wavelengths spread across it; per axle pass a
component grows by ln Z += ln|1 + K_b F^2 H(V / lambda)| (the paper's eqs. 1-2 with the contact
filter F; docs/models.md), where H uses the site's track (discrete-support receptance), the
class's unsprung mass and the Hertz contact of the class's wheel at its nominal load.

The wheel rolls over every position of the sleeper bay, and the roughness at each position grows
with the kernel there: the log growth is averaged over positions in the bay (the growth of the
geometric-mean amplitude along the track), not computed from a bay-averaged receptance, which would
average the receptance's phase before the nonlinear kernel (docs/models.md, "Bay positions").
The growths are tabulated once per site on a 0.1 m/s speed grid and interpolated linearly.
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
from rail_monitor.models import corrugation_bands
from rail_monitor.models import track as tr
from rail_monitor.models import wheel_rail_noise as wrn
from rail_monitor.models.contact_filter import hertzian_line_filter
from rail_monitor.models.engine import corrugation_kernels

# Positions in the bay (fraction of the sleeper spacing from a support): the midpoints of eight
# equal slices of a bay; the receptance is symmetric about mid-span, so the four of the first half
# stand for all eight with equal weight.
BAY_POSITIONS = (np.arange(4) + 0.5) / 8
# Frequencies of the tabulated receptance (log spaced, 0.05 Hz-20 kHz): steps of 0.46 %, a
# quarter of the half-power bandwidth of the pinned-pinned peak at mid-span (rail loss factor 0.02).
RECEPTANCE_POINTS = 2800


@lru_cache(maxsize=8)
def _rail_receptance(track: tr.Track) -> tuple[np.ndarray, np.ndarray]:
    """Discrete-support rail receptance [m/N] at BAY_POSITIONS (F, X) on a log frequency grid
    [Hz]: about a second to build, so kept on disk per track (rail_monitor.core.cache) and in memory."""
    grid = {"lowest_hz": 0.05, "highest_hz": 2.0e4, "points": RECEPTANCE_POINTS, "positions": BAY_POSITIONS.tolist()}

    def build() -> dict[str, np.ndarray]:
        f = np.geomspace(grid["lowest_hz"], grid["highest_hz"], grid["points"])
        return {"frequency_hz": f, "receptance_m_per_n": tr.discrete_receptance(f, track, position=BAY_POSITIONS)}

    got = cached_arrays("rail_receptance_in_bay", {**dataclasses.asdict(track), **grid}, build)
    return got["frequency_hz"], got["receptance_m_per_n"]


def _interp_log(x: np.ndarray, xp: np.ndarray, yp: np.ndarray) -> np.ndarray:
    """Complex yp(xp) interpolated at x, linearly in ln x (clamped at the ends)."""
    lx, lxp = np.log(np.clip(x, xp[0], xp[-1])), np.log(xp)
    return np.interp(lx, lxp, yp.real) + 1j * np.interp(lx, lxp, yp.imag)


class GrowthTables:
    """Per-axle-pass log growth of each band component, per vehicle class, over the speed grid.

    ``filtered_kernel`` is F^2 H at the components' wavelengths and the bay positions
    (X, C, B, V, P); ``set_k_b`` tabulates ln|1 + K_b F^2 H| averaged over X (C, 4, 2, B, V, P)
    for the K_b of each friction state, in partial slip (regime 0) and in full sliding (regime 1,
    K_b times -2/3 sliding_wear_ratio: :func:`rail_monitor.models.corrugation.sliding_wear_sensitivity`).

    The table of the configured K_b is kept on disk (rail_monitor.core.cache, keyed by everything
    it depends on), so a start-up loads it and never builds the kernel; the kernel is built, and
    then kept, only when K_b changes (a survey).
    """

    def __init__(self, site: Site, cfg: CorrugationConfig) -> None:
        self.sliding_wear_ratio = cfg.sliding_wear_ratio
        self.bands = corrugation_bands.wavelength_bands(cfg.shortest_wavelength_m, cfg.longest_wavelength_m)
        self.classes = list(site.vehicles)
        self.speeds = np.arange(1, round(MAX_SPEED_MPS / SPEED_STEP_MPS) + 1) * SPEED_STEP_MPS
        self._sub = corrugation_bands.band_sub_wavelengths(self.bands, cfg.points_per_band)
        self._track = site.track
        self._wheels = []  # per class: Hertz stiffness [N/m], semi-axis a [m], unsprung mass [kg]
        for name in self.classes:
            v = site.vehicle(name)
            patch = site.contact_patch(v.wheel_diameter_m / 2.0, v.wheel_load_n)
            self._wheels.append((float(patch.stiffness), float(patch.a), float(v.unsprung_mass_kg)))
        self._kernel: np.ndarray | None = None
        self._by_speed = np.empty((0, 0, 0, 0, 0, 0))
        self.k_b = np.full(4, np.nan)
        self._inputs = {"track": dataclasses.asdict(self._track), "wheels": self._wheels,
                        "sub_wavelengths_m": self._sub.tolist(), "speeds_mps": [float(self.speeds[0]), SPEED_STEP_MPS,
                                                                                len(self.speeds)],
                        "positions": BAY_POSITIONS.tolist(), "receptance_points": RECEPTANCE_POINTS,
                        "sliding_wear_ratio": self.sliding_wear_ratio}
        self.set_k_b(cfg.k_b, cached=True)

    @property
    def filtered_kernel(self) -> np.ndarray:
        """F^2 H (X, C, B, V, P) [m/N], built on first use."""
        if self._kernel is None:
            f_rail, r_rail = _rail_receptance(self._track)
            freq = self.speeds[None, :, None] / self._sub[:, None, :]
            kernels = []
            for kc, a, unsprung in self._wheels:
                h = cg.growth_kernel(kc, r_rail + wrn.wheel_receptance(f_rail, unsprung)[:, None])
                filt = hertzian_line_filter(self._sub, a)[:, None, :]
                kernels.append([filt * filt * _interp_log(freq, f_rail, h[:, x]) for x in range(h.shape[1])])
            self._kernel = np.stack(kernels, axis=1)
        return self._kernel

    def set_k_b(self, k_b: np.ndarray, cached: bool = False) -> None:
        """Tabulate the growth for K_b per friction state (4,) [-/axle pass] in partial slip, and
        the K_b in full sliding that follows from each; cached: through the disk cache."""
        k_b = np.asarray(k_b, float).copy()
        if np.array_equal(k_b, self.k_b):
            return
        sliding = cg.sliding_wear_sensitivity(k_b, self.sliding_wear_ratio)

        def build() -> dict[str, np.ndarray]:
            table = np.stack([np.stack([self._bay_mean(kb) for kb in pair], axis=1)
                              for pair in zip(k_b, sliding, strict=True)], axis=1)
            return {"table": np.ascontiguousarray(np.moveaxis(table, 4, 3))}  # (C, F, R, V, B, P)

        self._by_speed = cached_arrays("corrugation_growth_table_by_speed", {**self._inputs, "k_b": k_b.tolist()},
                                       build)["table"] if cached else build()["table"]
        self.k_b = k_b

    def _bay_mean(self, k_b: float) -> np.ndarray:
        """ln|1 + K_b F^2 H| averaged over the bay positions (C, B, V, P)."""
        out = cg.filtered_log_growth(k_b, self.filtered_kernel[0], 1.0)
        for x in range(1, len(self.filtered_kernel)):
            out += cg.filtered_log_growth(k_b, self.filtered_kernel[x], 1.0)
        return out / len(self.filtered_kernel)

    @property
    def table(self) -> np.ndarray:
        """Per-axle-pass log growth (class, friction state, regime, band, speed, component)."""
        return np.moveaxis(self._by_speed, 3, 4)

    def class_index(self, names: np.ndarray) -> np.ndarray:
        lookup = {n: i for i, n in enumerate(self.classes)}
        return np.array(list(map(lookup.__getitem__, names)), dtype=np.int64)

    def at(self, class_idx: np.ndarray, friction: np.ndarray, regime: np.ndarray, speed: np.ndarray,
           axles: np.ndarray | None = None, engine: str = "numpy") -> np.ndarray:
        """Per-axle-pass log growth (N, B, P) for passes of class index, friction state (1-4), contact
        regime (rail_monitor.core.contact.REGIME_*) and speed [m/s]; with axles (N,), each pass's
        log growth over its axles. engine: of the lookup (models.engine)."""
        x = np.clip(np.asarray(speed, float) / SPEED_STEP_MPS - 1.0, 0.0, len(self.speeds) - 1.0)
        j = np.minimum(x.astype(np.int64), len(self.speeds) - 2)
        scale = np.ones(len(x)) if axles is None else np.asarray(axles, float)  # x 1.0 is exact
        # One contiguous (B, P) block per pass and speed.
        return corrugation_kernels(engine).table_growth(self._by_speed, np.asarray(class_idx, np.int64),
                                                        np.asarray(friction, np.int64) - 1,
                                                        np.asarray(regime, np.int64), j, x - j, scale)
