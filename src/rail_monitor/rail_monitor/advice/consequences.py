"""What a speed plan does besides corrugation: the rolling noise of each class's trains and the
share of its passes at a squeal risk, tabulated on a speed grid.

Noise: a train of the class (its mean number of vehicles, dry rail, the site's noise models) at
each speed on the current rail roughness, LpAFmax at the site's receiver (the metric of the
noise limit, ISO 3095's maximum level). Squeal: the class's kept passes (their angle of attack,
wheel load and friction state) run at each speed through the squeal model; the share at risk
medium or above. Both are linear in a distribution of speeds, which is what the plan needs.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.core.passes import PassTable, synthetic_passes, with_class_defaults
from rail_monitor.core.site import Site
from rail_monitor.corrugation.history import KeptPasses
from rail_monitor.noise.config import noise_config
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.noise.records import Corrugation
from rail_monitor.squeal.config import RISK_MEDIUM, SquealConfig, squeal_config
from rail_monitor.squeal.predict import risk_at_speeds

NOISE_METRIC = "lpafmax_dba"


@dataclass
class Consequences:
    """The site's noise model and squeal parameters, evaluated per class on a speed grid."""

    site: Site
    noise: RollingNoiseModel
    squeal: SquealConfig

    @classmethod
    def of_values(cls, site: Site, values: Mapping[str, Any]) -> Consequences:
        """From a site's flat parameter values (its noise.* and squeal.* sections)."""
        return cls(site, RollingNoiseModel(site, noise_config(values)), squeal_config(values))

    def noise_dba(self, classes: list[str], speeds: np.ndarray, corrugation: Corrugation | None) -> np.ndarray:
        """LpAFmax [dB(A)] (models, C, G) of a train of each class at each speed [m/s]."""
        out = np.empty((len(self.noise.models), len(classes), len(speeds)))
        for j, name in enumerate(classes):
            cls = self.site.vehicle(name)
            table = synthetic_passes(self.site, cls, np.asarray(speeds, float), round(cls.mean_vehicles))
            for i, p in enumerate(self.noise.predict_models(table, (), corrugation).values()):
                out[i, j] = getattr(p, NOISE_METRIC)
        return out

    def squeal_share(self, kept: KeptPasses, name: str, class_idx: int, speeds: np.ndarray | None) -> np.ndarray:
        """Share of a class's kept passes at squeal risk medium or above (G,) if run at each speed
        [m/s]; with speeds None, (1,) at their own speeds. 0 for a class without kept passes."""
        rows = np.flatnonzero(kept.class_idx == class_idx)
        if not len(rows):
            return np.zeros(1 if speeds is None else len(speeds))
        n = len(rows)
        table = with_class_defaults(PassTable(
            stamp_ns=np.arange(n, dtype=np.int64) + 1, train_id=[""] * n, vehicle_class=[name] * n,
            vehicle_count=[1] * n, axle_count=[0] * n, speed_mps=kept.speed[rows],
            angle_of_attack_rad=np.arcsin(np.clip(kept.creepage[rows], 0.0, 1.0)), wheel_load_n=kept.load[rows],
            friction_state=kept.friction[rows], train_length_m=[0.0] * n), self.site)
        v = table.speed_mps[None, :] if speeds is None else np.asarray(speeds, float)[:, None]
        return (risk_at_speeds(self.squeal, self.site, table, v) >= RISK_MEDIUM).mean(axis=1)
