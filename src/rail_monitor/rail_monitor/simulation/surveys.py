"""Roughness surveys of a simulated rail whose true K_b differs from the configured one.

The true rail is a corrugation state advanced over the same passes with K_b x ``k_b_factor``
(the model's own growth law, so a calibration that works recovers the factor); a survey reads
its band r.m.s. with a log-normal error of ``uncertainty_db`` per band (the repeatability of a
trolley survey, e.g. EN 15610). The true grinding date is when the true rail's first band reaches
its threshold. No rclpy: the simulate command and the tests call it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.core.passes import PassTable, accepted_passes
from rail_monitor.core.site import Site
from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.corrugation.config import K_B_DEFAULTS, corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.surveys import KIND_SURVEY, MaintenanceEvent
from rail_monitor.models.calibration import LN_PER_DB


@dataclass(frozen=True)
class SurveySeries:
    """Surveys of the true rail: stamps (S,) [ns], band centres (B,) [m], measured r.m.s. (S, B)
    [m]; the true K_b (4,); when each band of the true rail first reaches its threshold (B,) [ns]
    (0: not within the passes)."""

    stamp_ns: np.ndarray
    wavelength_m: np.ndarray
    amplitude_m: np.ndarray
    true_k_b: np.ndarray
    true_crossing_ns: np.ndarray

    def events(self) -> list[MaintenanceEvent]:
        """The surveys as the events a history bag carries."""
        return [MaintenanceEvent(int(t), KIND_SURVEY, self.wavelength_m, self.amplitude_m[k])
                for k, t in enumerate(self.stamp_ns.tolist())]

    @property
    def true_grinding_ns(self) -> int:
        """The first band's crossing [ns] (0: none within the passes)."""
        crossed = self.true_crossing_ns[self.true_crossing_ns > 0]
        return int(crossed.min()) if len(crossed) else 0


def true_estimator(site: Site, values: Mapping[str, Any], k_b_factor: float | Sequence[float]) -> CorrugationEstimator:
    """A state of the site whose K_b is the configured one times k_b_factor (one for every friction
    state, or one per state in FRICTION_* order)."""
    cfg = corrugation_config(values)
    factors = np.broadcast_to(np.asarray(k_b_factor, float), cfg.k_b.shape)
    scaled = {f"corrugation.k_b.{name}": float(k * f)
              for name, k, f in zip(K_B_DEFAULTS, cfg.k_b.tolist(), factors.tolist(), strict=True)}
    return CorrugationEstimator(site, corrugation_config({**values, **scaled}))


def simulate_surveys(site: Site, values: Mapping[str, Any], passes: PassTable, k_b_factor: float | Sequence[float],
                     every_days: float, uncertainty_db: float, seed: int) -> SurveySeries:
    """Surveys every ``every_days`` [day] from the first pass's day (the first one then, on the
    freshly ground rail) to the last pass, of the true rail under ``passes`` (time order)."""
    truth = true_estimator(site, values, k_b_factor)
    ok = accepted_passes(passes, site)
    traj = truth.advance_history(ok)
    first, last = int(passes.stamp_ns.min()), int(passes.stamp_ns.max())
    day0 = first - first % NS_PER_DAY
    stamps = day0 + (np.arange(int((last - day0) // (every_days * NS_PER_DAY)) + 1) * every_days
                     * NS_PER_DAY).astype(np.int64)
    row = np.searchsorted(traj.stamp_ns, stamps, side="right") - 1
    state = np.where(row[:, None] >= 0, traj.amplitude[np.maximum(row, 0)], traj.constants.amplitude)
    rng = np.random.Generator(np.random.PCG64(seed))
    measured = state * np.exp(uncertainty_db * LN_PER_DB * rng.standard_normal(state.shape))
    past = traj.amplitude >= truth.threshold
    crossing = np.where(past.any(axis=0), traj.stamp_ns[np.argmax(past, axis=0)], 0).astype(np.int64)
    return SurveySeries(stamps, truth.bands.copy(), measured, truth.k_b.copy(), crossing)
