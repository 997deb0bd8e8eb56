"""Indirect rail roughness of a batch run's recent measured passes (rail_monitor.measured.indirect),
as ``rail-monitor predict roughness`` reports it (no rclpy)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from rail_monitor.alerts.config import alert_config
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.engine.result import SiteOutputs
from rail_monitor.measured.config import residual_config
from rail_monitor.measured.indirect import IndirectRoughness, indirect_rail_roughness
from rail_monitor.noise.config import noise_config
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.noise.records import Corrugation


def indirect_of_run(result: SiteOutputs, values: Mapping[str, Any], days: float) -> IndirectRoughness:
    """The indirect rail roughness on the corrugation state's bands from the measured passes of the
    last ``days`` [day] of a run (``alerts.residual_model``'s residuals), against the final state."""
    est = result.estimator
    model_name = alert_config(values, est.cfg.lead_time_days).residual_model
    since = est.newest_ns - int(days * NS_PER_DAY)
    mine = {(r.stamp_ns, r.train_id): r for r in result.residuals if r.model == model_name and r.stamp_ns > since}
    if not mine:
        raise RailMonitorError(f"no measured pass in the last {days:g} days of the history: no indirect roughness")
    acc = result.accepted
    rows = np.array([k in mine for k in zip(acc.stamp_ns.tolist(), acc.train_id.tolist(), strict=True)], bool)
    passes = acc.take(rows)
    residual = np.array([mine[k].residual_db for k in zip(passes.stamp_ns.tolist(), passes.train_id.tolist(),
                                                           strict=True)])
    model = RollingNoiseModel(result.site, noise_config(values))
    state = Corrugation(est.bands, est.amplitude, est.grinding_amplitude)
    rail_db = np.interp(est.bands, model.grid, model.rail_roughness_db(state))
    return indirect_rail_roughness(residual, model.rail_share(passes, state), passes.speed_mps, model.band_hz,
                                   est.bands, rail_db, residual_config(values).prediction_sd_db)

