"""The ``residual.*`` parameters: pairing, the prediction's uncertainty and the running baseline."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from rail_monitor.core.params import ParamSpec, section_values

RESIDUAL_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("prediction_sd_db", 2.0, "Standard uncertainty of a predicted 1/3-octave band level [dB] (the "
              "model's, at a site it was not calibrated at).", 0.0, 20.0),
    ParamSpec("baseline_passes", 200, "Measured passes in the running median of the 500-2000 Hz residual: "
              "the site's baseline [-].", 5, 100_000),
    ParamSpec("baseline_min_passes", 20, "Passes the baseline needs before passes are scored against it [-].",
              1, 100_000),
    ParamSpec("outlier_db", 6.0, "A pass this far above the baseline is left out of it [dB].", 0.5, 60.0),
    ParamSpec("receiver_tolerance_m", 0.5, "A measurement's receiver may differ from the model's by this "
              "(distance and height) [m].", 0.0, 100.0),
    ParamSpec("indirect_days", 0.0, "Window of the indirect rail roughness taken by the corrugation state as "
              "an observation, from the Unix epoch (UTC) [day]; 0: not taken.", 0.0, 366.0),
    ParamSpec("held_predictions", 20_000, "Predictions kept for measurements still to come, and measurements "
              "kept waiting for their passes' predictions [-].", 10, 10_000_000),
)

@dataclass(frozen=True)
class ResidualConfig:
    """Residual parameters (names and units as in RESIDUAL_SPECS)."""

    prediction_sd_db: float
    baseline_passes: int
    baseline_min_passes: int
    outlier_db: float
    receiver_tolerance_m: float
    indirect_days: float
    held_predictions: int


def residual_config(values: Mapping[str, Any], prefix: str = "residual.") -> ResidualConfig:
    """Checked residual parameters from flat values (keys under prefix)."""
    return section_values(ResidualConfig, RESIDUAL_SPECS, values, prefix)
